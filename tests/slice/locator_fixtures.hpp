// Cells with known geometry for the locator and sampler tests: axis-aligned boxes, a curved
// tricubic block, a rational quarter-annulus slab (exact circular arcs), and helpers to sample
// a whole grid.
#pragma once
#include <cmath>
#include <numbers>
#include <vector>

#include "trivox/slice/sampler.hpp"
#include "trivox/spline/tensor_spline.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::test {

using spline::KnotVector;
using spline::Trivariate;

/// The trilinear box [lo, hi] with constant properties `props`.
inline Trivariate box_cell(const std::array<double, 3>& lo, const std::array<double, 3>& hi, const std::vector<double>& props = {}) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        pts.push_back(i ? hi[0] : lo[0]);
        pts.push_back(j ? hi[1] : lo[1]);
        pts.push_back(k ? hi[2] : lo[2]);
        pts.insert(pts.end(), props.begin(), props.end());
      }
  const auto lin = KnotVector::bezier(2);
  return Trivariate({lin, lin, lin}, 3 + static_cast<int>(props.size()), pts);
}

/// A tricubic Bezier block over [0,10]^3 whose non-corner control points are moved by up to
/// 0.6 mm (curved faces, curved interior), with 3 properties that vary over the net.
inline Trivariate curved_tricubic() {
  std::vector<double> pts;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const bool corner = (i == 0 || i == 3) && (j == 0 || j == 3) && (k == 0 || k == 3);
        const double a = corner ? 0.0 : 0.6;
        pts.push_back(10.0 * i / 3.0 + a * std::sin(1.0 + i + 2.0 * j + 3.0 * k));
        pts.push_back(10.0 * j / 3.0 + a * std::cos(2.0 + 3.0 * i + j + k));
        pts.push_back(10.0 * k / 3.0 + a * std::sin(3.0 + i + j + 2.0 * k));
        pts.push_back(0.5 + 0.5 * std::sin(0.7 * i + 1.3 * j + 0.4 * k));
        pts.push_back(0.5 + 0.5 * std::cos(1.1 * i + 0.3 * j + 0.9 * k));
        pts.push_back((i + j + k) / 9.0);
      }
  const auto cub = KnotVector::bezier(4);
  return Trivariate({cub, cub, cub}, 6, pts);
}

/// The quarter-annulus slab r1 <= |(x,y)| <= r2, x, y >= 0, 0 <= z <= h: u along the arc
/// (rational quadratic, weights 1, sqrt(2)/2, 1: exact circles), v radial, w along z; one
/// property equal to v. Volume (pi / 4) (r2^2 - r1^2) h.
inline Trivariate quarter_annulus(double r1, double r2, double h) {
  std::vector<double> pts, w;
  const double s = std::sqrt(0.5);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) {
        const double r = j ? r2 : r1;
        const double xy[3][2] = {{r, 0}, {r, r}, {0, r}};
        pts.insert(pts.end(), {xy[i][0], xy[i][1], k * h, double(j)});
        w.push_back(i == 1 ? s : 1.0);
      }
  return Trivariate({KnotVector::bezier(3), KnotVector::bezier(2), KnotVector::bezier(2)}, 4, pts, w);
}

inline vmodel::VModel model_of(std::vector<Trivariate> cells, std::vector<std::string> props = {}) {
  vmodel::VModel m;
  m.properties = std::move(props);
  for (std::size_t i = 0; i < cells.size(); ++i) m.cells.push_back({"cell" + std::to_string(i), std::move(cells[i])});
  return m;
}

/// Every cell's xyz multiplied by `f`.
inline vmodel::VModel scaled(vmodel::VModel m, double f) {
  for (auto& c : m.cells) {
    auto pts = c.volume.points();
    const auto dim = static_cast<std::size_t>(c.volume.dim());
    for (std::size_t i = 0; i < pts.size(); i += dim)
      for (std::size_t h = 0; h < 3; ++h) pts[i + h] *= f;
  }
  return m;
}

/// Samples every layer of the sampler's grid; calls f(i, j, k, band, r) for every voxel.
template <class F>
void sample_all(const slice::LayerSampler& s, F&& f, std::int64_t* failures = nullptr) {
  const auto& g = s.grid();
  slice::RowBand band;
  for (int k = 0; k < g.count[2]; ++k) {
    s.sample(k, 0, g.count[1], band);
    if (failures) *failures += band.failures;
    for (int r = 0; r < g.count[1]; ++r)
      for (int i = 0; i < g.count[0]; ++i) f(i, g.count[1] - 1 - r, k, band, r);
  }
}

/// Number of voxels of the grid that are inside some cell.
inline std::int64_t occupied(const slice::LayerSampler& s, std::int64_t* failures = nullptr) {
  std::int64_t n = 0;
  sample_all(s, [&](int i, int, int, const slice::RowBand& b, int r) { n += b.cell_at(r, i) >= 0; }, failures);
  return n;
}

}  // namespace trivox::test
