/// @file trivox/vmodel/vmodel.hpp
/// @brief The V-model: a complex of volumetric cells whose control points carry xyz plus
/// properties (Massarwi & Elber 2016, seed 003, Sec. 3.1).
///
/// This is the data every module passes around. Topology (V-surfaces, half-V-surfaces,
/// V-curves, V-points), trimming and Booleans build on it.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::vmodel {

/// One volumetric cell: a trivariate in R^(3+m), coordinates 0..2 xyz and 3.. the properties.
struct VCell {
  std::string name;
  spline::Trivariate volume;

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
