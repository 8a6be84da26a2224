/// @file trivox/vmodel/vmodel.hpp
/// @brief The V-model: a complex of volumetric cells whose control points carry xyz plus
/// properties (Massarwi & Elber 2016, Sec. 3.1).
///
/// This is the data every module passes around. Topology (V-surfaces, half-V-surfaces,
/// V-curves, V-points), trimming and Booleans build on it.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "trivox/spline/extract.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::vmodel {

/// How the properties of a cell that lies in several inputs' cells combine (Booleans,
/// Massarwi & Elber 2016, Sec. 3.1.2): the cell's own trivariate and each `within`
/// cell give values at a point.
enum class BlendRule {
  first,    ///< the cell's own trivariate alone
  sum_clip, ///< the sum of all values, clipped to [0, 1] (Massarwi & Elber 2016, Fig. 5: colours summed)
  mean,     ///< their average
  /// Massarwi & Elber 2016, Eq. 2: the average weighted by d_i^k, d_i the distance from the point
  /// to the boundary of the input model that value i comes from (VCell::boundaries), k =
  /// blend_power. On the boundary of one input, the other inputs' values alone remain, so the
  /// attribute is C0 across the intersection cell's boundary. (Eq. 2 measures the distance to the
  /// part of that boundary inside the other input; the whole boundary vanishes on the same parts of
  /// the cell's boundary, so continuity is the same, only the interior weights differ.)
  distance,
};

/// "first", "sum_clip", "mean", "distance".
const char* blend_rule_name(BlendRule r) noexcept;
/// The rule called `name`, or false.
bool blend_rule_from_name(std::string_view name, BlendRule& out) noexcept;

/// Trimming curves on one boundary face of a cell's trivariate: where the other input of a
/// Boolean cuts that face (surface-surface intersection, Massarwi & Elber 2016, Sec. 4), as curves
/// in the face's parameter space (R^2; the face's parameters are the two
/// other directions in order).
struct FaceTrim {
  spline::Face face = spline::Face::u0;
  std::vector<spline::Curve> curves;

  bool operator==(const FaceTrim&) const = default;
};

/// The data of a fillet cell whose properties are the Euclidean-distance (Shepard) blend of
/// Masalha, Cirillo & Elber 2021, Sec. 7.2, after Biswas et al. 2004: at a point p,
/// f(p) = alpha_1 g_1(pi_1(p)) + alpha_2 g_2(pi_2(p)), alpha_i = d_i^-q / (d_1^-q + d_2^-q), d_i
/// the distance from p to the fillet's sub-region S^_i, pi_i(p) its closest point there and g_i
/// the properties S^_i carries. The cell's own property control points hold the least-squares
/// encoding of f (fillet/shepard.hpp); this lets the slicer evaluate f exactly per voxel
/// (`trivox slice --blend shepard`).
struct ShepardData {
  /// S^_1, S^_2 in R^(3+m): xyz then the m properties g_i, as the model's cells.
  std::array<spline::Surface, 2> sources;
  int power = 2;  ///< q, a positive integer (1..16)

  bool operator==(const ShepardData&) const = default;
};

/// One volumetric cell: a trivariate in R^(3+m), coordinates 0..2 xyz and 3.. the properties.
///
/// A plain cell is the image of its trivariate. A cell made by a Boolean operation (Massarwi &
/// Elber 2016 Sec. 4, Alg. 1-3) is *trimmed*: it is the part of that image that lies in every
/// `within` cell and in none of the cells of any `without` list (Def. 3.2: a V-cell is in the
/// intersection of one or more trivariates; here the trimming is given by the other inputs' cells
/// themselves, so membership is exact at every point, decided by point inversion). Intersection
/// cells keep the other input's cell in `within`, with its trivariate and attributes, and blend the
/// properties by `blend`. The nesting follows the Boolean expression: a `within` cell or a
/// `without` cell may itself be trimmed.
struct VCell {
  VCell() = default;
  /// A plain cell.
  VCell(std::string name_, spline::Trivariate volume_) : name(std::move(name_)), volume(std::move(volume_)) {}

  std::string name;
  spline::Trivariate volume;
  std::vector<VCell> within;                ///< the cell also lies in each of these
  std::vector<std::vector<VCell>> without;  ///< and in no cell of any of these solids
  BlendRule blend = BlendRule::first;       ///< how volume's and the within cells' properties combine
  double blend_power = 1.0;                 ///< k of BlendRule::distance (> 0)
  /// BlendRule::distance: one list of boundary surfaces (xyz) per blended value: the input
  /// model that `volume` came from, then that of each within cell.
  std::vector<std::vector<spline::Surface>> boundaries;
  /// Booleans: where the other input's faces cut this cell's faces (per face, in order).
  std::vector<FaceTrim> trim_curves;
  /// Fillets built with the Shepard blend: the data for the exact per-voxel value.
  std::optional<ShepardData> shepard;

  /// No trimming: the cell is its trivariate's image.
  bool plain() const noexcept { return within.empty() && without.empty(); }

  bool operator==(const VCell&) const = default;
};

/// A free-standing surface patch of a model (G+Smo surface files, such as the Utah teapot):
/// input to the constructors, not printable material on its own.
struct NamedSurface {
  std::string name;
  spline::Surface surface;

  bool operator==(const NamedSurface&) const = default;
};

class VModel {
public:
  std::string units = "mm";
  /// Names of the property coordinates 3.. of every control point.
  std::vector<std::string> properties;
  std::vector<VCell> cells;
  std::vector<NamedSurface> surfaces;

  /// Coordinates per control point: 3 + properties.size().
  int dim() const noexcept { return 3 + static_cast<int>(properties.size()); }

  /// The cell called `name`, or nullptr.
  const VCell* find_cell(const std::string& name) const noexcept;

  bool operator==(const VModel&) const = default;
};

}  // namespace trivox::vmodel
