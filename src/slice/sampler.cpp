// The layer sampler (sampler.hpp; the slicing of Masalha et al. 2021, Sec. 8): its locator, with
// the tolerance and leaf deviations set from the voxel pitch, and the Shepard fields of its
// fillet cells; a band of image rows sampled block by block (block_sampler.hpp), straight into
// the band where a block lies inside it, then the Shepard pass (shepard_pass.cpp) and the
// Booleans' trimming (trim.hpp). Cost: that of the blocks the band touches (sampler.hpp), plus
// a copy of the rows of a block that lies only partly inside the band.
#include "trivox/slice/sampler.hpp"

#include "trivox/slice/trim.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include "trivox/error.hpp"

#include "block_sampler.hpp"

namespace trivox::slice {

namespace {

LocatorOptions options_for(const VoxelGrid& grid) {
  const double pmin = std::min({grid.pitch[0], grid.pitch[1], grid.pitch[2]});
  if (!(std::isfinite(pmin) && pmin > 0.0))
    throw Error("voxel pitch " + std::to_string(pmin) + " mm; expected positive finite pitches");
  LocatorOptions o;
  o.tolerance = 1e-3 * pmin;
  // Leaves hugging the cells to within about a voxel: little empty space left to invert.
  o.leaf_deviation = 1.0 * std::max({grid.pitch[0], grid.pitch[1], grid.pitch[2]});
  // Then on towards a quarter of that, within 4 times the leaves per piece.
  o.fine_leaf_deviation = 0.25 * o.leaf_deviation;
  o.fine_leaf_factor = 4;
  return o;
}

}  // namespace

const char* property_blend_name(PropertyBlend b) noexcept { return b == PropertyBlend::shepard ? "shepard" : "encoded"; }

bool property_blend_from_name(std::string_view name, PropertyBlend& out) noexcept {
  if (name == "encoded") out = PropertyBlend::encoded;
  else if (name == "shepard") out = PropertyBlend::shepard;
  else return false;
  return true;
}

LayerSampler::LayerSampler(const vmodel::VModel& model, const VoxelGrid& grid, SamplerOptions opt)
    : grid_(grid), opt_(opt), locator_(model, options_for(grid)) {
  if (grid.count[0] < 1 || grid.count[1] < 1 || grid.count[2] < 1)
    throw Error("voxel grid of " + std::to_string(grid.count[0]) + " x " + std::to_string(grid.count[1]) + " x " +
                std::to_string(grid.count[2]) + " voxels; expected at least one along each axis");
  if (opt_.blend != PropertyBlend::shepard || model.properties.empty()) return;
  shepard_of_.assign(model.cells.size(), -1);
  std::vector<const vmodel::ShepardData*> data;
  for (std::size_t c = 0; c < model.cells.size(); ++c) {
    const auto& sd = model.cells[c].shepard;
    if (!sd) continue;
    std::size_t k = 0;
    while (k < data.size() && !(*data[k] == *sd)) ++k;
    if (k == data.size()) {
      data.push_back(&*sd);
      try {
        shepard_.push_back(std::make_unique<vmodel::ShepardField>(*sd));
      } catch (const Error& e) {
        throw e.within("cell " + model.cells[c].name);
      }
    }
    shepard_of_[c] = static_cast<int>(k);
  }
  if (shepard_.empty()) shepard_of_.clear();
}

void LayerSampler::sample(int layer, int row0, int rows, RowBand& out) const {
  const int nx = grid_.count[0], ny = grid_.count[1], nz = grid_.count[2];
  if (layer < 0 || layer >= nz)
    throw Error("layer " + std::to_string(layer) + "; expected 0 <= layer < " + std::to_string(nz));
  if (row0 < 0 || rows < 0 || row0 > ny || rows > ny - row0)
    throw Error("image rows [" + std::to_string(row0) + ", " + std::to_string(static_cast<long long>(row0) + rows) +
                "); expected a range within [0, " + std::to_string(ny) + ")");
  const int m = static_cast<int>(locator_.model().properties.size());
  const auto unx = static_cast<std::size_t>(nx), um = static_cast<std::size_t>(m);
  out.layer = layer;
  out.row0 = row0;
  out.rows = rows;
  out.nx = nx;
  out.nprops = m;
  out.cell.resize(static_cast<std::size_t>(rows) * unx);
  out.props.resize(static_cast<std::size_t>(rows) * unx * um);
  if (opt_.keep_uvw)
    out.uvw.resize(static_cast<std::size_t>(rows) * unx * 3);
  else
    out.uvw.clear();
  out.failures = 0;
  out.inverted = 0;
  if (rows == 0) return;
  detail::BlockSampler bs(locator_, grid_);
  std::vector<std::int32_t> owner;
  std::vector<float> props;
  std::vector<double> uvw;
  for (int b = row0 / block_rows; b * block_rows < row0 + rows; ++b) {
    const int r0 = b * block_rows, nr = std::min(block_rows, ny - r0);
    const int from = std::max(r0, row0), to = std::min(r0 + nr, row0 + rows);
    detail::BlockOut blk;
    blk.zero_props = opt_.zero_void_props;
    const bool direct = from == r0 && to == r0 + nr;  // the whole block is in the band
    if (direct) {
      const auto dst = static_cast<std::size_t>(r0 - row0);
      blk.owner = out.cell.data() + dst * unx;
      blk.props = out.props.data() + dst * unx * um;
      blk.uvw = opt_.keep_uvw ? out.uvw.data() + dst * unx * 3 : nullptr;
    } else {
      owner.resize(static_cast<std::size_t>(nr) * unx);
      props.resize(static_cast<std::size_t>(nr) * unx * um);
      if (opt_.keep_uvw) uvw.resize(static_cast<std::size_t>(nr) * unx * 3);
      blk.owner = owner.data();
      blk.props = props.data();
      blk.uvw = opt_.keep_uvw ? uvw.data() : nullptr;
    }
    bs.run(layer, r0, nr, blk);
    if (!shepard_.empty()) apply_shepard(layer, r0, nr, blk.owner, blk.props);
    for (int r = from; r < to; ++r) {
      const auto src = static_cast<std::size_t>(r - r0), dst = static_cast<std::size_t>(r - row0);
      if (!direct) {
        std::copy_n(owner.data() + src * unx, unx, out.cell.data() + dst * unx);
        std::copy_n(props.data() + src * unx * um, unx * um, out.props.data() + dst * unx * um);
        if (opt_.keep_uvw) std::copy_n(uvw.data() + src * unx * 3, unx * 3, out.uvw.data() + dst * unx * 3);
      }
      out.failures += blk.failures[src];
      out.inverted += blk.inverted[src];
    }
  }
  // Cells of Booleans: the first cell whose trivariate holds a voxel took it above; the trimming
  // pass gives it to the cell whose conditions admit it (or to none) and blends properties.
  if (locator_.has_trims()) apply_trimming(locator_, grid_, out);
}

}  // namespace trivox::slice
