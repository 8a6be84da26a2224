#include "trivox/slice/trim.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "trivox/spline/refine.hpp"

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
      std::copy(vp, vp + m, props.begin());
      if (loc.admits(c, p, props.data())) {
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
      loc.admits(res.cell, p, props.data());  // admitted by locate: blends
      std::transform(props.begin(), props.end(), vp, [](double d) { return static_cast<float>(d); });
      if (vu) std::copy(res.uvw.begin(), res.uvw.end(), vu);
    }
  }
}

double trimmed_volume(const Locator& loc, int cell, int divisions) {
  const auto& tv = loc.model().cells[static_cast<std::size_t>(cell)].volume;
  const auto dom = loc.domain(cell);
  const double g = 0.5 / std::sqrt(3.0);  // 2-point Gauss nodes at 1/2 -+ g of a unit interval
  const double nodes[2] = {0.5 - g, 0.5 + g};
  std::vector<double> d(static_cast<std::size_t>(4 * tv.dim()));
  Vec3 h;
  for (std::size_t k = 0; k < 3; ++k) h[k] = (dom[1][k] - dom[0][k]) / divisions;
  double sum = 0.0;
  for (int c = 0; c < divisions; ++c)
    for (int b = 0; b < divisions; ++b)
      for (int a = 0; a < divisions; ++a)
        for (int n = 0; n < 8; ++n) {
          const Vec3 t{dom[0][0] + (a + nodes[n & 1]) * h[0], dom[0][1] + (b + nodes[(n >> 1) & 1]) * h[1],
                       dom[0][2] + (c + nodes[(n >> 2) & 1]) * h[2]};
          tv.eval_derivatives(t, 1, d.data());
          const double* x = d.data();
          if (loc.trimmed(cell) && !loc.admits(cell, {x[0], x[1], x[2]})) continue;
          const double* du = x + tv.dim();
          const double* dv = du + tv.dim();
          const double* dw = dv + tv.dim();
          const double det = du[0] * (dv[1] * dw[2] - dv[2] * dw[1]) - du[1] * (dv[0] * dw[2] - dv[2] * dw[0]) +
                             du[2] * (dv[0] * dw[1] - dv[1] * dw[0]);
          sum += std::abs(det);
        }
  return sum * h[0] * h[1] * h[2] / 8.0;
}

namespace {

/// The parameter box [lo, hi] of cell c whose image is the admitted part, if there is one.
bool admitted_box(const Locator& loc, int c, Vec3& lo, Vec3& hi) {
  const auto& tv = loc.model().cells[static_cast<std::size_t>(c)].volume;
  const auto dom = loc.domain(c);
  constexpr int n = 17;
  std::vector<double> x(static_cast<std::size_t>(tv.dim()));
  const auto at = [&](const Vec3& t) {
    tv.eval(t, x.data());
    return loc.admits(c, {x[0], x[1], x[2]});
  };
  const auto param = [&](std::size_t d, double s) { return dom[0][d] + s * (dom[1][d] - dom[0][d]); };
  std::vector<char> in(n * n * n);
  std::array<int, 3> i0{n, n, n}, i1{-1, -1, -1};
  int count = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec3 t{param(0, (i + 0.5) / n), param(1, (j + 0.5) / n), param(2, (k + 0.5) / n)};
        const bool a = at(t);
        in[static_cast<std::size_t>(i + n * (j + n * k))] = a;
        if (!a) continue;
        ++count;
        const int idx[3] = {i, j, k};
        for (std::size_t d = 0; d < 3; ++d) i0[d] = std::min(i0[d], idx[d]), i1[d] = std::max(i1[d], idx[d]);
      }
  if (count == 0) return false;
  if (count != (i1[0] - i0[0] + 1) * (i1[1] - i0[1] + 1) * (i1[2] - i0[2] + 1)) return false;  // not an index box
  if (count == n * n * n) return false;  // nothing to restrict
  // Each cut face by bisection along the line through the box's centre.
  Vec3 centre;
  for (std::size_t d = 0; d < 3; ++d) centre[d] = param(d, (i0[d] + i1[d] + 1) / (2.0 * n));
  for (std::size_t d = 0; d < 3; ++d) {
    lo[d] = dom[0][d];
    hi[d] = dom[1][d];
    for (int side = 0; side < 2; ++side) {
      const int edge = side == 0 ? i0[d] : i1[d];
      if ((side == 0 && edge == 0) || (side == 1 && edge == n - 1)) continue;
      double a = param(d, (edge + 0.5) / n);                        // admitted
      double b = param(d, (edge + (side == 0 ? -0.5 : 1.5)) / n);   // not admitted
      Vec3 t = centre;
      while (std::abs(b - a) > 1e-13 * (dom[1][d] - dom[0][d])) {
        t[d] = 0.5 * (a + b);
        (at(t) ? a : b) = t[d];
      }
      (side == 0 ? lo : hi)[d] = 0.5 * (a + b);
    }
  }
  // Checks: inside the box everything is admitted; just outside every cut face nothing is.
  constexpr int m = 9;
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const int idx[3] = {i, j, k};
        Vec3 t;
        for (std::size_t d = 0; d < 3; ++d) t[d] = lo[d] + (hi[d] - lo[d]) * (0.02 + 0.96 * idx[d] / (m - 1));
        if (!at(t)) return false;
        for (std::size_t d = 0; d < 3; ++d) {
          if (idx[d] != 0 && idx[d] != m - 1) continue;
          const bool low = idx[d] == 0;
          const double eps = 1e-6 * (dom[1][d] - dom[0][d]);
          if (low ? lo[d] <= dom[0][d] : hi[d] >= dom[1][d]) continue;
          Vec3 q = t;
          q[d] = low ? lo[d] - eps : hi[d] + eps;
          if (at(q)) return false;
        }
      }
  return true;
}

}  // namespace

vmodel::VModel untrim(const vmodel::VModel& model) {
  vmodel::VModel out = model;
  bool any = false;
  for (const auto& c : model.cells) any = any || !c.plain();
  if (!any) return out;
  const Locator loc(model, {.tolerance = 1e-10 * model_diagonal(model)});
  for (std::size_t c = 0; c < model.cells.size(); ++c) {
    if (model.cells[c].plain()) continue;
    Vec3 lo, hi;
    if (!admitted_box(loc, static_cast<int>(c), lo, hi)) continue;
    auto& v = out.cells[c].volume;
    const auto dom = loc.domain(static_cast<int>(c));
    for (std::size_t d = 0; d < 3; ++d)
      if (lo[d] > dom[0][d] || hi[d] < dom[1][d]) v = spline::restrict_to(v, static_cast<int>(d), lo[d], hi[d]);
  }
  return out;
}

}  // namespace trivox::slice
