#include "trivox/slice/piece_measures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include "../geom/patch_quadrature.hpp"
#include "trivox/error.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::slice {

namespace {

/// Sums over the oriented patches, about the point c.
struct Sums {
  std::array<double, 3> normal{};  ///< int n_i dA
  std::array<double, 3> volume{};  ///< int (x_i - c_i) n_i dA
  std::array<double, 3> moment{};  ///< 1/2 int (x_i - c_i)^2 n_i dA
};

/// Adds a patch's integrands at its Gauss points, 2 x order per direction: x_i^2 n_i has
/// degree 4p - 1 in a direction of degree p, which 2p + 2 points integrate exactly.
void integrate(const spline::Surface& p, int sign, const std::array<double, 3>& c, geom::detail::PatchRules& rules,
               std::vector<geom::detail::PatchPoint>& pts, Sums& s) {
  geom::detail::patch_points(p, [](int order) { return 2 * order; }, rules, pts);
  for (const auto& q : pts) {
    const auto &xs = q.xs, &xt = q.xt;
    const double n[3] = {xs[1] * xt[2] - xs[2] * xt[1], xs[2] * xt[0] - xs[0] * xt[2], xs[0] * xt[1] - xs[1] * xt[0]};
    const double w = sign * q.w;
    for (std::size_t k = 0; k < 3; ++k) {
      const double y = q.x[k] - c[k];
      s.normal[k] += w * n[k];
      s.volume[k] += w * y * n[k];
      s.moment[k] += w * 0.5 * y * y * n[k];
    }
  }
}

/// The largest of a scalar patch's corner coefficients (points on a clamped patch).
double corner_max(const spline::Surface& g) {
  const auto& a = g.points();
  const std::size_t ns = static_cast<std::size_t>(g.count(0)), n = a.size();
  return std::max({a[0], a[ns - 1], a[n - ns], a[n - 1]});
}

/// Raises `best` to the maximum of the scalar Bezier patch g within tol (branch and bound on
/// the coefficients' convex hull, halving by spline::split); false when the budget ran out
/// (best then also holds the remaining coefficient bounds).
bool patch_max(const spline::Surface& g, double tol, int budget, double& best) {
  std::vector<spline::Surface> stack{g};
  double bound = -std::numeric_limits<double>::infinity();
  bool tight = true;
  while (!stack.empty()) {
    spline::Surface h = std::move(stack.back());
    stack.pop_back();
    const auto& a = h.points();
    const double m = *std::max_element(a.begin(), a.end());
    if (m <= best + tol) continue;
    best = std::max(best, corner_max(h));
    if (m <= best + tol) continue;
    if (budget-- <= 0) {
      bound = std::max(bound, m);
      tight = false;
      continue;
    }
    // Split across the direction along which the coefficients vary most.
    const int ns = h.count(0), nt = h.count(1);
    auto at = [&](int i, int j) { return a[static_cast<std::size_t>(i + ns * j)]; };
    double vs = 0, vt = 0;
    for (int j = 0; j < nt; ++j)
      for (int i = 0; i + 1 < ns; ++i) vs = std::max(vs, std::abs(at(i + 1, j) - at(i, j)));
    for (int j = 0; j + 1 < nt; ++j)
      for (int i = 0; i < ns; ++i) vt = std::max(vt, std::abs(at(i, j + 1) - at(i, j)));
    const int dir = vs >= vt ? 0 : 1;
    const auto d = h.domain(dir);
    auto [lo, hi] = spline::split(h, dir, 0.5 * (d[0] + d[1]));
    stack.push_back(std::move(lo));
    stack.push_back(std::move(hi));
  }
  best = std::max(best, bound);
  return tight;
}

void check_polynomial(const vmodel::VCell& c, const std::string& what) {
  if (c.volume.rational())
    throw Error("piece_measures: " + what + " '" + c.name +
                    "' is rational; expected polynomial trivariates (untrimming composes polynomial surfaces)",
                ErrorKind::failed);
}

/// A planar face: its unit normal and offset (n . x = d for every control point within eps).
struct Plane {
  bool planar = false;
  std::array<double, 3> n{};
  double d = 0;
  std::array<std::array<double, 3>, 2> box{};
};

Plane plane_of(const spline::Surface& f, double eps) {
  Plane pl;
  const auto pts = f.points();
  const std::size_t dim = static_cast<std::size_t>(f.dim()), m = pts.size() / dim;
  auto P = [&](std::size_t i) { return std::array<double, 3>{pts[i * dim], pts[i * dim + 1], pts[i * dim + 2]}; };
  for (std::size_t k = 0; k < 3; ++k) pl.box[0][k] = pl.box[1][k] = pts[k];
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t k = 0; k < 3; ++k)
      pl.box[0][k] = std::min(pl.box[0][k], P(i)[k]), pl.box[1][k] = std::max(pl.box[1][k], P(i)[k]);
  // The normal from the control net's corners (the face's corners).
  const auto c = f.counts();
  const auto a = P(0), b = P(static_cast<std::size_t>(c[0] - 1)), e = P(static_cast<std::size_t>(c[0] * (c[1] - 1))),
             g = P(m - 1);
  const std::array<double, 3> u{g[0] - a[0], g[1] - a[1], g[2] - a[2]}, v{e[0] - b[0], e[1] - b[1], e[2] - b[2]};
  std::array<double, 3> n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double len = std::hypot(n[0], n[1], n[2]);
  if (!(len > 0)) return pl;
  for (auto& x : n) x /= len;
  pl.n = n;
  pl.d = n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
  for (std::size_t i = 0; i < m; ++i) {
    const auto x = P(i);
    if (std::abs(n[0] * x[0] + n[1] * x[1] + n[2] * x[2] - pl.d) > eps) return pl;
  }
  pl.planar = true;
  return pl;
}

