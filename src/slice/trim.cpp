#include "trivox/slice/trim.hpp"

#include <algorithm>
#include <vector>

namespace trivox::slice {

void apply_trimming(const Locator& loc, const VoxelGrid& grid, RowBand& band) {
  if (!loc.has_trims()) return;
  const int m = band.nprops;
  const bool with_uvw = !band.uvw.empty();
  const int ny = grid.count[1];
  std::vector<double> props(static_cast<std::size_t>(m));
  for (int r = 0; r < band.rows; ++r) {
    const int j = ny - 1 - (band.row0 + r);  // image row -> grid row (grid.hpp)
    for (int i = 0; i < band.nx; ++i) {
      const std::size_t v = static_cast<std::size_t>(r) * static_cast<std::size_t>(band.nx) + static_cast<std::size_t>(i);
      const int c = band.cell[v];
      if (c < 0 || !loc.trimmed(c)) continue;
      const Vec3 p = grid.centre(i, j, band.layer);
      float* vp = band.props.data() + v * static_cast<std::size_t>(m);
      double* vu = with_uvw ? band.uvw.data() + 3 * v : nullptr;
      if (loc.admits(c, p)) {
        std::copy(vp, vp + m, props.begin());
        loc.blend_properties(c, p, props.data());
        std::copy(props.begin(), props.end(), vp);
        continue;
      }
      const LocateResult res = loc.locate(p);
      if (!res.inside) {
        band.cell[v] = -1;
        std::fill(vp, vp + m, 0.0f);
        if (vu) std::fill(vu, vu + 3, 0.0);
        continue;
      }
      band.cell[v] = res.cell;
      double x[3];
      loc.eval(res.cell, res.uvw, x, props.data());
      loc.blend_properties(res.cell, p, props.data());
      std::transform(props.begin(), props.end(), vp, [](double d) { return static_cast<float>(d); });
      if (vu) std::copy(res.uvw.begin(), res.uvw.end(), vu);
    }
  }
}

}  // namespace trivox::slice
