/// @file trivox/slice/sampler.hpp
/// @brief Sampling a V-model on a printer's voxel grid, a band of image rows at a time: per voxel
/// the cell that contains its centre (or void) and the model's properties there.
///
/// The print job's hot path (Masalha, Cirillo & Elber 2021, seed 000, Sec. 8: V-models sliced
/// into Voxel Print images, geometry and materials together). Per image row (fixed y and z):
/// - empty space is skipped: the row line meets only some leaves' xyz boxes (locator.hpp); each
///   gives an x-interval, and voxels outside all intervals are void without any inversion;
/// - within a cell's intervals, voxels are inverted in x order, each warm-started from its
///   neighbours' (u,v,w) (quadratic extrapolation of the last three): damped Newton over the whole
///   cell domain usually converges in one evaluation;
/// - only when that does not converge (entering the cell, leaving it, the first voxel of a run),
///   the leaves whose intervals hold the voxel decide, by Newton clamped to each leaf (each
///   warm-started from its own answer at the previous voxel) with the locator's subdivision
///   fallback. So occupancy is as exact as Locator::locate.
/// Cells are processed in file order and a voxel taken by a cell is skipped by later ones: the
/// first cell wins on overlap. Properties are the cell's coordinates 3.. evaluated at the located
/// (u,v,w) (exact up to rounding to float).
///
/// Accuracy: occupancy equals the exact answer except for voxel centres within the tolerance
/// (1e-3 of the smallest pitch) of a cell boundary; properties are those at a (u,v,w) whose image
/// lies within that tolerance of the centre.
///
/// Determinism: a row's result depends only on the row (layer, image row), never on the band it
/// was computed in or on other threads, so any banding and thread count give identical output.
///
/// Cost: per voxel inside the model about one geometry evaluation (O(order^3)) plus one property
/// evaluation (O(order^3 * m)); per row a pass over the leaves that meet the layer; void voxels
/// outside every leaf box cost nothing. No allocation per voxel.
#pragma once
#include <cstdint>
#include <vector>

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
  /// Voxels whose inversion did not converge even after subdivision. Each takes its best guess:
  /// inside (at the best iterate) when that iterate's image lies within half the smallest pitch of
  /// the centre, else void. Reported in the job summary and manifest, never silent.
  std::int64_t failures = 0;
  std::int64_t inverted = 0;  ///< voxels that needed Newton (inside some leaf box): a cost figure
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

/// Sampling options (room for per-voxel blending, --blend, later).
struct SamplerOptions {
  bool keep_uvw = false;  ///< also fill RowBand::uvw (tests, diagnostics)
};

class LayerSampler {
public:
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

private:
  VoxelGrid grid_;
  SamplerOptions opt_;
  Locator locator_;
};

}  // namespace trivox::slice