/// Two planar faces on one plane whose boxes overlap with positive extent in two directions:
/// coincident regions, which boundary_faces does not cut.
bool coincide(const Plane& p, const Plane& q, double eps) {
  if (!p.planar || !q.planar) return false;
  const double dot = p.n[0] * q.n[0] + p.n[1] * q.n[1] + p.n[2] * q.n[2];
  if (std::abs(std::abs(dot) - 1) > 1e-12 || std::abs(p.d - (dot > 0 ? q.d : -q.d)) > eps) return false;
  int wide = 0;
  for (std::size_t k = 0; k < 3; ++k)
    wide += std::min(p.box[1][k], q.box[1][k]) - std::max(p.box[0][k], q.box[0][k]) > eps;
  return wide >= 2;
}

}  // namespace

PieceMeasures piece_measures(const vmodel::VModel& model, int cell, const PieceMeasureOptions& options) {
  if (cell < 0 || cell >= static_cast<int>(model.cells.size()))
    throw Error("piece_measures: cell " + std::to_string(cell) + " out of range; the model has " +
                std::to_string(model.cells.size()) + " cells");
  // Refuse rational sources before the intersections (geom::TrimmedSurface would, later).
  const vmodel::VCell& c = model.cells[static_cast<std::size_t>(cell)];
  check_polynomial(c, "cell");
  for (const auto& w : c.within) check_polynomial(w, "condition");
  for (const auto& list : c.without)
    for (const auto& w : list) check_polynomial(w, "condition");
  // Coplanar faces of two sources: boundary_faces classifies them whole (no intersection curve
  // cuts them), so a shared region would be kept twice or not at all; refused here before the
  // intersections (geom::face_trim can be slow to refuse the thin regions they leave).
  // Cells of one `without` list are one solid: their shared faces are coplanar by construction
  // and boundary_faces handles them, so only faces of different solids are compared.
  std::vector<const vmodel::VCell*> src{&c};
  std::vector<int> solid{0};
  for (const auto& w : c.within) src.push_back(&w), solid.push_back(static_cast<int>(solid.size()));
  int next = static_cast<int>(solid.size());
  for (const auto& list : c.without) {
    for (const auto& w : list) src.push_back(&w), solid.push_back(next);
    ++next;
  }
  if (static_cast<int>(src.size()) - 1 > options.max_conditions)
    throw Error("piece_measures: cell " + std::to_string(cell) + " (" + c.name + ") has " + std::to_string(src.size() - 1) +
                    " direct conditions; expected at most " + std::to_string(options.max_conditions) +
                    " (its boundary faces intersect 36 (1 + C)^2 pairs of faces)",
                ErrorKind::failed);
  const double eps = 1e-9 * model_diagonal(model);
  std::vector<std::array<Plane, 6>> planes(src.size());
  for (std::size_t k = 0; k < src.size(); ++k)
    for (std::size_t f = 0; f < 6; ++f) planes[k][f] = plane_of(spline::boundary_face(src[k]->volume, spline::all_faces[f]), eps);
  for (std::size_t k = 0; k < src.size(); ++k)
    for (std::size_t j = k + 1; j < src.size(); ++j) {
      if (solid[j] == solid[k]) continue;
      for (std::size_t f = 0; f < 6; ++f)
        for (std::size_t g = 0; g < 6; ++g)
          if (coincide(planes[k][f], planes[j][g], eps))
            throw Error("piece_measures: cell " + std::to_string(cell) + " (" + c.name + "): face " +
                            std::string(spline::face_name(spline::all_faces[f])) + " of '" + src[k]->name + "' and face " +
                            std::string(spline::face_name(spline::all_faces[g])) + " of '" + src[j]->name +
                            "' are coplanar and overlap; expected faces that cross or miss (coincident faces are not cut)",
                        ErrorKind::failed);
    }
  return piece_measures(boundary_faces(model, cell, options.faces), cell, options);
}

