/// @file trivox/slice/sampler.hpp
/// @brief Sampling a V-model on a printer's voxel grid, a band of image rows at a time: per voxel
/// the cell that contains its centre (or void) and the model's properties there.
///
/// The print job's hot path (Masalha, Cirillo & Elber 2021, Masalha et al. 2021, Sec. 8: V-models
/// sliced into Voxel Print images, geometry and materials together; their research code took about
/// six minutes for a 1516 x 2524 slice). A layer is processed in blocks of 4 image rows, cell by
/// cell in file order (a voxel taken by a cell is skipped by later ones: the first cell wins on
/// overlap), each row from left to right:
/// - Empty space is skipped: a row line meets only some leaves' regions (locator.hpp; the
///   sampler asks for leaves within about one voxel of affine), each gives an x-interval, and
///   voxels outside every interval are void without any inversion.
/// - Certified stepping (polynomial cells with up to 7 properties): an *anchor* is one exact
///   evaluation at a voxel, of every coordinate with its first partials (Locator::expand). From
///   it the parameters of the voxels around it follow from the linear model,
///   t = t0 + J0^-1 (p - X0). The piece's bounds on second partials (StepBounds) turn that into
///   a certificate: a Taylor bound on |J0^-1 (X(t) - p)|, the Newton-Kantorovich theorem in its
///   affine-covariant form (Deuflhard; so thin, sheared or layer-thin cells are as well served as
///   cubes in the image space; in the parameter space the norm is also taken with each t_j
///   scaled by |dX/dt_j| at the anchor, so that a shell 2 mm thick and 125 mm around is not
///   refused after a few voxels, the plain norm tried where that fails and alone used where a
///   rectangle reaches out of the piece) for an exact preimage t* within a radius r of t inside the piece (so p is inside the
///   cell; or outside the piece by less than the tolerance, where the contract allows either
///   answer: a layer through a face between cells is certified too), and a bound on the
///   properties' error below 0.95/512. The properties come from the first-order model
///   P0 + G0 (t - t0) where its Taylor remainder fits that budget; else from the piece's own
///   polynomial, evaluated exactly at the t of every s-th voxel of a row (Locator::
///   piece_properties) and interpolated in between, the error being the gradient times
///   |t* - t| (at most half the budget) plus the interpolation's (the rest): linearly, s^2 / 8
///   times a bound on the second derivative along the row, or, where that spaces the samples
///   farther, quadratically through three samples at most s apart, s^3 / 12 times a
///   bound on the third derivative (StepBounds::p3). So where the cells are nearly affine at voxel scale and the
///   properties vary fast (the twisted column of models/: radii r about 1e-10), an anchor is
///   limited by the piece and the cell's shape, not by its properties: hundreds of voxels
///   instead of tens. All bounds
///   grow with the distance from the anchor, so an anchor certifies a rectangle of voxels across
///   the block's rows at once (its width found by doubling and bisection, up to where its
///   parameters leave the piece's box, and that width tried first where the box bound the last
///   anchor); inside it a voxel costs a few multiply-adds. Where the rectangle spans only some
///   of the block's rows (a face crossing the rows at a slant, as at the start of most runs
///   through the twisted column's rings), each other row is certified on its own, with the
///   columns where its linear-model parameters stay in the piece's box (a one-row rectangle
///   beside the anchor: the same bounds), so that one anchor still serves the whole block.
///   The next anchor is placed ahead of the
///   first voxel not yet covered, by the reach of the last one, so that rectangles do not
///   overlap by half.
/// - A voxel whose predicted parameters leave the cell's domain is first tried for a proof that
///   it is outside: one expansion at the face and a Taylor bound on where a root could lie,
///   over the piece's leaves that hold the voxel (without Newton; the proof also serves the next
///   voxels of the row).
/// - Elsewhere (near boundaries, rational cells): the voxel is evaluated once at a prediction
///   (a new anchor, or an exact residual check |X(t) - p| < tolerance), and failing that Newton
///   over the cell domain from the prediction, then the leaves whose intervals hold the voxel
///   (Newton clamped to each leaf, warm-started from its answer at the previous voxel, with the
///   locator's subdivision fallback) decide. So occupancy is as exact as Locator::locate.
///
/// Accuracy (tests check it against a locator at tolerance 1e-10): occupancy equals the exact
/// answer except for voxel centres within the tolerance (1e-3 of the smallest pitch) of a cell
/// boundary; properties are within 1/512 of the cell's properties at the exact preimage of the
/// voxel's centre (certified voxels: by the bounds above; evaluated voxels: exact at a (u,v,w)
/// whose image lies within the tolerance of the centre). The (u,v,w) kept with
/// SamplerOptions::keep_uvw map within the tolerance of the centre for evaluated voxels and within
/// half the smallest pitch for certified ones (their exact preimage being
/// within the certified radius).
///
/// Booleans: for a model with trimmed cells (vmodel/boolean.hpp), each sampled band then goes
/// through slice/trim.hpp's apply_trimming, so occupancy and properties follow the trimming
/// exactly (one point location per condition for each voxel of a trimmed cell).
///
/// Shepard fillets (SamplerOptions::blend = shepard): after a block is sampled, every voxel held
/// by a cell with Shepard data gets f at its centre (vmodel/shepard_field.hpp), the walk of warm starts
/// running along each row of the block; cells without it are untouched.
///
/// Determinism: a block's result depends only on the block (layer and its 4 image rows); a band
/// computes every block it touches in full and copies out its rows, so any banding and thread
/// count give identical output.
///
/// Cost: per voxel inside a cell a few multiply-adds where certified, about one evaluation
/// (O(order^3 * (3 + m))) per anchor (tens to hundreds of voxels each at printer pitch) and one
/// of the m properties (O(order^3 * m), eight points per vector pass) per sample, a few Newton
/// iterations per voxel near boundaries; per row a pass over the leaves that meet the block;
/// void voxels outside every leaf region cost nothing. No allocation per voxel.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "trivox/vmodel/shepard_field.hpp"