PieceMeasures piece_measures(const std::vector<BoundaryFace>& faces, int cell, const PieceMeasureOptions& options) {
  PieceMeasures r;
  r.cell = cell;
  r.faces = static_cast<int>(faces.size());
  if (faces.empty()) return r;
  r.empty = false;
  // The patches' control boxes: the centre c and the diagonal.
  std::array<double, 3> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (const auto& f : faces)
    for (const auto& p : f.patches.patches) {
      ++r.patches;
      const auto pts = p.points();
      for (std::size_t q = 0; q < pts.size(); q += static_cast<std::size_t>(p.dim()))
        for (std::size_t k = 0; k < 3; ++k) lo[k] = std::min(lo[k], pts[q + k]), hi[k] = std::max(hi[k], pts[q + k]);
    }
  if (r.patches == 0) throw Error("piece_measures: cell " + std::to_string(cell) + ": boundary faces without patches", ErrorKind::failed);
  std::array<double, 3> c;
  double diag = 0;
  for (std::size_t k = 0; k < 3; ++k) c[k] = 0.5 * (lo[k] + hi[k]), diag += (hi[k] - lo[k]) * (hi[k] - lo[k]);
  diag = std::sqrt(diag);

  Sums s;
  geom::detail::PatchRules rules;
  std::vector<geom::detail::PatchPoint> pts;
  for (const auto& f : faces) {
    r.area += f.area;
    for (const auto& p : f.patches.patches) integrate(p, f.orientation, c, rules, pts, s);
  }
  r.volume = (s.volume[0] + s.volume[1] + s.volume[2]) / 3;
  r.closure = std::hypot(s.normal[0], s.normal[1], s.normal[2]) / r.area;
  for (std::size_t k = 0; k < 3; ++k) r.spread = std::max(r.spread, std::abs(s.volume[k] - r.volume) / (r.area * diag));
  const std::string where = "piece_measures: cell " + std::to_string(cell);
  auto fig = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", v);
    return std::string(b);
  };
  if (!(r.closure <= options.check_tolerance) || !(r.spread <= options.check_tolerance))
    throw Error(where + ": the boundary faces do not close (|int n dA| / area " + fig(r.closure) +
                    ", volumes by x, y, z differ by " + fig(r.spread) + " of area x diagonal); expected at most " +
                    fig(options.check_tolerance),
                ErrorKind::failed);
  if (!(r.volume > 0))
    throw Error(where + ": the boundary encloses volume " + fig(r.volume) + "; expected a positive volume (outward faces)",
                ErrorKind::failed);
  for (std::size_t k = 0; k < 3; ++k) r.centroid[k] = c[k] + s.moment[k] / r.volume;

  // The tight box: per coordinate and side, branch and bound over every patch, starting from
  // the best corner of all patches so that most patches are discarded at once.
  const double tol = options.bbox_tolerance * diag;
  for (std::size_t k = 0; k < 3; ++k)
    for (int side = 0; side < 2; ++side) {
      const double sg = side ? 1.0 : -1.0;  // maximise sg * x_k
      std::vector<spline::Surface> grids;
      double best = -std::numeric_limits<double>::infinity();
      for (const auto& f : faces)
        for (const auto& p : f.patches.patches) {
          std::vector<double> a;
          const auto pts = p.points();
          for (std::size_t q = 0; q < pts.size(); q += static_cast<std::size_t>(p.dim())) a.push_back(sg * pts[q + k]);
          spline::Surface g({p.knots(0), p.knots(1)}, 1, std::move(a));
          // A patch of several knot spans (untrim's sides of many Bezier pieces): its Bezier pieces.
          const bool several = p.count(0) != p.orders()[0] || p.count(1) != p.orders()[1];
          for (auto& b : several ? spline::bezier_pieces(g) : std::vector<spline::Surface>{std::move(g)}) {
            best = std::max(best, corner_max(b));
            grids.push_back(std::move(b));
          }
        }
      for (const auto& g : grids) r.bbox_tight = patch_max(g, tol, options.bbox_budget, best) && r.bbox_tight;
      r.bbox[static_cast<std::size_t>(side)][k] = sg * best;
    }
  return r;
}

}  // namespace trivox::slice