#include "trivox/slice/grid.hpp"
#include "trivox/slice/locator.hpp"

namespace trivox::slice {

/// One band of rows of one layer: per voxel the cell index (-1 void) and the model's properties.
struct RowBand {
  int layer = 0;   ///< k, the layer (slice image) index
  int row0 = 0;    ///< first image row; image row r holds grid row j = ny - 1 - r (grid.hpp)
  int rows = 0;    ///< number of image rows
  int nx = 0;      ///< voxels per row
  int nprops = 0;  ///< properties per voxel (VModel::properties.size())
  std::vector<std::int32_t> cell;  ///< rows * nx: cell index into VModel::cells, or -1 (void)
  std::vector<float> props;        ///< rows * nx * nprops, voxel after voxel; 0 for void voxels
                                   ///< (unspecified with SamplerOptions::zero_void_props false)
  /// Voxels whose inversion did not converge even after subdivision. Each takes its best guess:
  /// inside (at the best iterate) when that iterate's image lies within half the smallest pitch of
  /// the centre, else void. Reported in the job summary and manifest, never silent.
  std::int64_t failures = 0;
  /// Voxels inside some leaf's region of a cell that had not taken them yet (stepped, evaluated
  /// or inverted): a cost figure.
  std::int64_t inverted = 0;
  /// rows * nx * 3: the located (u,v,w) of each voxel (0 for void); only with
  /// SamplerOptions::keep_uvw, else empty.
  std::vector<double> uvw;

  /// Cell of the voxel at image row `r` (0-based within the band) and column i.
  std::int32_t cell_at(int r, int i) const { return cell[static_cast<std::size_t>(r) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i)]; }
  /// Its properties (nprops values).
  const float* props_at(int r, int i) const {
    return props.data() + (static_cast<std::size_t>(r) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i)) * static_cast<std::size_t>(nprops);
  }
};

/// Which properties the fillet cells that carry Shepard data (vmodel::ShepardData) get.
enum class PropertyBlend : std::uint8_t {
  encoded,  ///< their control points' (the least-squares encoding of f): the default
  /// f itself, exactly per voxel (Masalha et al. 2021, Sec. 7.2; vmodel/shepard_field.hpp): two
  /// closest-point queries per voxel of those cells, warm-started along each image row of a block
  /// (cold at every row's first such voxel), so a voxel's value depends only on its block.
  shepard,
};

/// "encoded", "shepard".
const char* property_blend_name(PropertyBlend b) noexcept;
/// The blend called `name`, or false.
bool property_blend_from_name(std::string_view name, PropertyBlend& out) noexcept;

/// Sampling options.
struct SamplerOptions {
  bool keep_uvw = false;  ///< also fill RowBand::uvw (tests, diagnostics)
  PropertyBlend blend = PropertyBlend::encoded;  ///< properties of Shepard fillet cells
  /// Zero the properties of void voxels. A caller that never reads them (the print job: every
  /// dithering mode looks at the cell first) sets false, and the sampler then leaves whatever
  /// its band held there, saving the 4 m bytes per voxel of clearing each block.
  bool zero_void_props = true;
};

class LayerSampler {
public:
  /// Image rows sampled together (blocks aligned on multiples of this): bands whose first row
  /// and size are multiples of it cost no recomputation.
  static constexpr int block_rows = 4;

  /// @param model  the V-model; must outlive the sampler and stay unchanged
  /// @param grid   the voxel grid (copied); the locator's tolerance is 1e-3 * its smallest pitch
  /// @param opt    sampling options
  /// @throws Error (bad_input) as Locator, or for a grid without voxels
  LayerSampler(const vmodel::VModel& model, const VoxelGrid& grid, SamplerOptions opt = {});

  /// Fills `out` for image rows [row0, row0 + rows) of layer `layer`. Thread-safe: several
  /// threads may call it at once (on different bands, each with its own `out`); `out` is resized
  /// and reused, so a caller that keeps it avoids allocation.
  /// @param layer  0 <= layer < nz
  /// @param row0   first image row, 0 <= row0 <= ny
  /// @param rows   number of rows, row0 + rows <= ny
  /// @param out    the band (all fields overwritten)
  /// @throws Error (bad_input) for a layer or row range outside the grid
  void sample(int layer, int row0, int rows, RowBand& out) const;

  const VoxelGrid& grid() const noexcept { return grid_; }
  const Locator& locator() const noexcept { return locator_; }

  /// Voxels whose properties were the exact Shepard blend, and how many of their closest-point
  /// queries were warm (cost figures, summed over every sample() call; thread-safe counters).
  std::int64_t shepard_voxels() const noexcept { return shepard_voxels_.load(); }
  std::int64_t shepard_warm() const noexcept { return shepard_warm_.load(); }

private:
  /// PropertyBlend::shepard: f at every voxel of block rows [r0, r0 + nr) held by a Shepard cell.
  void apply_shepard(int layer, int r0, int nr, std::int32_t* owner, float* props) const;

  VoxelGrid grid_;
  SamplerOptions opt_;
  Locator locator_;
  /// Per cell: index into shepard_ (-1: no Shepard data or the encoded blend); cells with equal
  /// data (the two halves of a fillet) share one field.
  std::vector<int> shepard_of_;
  std::vector<std::unique_ptr<vmodel::ShepardField>> shepard_;
  mutable std::atomic<std::int64_t> shepard_voxels_{0}, shepard_warm_{0};
};

}  // namespace trivox::slice
