#include "trivox/vmodel/boundary_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <unordered_map>
#include <utility>

#include "../detail/union_find.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/vmodel/topology.hpp"

namespace trivox::vmodel {

namespace {

using spline::Face;
using spline::Trivariate;
using Vec3 = std::array<double, 3>;

std::size_t idx(int i) noexcept { return static_cast<std::size_t>(i); }

double norm(const Vec3& a) noexcept { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

/// The two directions other than d, ascending.
std::array<int, 2> others(int d) noexcept { return {d == 0 ? 1 : 0, d == 2 ? 1 : 2}; }

/// Parameter at normalised position i / n of direction d, the ends exact.
double param(const Trivariate& s, int d, int i, int n) noexcept {
  const auto dom = s.domain(d);
  if (i <= 0) return dom[0];
  if (i >= n) return dom[1];
  return dom[0] + (dom[1] - dom[0]) * static_cast<double>(i) / static_cast<double>(n);
}

/// Parameter at position x in [0, 1] of direction d (for midpoints).
double param_at(const Trivariate& s, int d, double x) noexcept {
  const auto dom = s.domain(d);
  return dom[0] + (dom[1] - dom[0]) * x;
}

using detail::UnionFind;

/// One face to tessellate.
struct MeshFace {
  int half = -1;  ///< half-V-surface
  int cell = -1;
  Face face = Face::u0;
  int dir = 0, side = 0, d1 = 1, d2 = 2;  ///< fixed direction and side; s and t directions
  bool flip = false;                      ///< reverse the natural orientation S_s x S_t
  std::array<int, 2> need{1, 1};          ///< segments the face needs along s and t
};

/// The point of face `mf` at grid (i, j) of ns x nt segments, the cell's parameters.
std::array<double, 3> face_params(const Trivariate& s, const MeshFace& mf, double a, double b) noexcept {
  std::array<double, 3> t{};
  t[idx(mf.dir)] = s.domain(mf.dir)[idx(mf.side)];
  t[idx(mf.d1)] = a;
  t[idx(mf.d2)] = b;
  return t;
}

/// Samples |S_ss|, |S_st|, |S_tt| of the face (three points per knot span, at most 64 per
/// direction) and returns the segment counts that keep each term of the error bound below tol/3.
std::array<int, 2> estimate_counts(const Trivariate& s, const MeshFace& mf, double tol, int max_segments) {
  auto positions = [&](int d) {
    std::vector<double> x;
    const auto dom = s.domain(d);
    std::vector<double> breaks;
    for (double k : s.knots(d).knots())
      if (k >= dom[0] && k <= dom[1] && (breaks.empty() || k > breaks.back())) breaks.push_back(k);
    if (breaks.size() >= 2 && breaks.size() <= 22) {
      for (std::size_t k = 0; k + 1 < breaks.size(); ++k)
        for (int q = 0; q < 3; ++q) x.push_back(breaks[k] + (breaks[k + 1] - breaks[k]) * q / 2.0);
    } else {
      for (int q = 0; q < 64; ++q) x.push_back(dom[0] + (dom[1] - dom[0]) * q / 63.0);
    }
    return x;
  };
  const auto xs = positions(mf.d1), xt = positions(mf.d2);
  // Derivatives of the trivariate: slots of the second partials in directions d1, d2.
  auto unit = [](int a) {
    std::array<int, 3> alpha{};
    alpha[idx(a)] = 1;
    return alpha;
  };
  auto slot = [](int a, int b) {
    std::array<int, 3> alpha{};
    ++alpha[idx(a)];
    ++alpha[idx(b)];
    return spline::derivative_slot<3>(alpha);
  };
  const int sss = slot(mf.d1, mf.d1), sst = slot(mf.d1, mf.d2), stt = slot(mf.d2, mf.d2);
  const int dim = s.dim();
  std::vector<double> der(idx(spline::derivative_count(3, 2) * dim));
  double mss = 0.0, mst = 0.0, mtt = 0.0;
  for (double b : xt)
    for (double a : xs) {
      s.eval_derivatives(face_params(s, mf, a, b), 2, der.data());
      // The normal components: a surface's deviation from its chords is along its normal (a
      // planar face deviates by nothing, however it is parametrised). Where the normal vanishes
      // (a pole, a collapsed edge) the sample is skipped: the midpoint check covers it.
      const double* ds = &der[idx(spline::derivative_slot<3>(unit(mf.d1)) * dim)];
      const double* dt = &der[idx(spline::derivative_slot<3>(unit(mf.d2)) * dim)];
      Vec3 n{ds[1] * dt[2] - ds[2] * dt[1], ds[2] * dt[0] - ds[0] * dt[2], ds[0] * dt[1] - ds[1] * dt[0]};
      const double len = norm(n), scale = norm({ds[0], ds[1], ds[2]}) * norm({dt[0], dt[1], dt[2]});
      const bool normal = len > 1e-9 * scale && len > 0.0;
      if (!normal) continue;
      auto mag = [&](int sl) {
        const double* p = &der[idx(sl * dim)];
        return std::abs(p[0] * n[0] + p[1] * n[1] + p[2] * n[2]) / len;
      };
      mss = std::max(mss, mag(sss));
      mst = std::max(mst, mag(sst));
      mtt = std::max(mtt, mag(stt));
    }
  const double ls = s.domain(mf.d1)[1] - s.domain(mf.d1)[0], lt = s.domain(mf.d2)[1] - s.domain(mf.d2)[0];
  // h^2 M / 8 <= tol / 3  <=>  n >= L sqrt(3 M / (8 tol)).
  auto count = [&](double l, double m) {
    const double n = std::ceil(l * std::sqrt(3.0 * m / (8.0 * tol)));
    return std::isfinite(n) ? static_cast<int>(std::clamp(n, 1.0, static_cast<double>(max_segments) + 1.0)) : max_segments + 1;
  };
  int ns = count(ls, mss), nt = count(lt, mtt);
  // The cross term h_s h_t M_st / 4 <= tol / 3: both counts scaled by the same factor.
  const double cross = (ls / ns) * (lt / nt) * mst / 4.0;
  if (cross > tol / 3.0) {
    const double f = std::sqrt(cross / (tol / 3.0));
    ns = static_cast<int>(std::min<double>(std::ceil(ns * f), max_segments + 1.0));
    nt = static_cast<int>(std::min<double>(std::ceil(nt * f), max_segments + 1.0));
  }
  return {ns, nt};
}

/// The face's grid of (ns + 1) x (nt + 1) points (all coordinates), index i + (ns + 1) j, and the
/// largest deviation of the surface from the chords at segment midpoints along s, along t and
/// at quad centres (from the diagonal (i, j)-(i+1, j+1)).
struct FaceGrid {
  int ns = 0, nt = 0;
  std::vector<double> points;
  std::array<double, 3> deviation{};
};

FaceGrid sample_face(const Trivariate& s, const MeshFace& mf, int ns, int nt) {
  FaceGrid g;
  g.ns = ns;
  g.nt = nt;
  const int dim = s.dim();
  const std::size_t row = idx(ns + 1);
  g.points.resize(row * idx(nt + 1) * idx(dim));
  for (int j = 0; j <= nt; ++j)
    for (int i = 0; i <= ns; ++i)
      s.eval(face_params(s, mf, param(s, mf.d1, i, ns), param(s, mf.d2, j, nt)), &g.points[(idx(i) + row * idx(j)) * idx(dim)]);
  auto at = [&](int i, int j) { return &g.points[(idx(i) + row * idx(j)) * idx(dim)]; };
  std::vector<double> m(idx(dim));
  auto sub = [](const double* p, const double* q) { return Vec3{p[0] - q[0], p[1] - q[1], p[2] - q[2]}; };
  auto dot = [](const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  // The unit normal of quad (i, j) from its diagonals, or zero when they are parallel.
  auto quad_normal = [&](int i, int j) {
    const Vec3 a = sub(at(i + 1, j + 1), at(i, j)), b = sub(at(i, j + 1), at(i + 1, j));
    Vec3 n{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    const double len = norm(n);
    if (!(len > 1e-12 * norm(a) * norm(b))) return Vec3{};
    for (double& x : n) x /= len;
    return n;
  };
  // Surface point m against the chord p-q: on the face's boundary (shared with the neighbour)
  // the distance from the chord's line; inside, along the normal n (in-plane distortion of the
  // parametrisation is no deviation), or the distance from the chord's midpoint where n is zero.
  auto deviation = [&](const double* p, const double* q, bool boundary, const Vec3& n) {
    const Vec3 mid{m[0] - 0.5 * (p[0] + q[0]), m[1] - 0.5 * (p[1] + q[1]), m[2] - 0.5 * (p[2] + q[2])};
    if (boundary) {
      const Vec3 d = sub(q, p);
      const double l2 = dot(d, d);
      if (l2 == 0.0) return norm(mid);
      const double f = dot(mid, d) / l2;
      return norm({mid[0] - f * d[0], mid[1] - f * d[1], mid[2] - f * d[2]});
    }
    if (n == Vec3{}) return norm(mid);
    return std::abs(dot(mid, n));
  };
  const double hs = 1.0 / ns, ht = 1.0 / nt;
  for (int j = 0; j <= nt; ++j)
    for (int i = 0; i < ns; ++i) {
      s.eval(face_params(s, mf, param_at(s, mf.d1, (i + 0.5) * hs), param(s, mf.d2, j, nt)), m.data());
      const bool edge = j == 0 || j == nt;
      g.deviation[0] = std::max(g.deviation[0], deviation(at(i, j), at(i + 1, j), edge, edge ? Vec3{} : quad_normal(i, j)));
    }
  for (int j = 0; j < nt; ++j)
    for (int i = 0; i <= ns; ++i) {
      s.eval(face_params(s, mf, param(s, mf.d1, i, ns), param_at(s, mf.d2, (j + 0.5) * ht)), m.data());
      const bool edge = i == 0 || i == ns;
      g.deviation[1] = std::max(g.deviation[1], deviation(at(i, j), at(i, j + 1), edge, edge ? Vec3{} : quad_normal(i, j)));
    }
  for (int j = 0; j < nt; ++j)
    for (int i = 0; i < ns; ++i) {
      s.eval(face_params(s, mf, param_at(s, mf.d1, (i + 0.5) * hs), param_at(s, mf.d2, (j + 0.5) * ht)), m.data());
      g.deviation[2] = std::max(g.deviation[2], deviation(at(i, j), at(i + 1, j + 1), false, quad_normal(i, j)));
    }
  return g;
}

/// Whether faces f and g of one cell coincide (on a 5 x 5 grid, any of the 8 orientations).
bool same_cell_faces_coincide(const Trivariate& s, Face f, Face g, double tol) {
  constexpr int n = 5;
  auto grid = [&](Face face) {
    MeshFace mf;
    mf.dir = static_cast<int>(face) / 2;
    mf.side = static_cast<int>(face) % 2;
    const auto o = others(mf.dir);
    mf.d1 = o[0];
    mf.d2 = o[1];
    std::vector<Vec3> out(idx(n * n));
    std::vector<double> p(idx(s.dim()));
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        s.eval(face_params(s, mf, param(s, mf.d1, i, n - 1), param(s, mf.d2, j, n - 1)), p.data());
        out[idx(i + n * j)] = {p[0], p[1], p[2]};
      }
    return out;
  };
  const auto a = grid(f), b = grid(g);
  for (int o = 0; o < 8; ++o) {
    const Orientation orient = Orientation::from_index(o);
    bool same = true;
    for (int j = 0; j < n && same; ++j)
      for (int i = 0; i < n && same; ++i) {
        int p = orient.swap ? j : i, q = orient.swap ? i : j;
        if (orient.reverse_first) p = n - 1 - p;
        if (orient.reverse_second) q = n - 1 - q;
        const Vec3& x = a[idx(i + n * j)];
        const Vec3& y = b[idx(p + n * q)];
        same = norm({x[0] - y[0], x[1] - y[1], x[2] - y[2]}) <= tol;
      }
    if (same) return true;
  }
  return false;
}

/// Corner index (i + 2j + 4k) with the given side per direction.
int corner_of(const std::array<int, 3>& side) noexcept { return side[0] + 2 * side[1] + 4 * side[2]; }

/// Start corner of cell edge e (topology.hpp conventions).
int edge_start(int e) noexcept {
  const auto o = others(e / 4);
  std::array<int, 3> side{};
  side[idx(o[0])] = e & 1;
  side[idx(o[1])] = (e >> 1) & 1;
  return corner_of(side);
}

/// The cell edges s=0, s=1, t=0, t=1 of face f (as topology.cpp numbers them).
std::array<int, 4> face_edges(int dir, int side, int d1, int d2) noexcept {
  auto edge_index = [](int along, const std::array<int, 3>& sd) {
    const auto o = others(along);
    return 4 * along + sd[idx(o[0])] + 2 * sd[idx(o[1])];
  };
  std::array<int, 3> sd{};
  sd[idx(dir)] = side;
  std::array<int, 4> out{};
  for (int k = 0; k < 2; ++k) {
    sd[idx(d2)] = 0;
    sd[idx(d1)] = k;
    out[idx(k)] = edge_index(d2, sd);
    sd[idx(d1)] = 0;
    sd[idx(d2)] = k;
    out[idx(2 + k)] = edge_index(d1, sd);
  }
  return out;
}

void check_options(const MeshOptions& o) {
  if (!(std::isfinite(o.tolerance) && o.tolerance >= 0.0))
    throw Error("mesh: tolerance " + std::to_string(o.tolerance) + "; expected a finite value >= 0 (0: relative to the model)");
  if (!(o.relative_tolerance > 0.0 && o.relative_tolerance <= 0.1))
    throw Error("mesh: relative tolerance " + std::to_string(o.relative_tolerance) + "; expected a value in (0, 0.1]");
  if (o.max_segments < 1 || o.max_segments > 1'000'000)
    throw Error("mesh: max_segments " + std::to_string(o.max_segments) + "; expected 1..1000000");
  if (o.max_triangles < 1) throw Error("mesh: max_triangles " + std::to_string(o.max_triangles) + "; expected at least 1");
}

std::string cell_label(const VModel& model, int c) {
  return "cell \"" + model.cells[idx(c)].name + "\" (" + std::to_string(c) + ")";
}

}  // namespace

BoundaryMesh mesh_boundary(const VModel& model, const MeshOptions& options) {
  check_options(options);
  const int n_cells = static_cast<int>(model.cells.size());
  for (int c = 0; c < n_cells; ++c) {
    const VCell& cell = model.cells[idx(c)];
    if (!cell.plain() || !cell.trim_curves.empty())
      throw Error(cell_label(model, c) +
                  ": trimmed by a Boolean (within/without cells or trimming curves); expected untrimmed cells "
                  "(the boundary of trimmed cells is not meshed yet)");
    if (cell.volume.dim() < 3)
      throw Error(cell_label(model, c) + ": " + std::to_string(cell.volume.dim()) +
                  " coordinates per control point; expected at least 3 (xyz)");
  }
  BoundaryMesh mesh;
  mesh.property_names = model.properties;
  if (n_cells == 0) return mesh;

  // The tolerance, from the diagonal of the xyz control box when not given.
  Vec3 lo{}, hi{};
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (const auto& cell : model.cells) {
    const auto box = cell.volume.control_box();
    for (std::size_t d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], box[0][d]);
      hi[d] = std::max(hi[d], box[1][d]);
    }
  }
  const double diag = norm({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  const double tol = options.tolerance > 0.0 ? options.tolerance : options.relative_tolerance * diag;
  if (!(tol > 0.0)) throw Error("mesh: the model has no extent (diagonal 0); expected cells with volume");
  mesh.tolerance = tol;
  // Geometry that agrees within 1% of the chordal tolerance is one at the mesh's resolution:
  // faces, edges and corners are glued that close (a ring closed by fitting meets itself only
  // approximately; 1e-9 of the diagonal, the topology's default, would leave it open).
  TopologyOptions topo_options;
  topo_options.relative_tolerance = std::max(topo_options.relative_tolerance, 1e-2 * tol / diag);
  const Topology topo = build_topology(model, topo_options);

  // The sign of each cell's Jacobian, from its quadrature volume.
  std::vector<int> sign(idx(n_cells), 1);
  for (int c = 0; c < n_cells; ++c) {
    const double v = geom::signed_volume(model.cells[idx(c)].volume);
    sign[idx(c)] = v < 0.0 ? -1 : 1;
    mesh.cell_volume += std::abs(v);
  }

  // Faces of one cell that coincide are interior (a cell closed onto itself).
  std::vector<char> self_glued(topo.half_v_surfaces.size(), 0);
  for (int c = 0; c < n_cells; ++c)
    for (int a = 0; a < 6; ++a)
      for (int b = a + 1; b < 6; ++b) {
        const int ha = topo.cell_faces[idx(c)][idx(a)], hb = topo.cell_faces[idx(c)][idx(b)];
        if (ha < 0 || hb < 0 || topo.half_v_surfaces[idx(ha)].twin >= 0 || topo.half_v_surfaces[idx(hb)].twin >= 0)
          continue;
        if (same_cell_faces_coincide(model.cells[idx(c)].volume, static_cast<Face>(a), static_cast<Face>(b),
                                     std::max(topo.tolerance, 1e-12 * diag))) {
          self_glued[idx(ha)] = 1;
          self_glued[idx(hb)] = 1;
        }
      }

  std::vector<MeshFace> faces;
  for (int h = 0; h < static_cast<int>(topo.half_v_surfaces.size()); ++h) {
    const auto& half = topo.half_v_surfaces[idx(h)];
    if (self_glued[idx(h)] || (!options.per_cell && half.twin >= 0)) continue;
    MeshFace mf;
    mf.half = h;
    mf.cell = half.cell;
    mf.face = half.face;
    mf.dir = static_cast<int>(half.face) / 2;
    mf.side = static_cast<int>(half.face) % 2;
    const auto o = others(mf.dir);
    mf.d1 = o[0];
    mf.d2 = o[1];
    const int natural = (mf.side == 1 ? 1 : -1) * (mf.dir == 1 ? -1 : 1) * sign[idx(half.cell)];
    mf.flip = natural < 0;
    faces.push_back(mf);
  }
  mesh.faces = static_cast<int>(faces.size());
  const int n_faces = static_cast<int>(faces.size());
  const int n_curves = static_cast<int>(topo.v_curves.size());

  // Classes of edges: node q < n_curves is V-curve q; n_curves + 2k (+1) is face k's s (t)
  // direction, joined with its edges t=0, t=1 (s=0, s=1).
  UnionFind classes(idx(n_curves + 2 * n_faces));
  for (int k = 0; k < n_faces; ++k) {
    const auto& half = topo.half_v_surfaces[idx(faces[idx(k)].half)];
    for (int e = 0; e < 4; ++e) {
      const int q = half.v_curves[idx(e)];
      if (q >= 0) classes.join(n_curves + 2 * k + (e < 2 ? 1 : 0), q);
    }
  }

  const int cap = options.max_segments;
  auto refuse = [&](const MeshFace& mf, int n) {
    throw Error(cell_label(model, mf.cell) + ": face " + std::string(spline::face_name(mf.face)) + ": tolerance " +
                std::to_string(tol) + " needs " + std::to_string(n) + " segments along one direction; expected at most " +
                std::to_string(cap) + " (a coarser tolerance)");
  };
  for (auto& mf : faces) {
    mf.need = estimate_counts(model.cells[idx(mf.cell)].volume, mf, tol, cap);
    for (int n : mf.need)
      if (n > cap) refuse(mf, n);
  }

  // Rounds: unify the counts over the classes, sample, measure, refine where needed.
  std::vector<FaceGrid> grids(idx(n_faces));
  std::vector<int> class_count(idx(n_curves + 2 * n_faces), 1);
  for (int round = 1;; ++round) {
    std::fill(class_count.begin(), class_count.end(), 1);
    for (int k = 0; k < n_faces; ++k)
      for (int a = 0; a < 2; ++a) {
        const int r = classes.find(n_curves + 2 * k + a);
        class_count[idx(r)] = std::max(class_count[idx(r)], faces[idx(k)].need[idx(a)]);
      }
    std::int64_t triangles = 0;
    for (int k = 0; k < n_faces; ++k)
      triangles += 2LL * class_count[idx(classes.find(n_curves + 2 * k))] * class_count[idx(classes.find(n_curves + 2 * k + 1))];
    if (triangles > options.max_triangles)
      throw Error("mesh: tolerance " + std::to_string(tol) + " needs " + std::to_string(triangles) +
                  " triangles; expected at most " + std::to_string(options.max_triangles) + " (a coarser tolerance)");
    bool refined = false;
    mesh.max_deviation = 0.0;
    for (int k = 0; k < n_faces; ++k) {
      MeshFace& mf = faces[idx(k)];
      const int ns = class_count[idx(classes.find(n_curves + 2 * k))];
      const int nt = class_count[idx(classes.find(n_curves + 2 * k + 1))];
      FaceGrid& g = grids[idx(k)];
      if (g.ns != ns || g.nt != nt) g = sample_face(model.cells[idx(mf.cell)].volume, mf, ns, nt);
      const double worst = std::max({g.deviation[0], g.deviation[1], g.deviation[2]});
      mesh.max_deviation = std::max(mesh.max_deviation, worst);
      if (worst <= tol || round >= 8) continue;
      auto grow = [&](int a, int n, double dev) {
        if (dev <= tol) return;
        const double m = std::ceil(n * std::sqrt(dev / tol) * 1.1);
        const int want = static_cast<int>(std::min<double>(m, cap + 1.0));
        if (want > cap) refuse(mf, want);
        mf.need[idx(a)] = std::max(mf.need[idx(a)], want);
        refined = true;
      };
      grow(0, ns, std::max(g.deviation[0], g.deviation[2]));
      grow(1, nt, std::max(g.deviation[1], g.deviation[2]));
    }
    mesh.rounds = round;
    if (!refined) break;
  }

  // Vertices: V-points and V-curves once per scope (the model, or the cell with per_cell).
  const int m = static_cast<int>(model.properties.size());
  const int dim = 3 + m;
  std::map<std::pair<int, int>, int> point_vertex;
  std::map<std::pair<int, int>, std::vector<int>> curve_vertices;
  auto add_vertex = [&](const double* p) {
    mesh.vertices.push_back({p[0], p[1], p[2]});
    for (int h = 0; h < m; ++h) mesh.properties.push_back(p[3 + h]);
    return static_cast<int>(mesh.vertices.size()) - 1;
  };
  std::vector<double> buf(idx(dim));
  auto eval_cell = [&](int c, const std::array<double, 3>& t) {
    const Trivariate& s = model.cells[idx(c)].volume;
    std::vector<double> full(idx(s.dim()));
    s.eval(t, full.data());
    std::fill(buf.begin(), buf.end(), 0.0);
    std::copy_n(full.begin(), std::min(full.size(), buf.size()), buf.begin());
    return buf.data();
  };
  auto corner_params = [&](int c, int corner) {
    const Trivariate& s = model.cells[idx(c)].volume;
    return std::array<double, 3>{s.domain(0)[idx(corner & 1)], s.domain(1)[idx((corner >> 1) & 1)],
                                 s.domain(2)[idx((corner >> 2) & 1)]};
  };
  auto vpoint_vertex = [&](int scope, int c, int corner) {
    const int vp = topo.cell_corners[idx(c)][idx(corner)];
    auto [it, fresh] = point_vertex.try_emplace({scope, vp}, -1);
    if (fresh) it->second = add_vertex(eval_cell(c, corner_params(c, corner)));
    return it->second;
  };
  // Vertex at position `pos` of n along cell c's edge e (from its start corner), on V-curve q.
  auto curve_vertex = [&](int scope, int c, int e, int q, int pos, int n) {
    const auto& uses = topo.v_curves[idx(q)].uses;
    bool reversed = false;
    for (const auto& u : uses)
      if (u.cell == c && u.edge == e) reversed = u.reversed;
    auto [it, fresh] = curve_vertices.try_emplace({scope, q});
    if (fresh) {
      const Trivariate& s = model.cells[idx(c)].volume;
      const int along = e / 4;
      const auto o = others(along);
      std::array<double, 3> t{};
      t[idx(o[0])] = s.domain(o[0])[idx(e & 1)];
      t[idx(o[1])] = s.domain(o[1])[idx((e >> 1) & 1)];
      it->second.resize(idx(n - 1));
      for (int i = 1; i < n; ++i) {  // index i along the V-curve
        t[idx(along)] = param(s, along, reversed ? n - i : i, n);
        it->second[idx(i - 1)] = add_vertex(eval_cell(c, t));
      }
    }
    const int i = reversed ? n - pos : pos;
    return it->second[idx(i - 1)];
  };

  for (int k = 0; k < n_faces; ++k) {
    const MeshFace& mf = faces[idx(k)];
    const FaceGrid& g = grids[idx(k)];
    const int ns = g.ns, nt = g.nt, c = mf.cell;
    const int scope = options.per_cell ? c : 0;
    const auto& half = topo.half_v_surfaces[idx(mf.half)];
    const auto edges = face_edges(mf.dir, mf.side, mf.d1, mf.d2);
    const int cell_dim = model.cells[idx(c)].volume.dim();
    std::vector<int> ids(idx((ns + 1) * (nt + 1)));
    for (int j = 0; j <= nt; ++j)
      for (int i = 0; i <= ns; ++i) {
        const bool ci = i == 0 || i == ns, cj = j == 0 || j == nt;
        int id;
        if (ci && cj) {
          std::array<int, 3> sd{};
          sd[idx(mf.dir)] = mf.side;
          sd[idx(mf.d1)] = i == ns ? 1 : 0;
          sd[idx(mf.d2)] = j == nt ? 1 : 0;
          id = vpoint_vertex(scope, c, corner_of(sd));
        } else if (ci || cj) {
          const int e = ci ? (i == 0 ? 0 : 1) : (j == 0 ? 2 : 3);
          const int cell_edge = edges[idx(e)];
          const int q = half.v_curves[idx(e)];
          if (q < 0) id = vpoint_vertex(scope, c, edge_start(cell_edge));
          else id = ci ? curve_vertex(scope, c, cell_edge, q, j, nt) : curve_vertex(scope, c, cell_edge, q, i, ns);
        } else {
          const double* p = &g.points[(idx(i) + idx(ns + 1) * idx(j)) * idx(cell_dim)];
          std::fill(buf.begin(), buf.end(), 0.0);
          std::copy_n(p, std::min(cell_dim, dim), buf.begin());
          id = add_vertex(buf.data());
        }
        ids[idx(i + (ns + 1) * j)] = id;
      }
    auto emit = [&](int a, int b, int cc) {
      if (a == b || b == cc || a == cc) {
        ++mesh.dropped_triangles;
        return;
      }
      if (mf.flip) std::swap(b, cc);
      mesh.triangles.push_back({a, b, cc});
    };
    for (int j = 0; j < nt; ++j)
      for (int i = 0; i < ns; ++i) {
        const int a = ids[idx(i + (ns + 1) * j)], b = ids[idx(i + 1 + (ns + 1) * j)];
        const int cc = ids[idx(i + 1 + (ns + 1) * (j + 1))], d = ids[idx(i + (ns + 1) * (j + 1))];
        emit(a, b, cc);
        emit(a, cc, d);
      }
  }
  return mesh;
}

std::optional<std::array<int, 3>> colour_properties(const std::vector<std::string>& names) {
  std::array<int, 3> rgb{-1, -1, -1};
  for (int i = 0; i < static_cast<int>(names.size()); ++i) {
    if (names[idx(i)] == "r") rgb[0] = i;
    else if (names[idx(i)] == "g") rgb[1] = i;
    else if (names[idx(i)] == "b") rgb[2] = i;
  }
  if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) return std::nullopt;
  return rgb;
}

std::array<std::uint8_t, 3> vertex_colour(const BoundaryMesh& mesh, std::size_t v, const std::array<int, 3>& rgb) {
  std::array<std::uint8_t, 3> out{};
  const std::size_t m = mesh.property_names.size();
  for (std::size_t k = 0; k < 3; ++k) {
    const double c = mesh.properties[v * m + idx(rgb[k])];
    const double x = std::isfinite(c) ? std::clamp(c, 0.0, 1.0) : 0.0;
    out[k] = static_cast<std::uint8_t>(std::lround(x * 255.0));
  }
  return out;
}

double enclosed_volume(const BoundaryMesh& mesh) {
  if (mesh.vertices.empty()) return 0.0;
  Vec3 lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const auto& p : mesh.vertices)
    for (std::size_t d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], p[d]);
      hi[d] = std::max(hi[d], p[d]);
    }
  Vec3 o{};
  for (std::size_t d = 0; d < 3; ++d) o[d] = 0.5 * (lo[d] + hi[d]);
  double sum = 0.0;
  for (const auto& t : mesh.triangles) {
    const auto& pa = mesh.vertices[idx(t[0])];
    const auto& pb = mesh.vertices[idx(t[1])];
    const auto& pc = mesh.vertices[idx(t[2])];
    const Vec3 a{pa[0] - o[0], pa[1] - o[1], pa[2] - o[2]};
    const Vec3 b{pb[0] - o[0], pb[1] - o[1], pb[2] - o[2]};
    const Vec3 c{pc[0] - o[0], pc[1] - o[1], pc[2] - o[2]};
    sum += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return sum / 6.0;
}

double surface_area(const BoundaryMesh& mesh) {
  double sum = 0.0;
  for (const auto& t : mesh.triangles) {
    const auto& a = mesh.vertices[idx(t[0])];
    const auto& b = mesh.vertices[idx(t[1])];
    const auto& c = mesh.vertices[idx(t[2])];
    const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    sum += 0.5 * norm({u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]});
  }
  return sum;
}

namespace {

std::uint64_t edge_key(int a, int b) noexcept {
  const auto lo = static_cast<std::uint64_t>(std::min(a, b)), hi = static_cast<std::uint64_t>(std::max(a, b));
  return (lo << 32) | hi;
}

/// Per undirected edge: uses in the direction low -> high and high -> low, and the first
/// triangle using it.
struct EdgeUse {
  int forward = 0, backward = 0, triangle = -1;
};

std::unordered_map<std::uint64_t, EdgeUse> edge_uses(const BoundaryMesh& mesh) {
  std::unordered_map<std::uint64_t, EdgeUse> uses;
  uses.reserve(mesh.triangles.size() * 2);
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
    const auto& tri = mesh.triangles[idx(t)];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[idx(k)], b = tri[idx((k + 1) % 3)];
      if (a == b) continue;
      auto& u = uses[edge_key(a, b)];
      (a < b ? u.forward : u.backward)++;
      if (u.triangle < 0) u.triangle = t;
    }
  }
  return uses;
}

}  // namespace

EdgeReport edge_report(const BoundaryMesh& mesh) {
  EdgeReport r;
  for (const auto& t : mesh.triangles)
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) ++r.degenerate_triangles;
  const auto uses = edge_uses(mesh);
  r.edges = static_cast<std::int64_t>(uses.size());
  for (const auto& [key, u] : uses) {
    const int total = u.forward + u.backward;
    if (total == 1) ++r.boundary_edges;
    else if (total > 2 || u.forward != 1) ++r.non_manifold_edges;
  }
  return r;
}

bool edge_manifold(const BoundaryMesh& mesh) { return edge_report(mesh).manifold(); }

int shell_count(const BoundaryMesh& mesh) {
  const int n = static_cast<int>(mesh.triangles.size());
  UnionFind uf(n);
  std::unordered_map<std::uint64_t, int> first;
  first.reserve(idx(n) * 2);
  for (int t = 0; t < n; ++t) {
    const auto& tri = mesh.triangles[idx(t)];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[idx(k)], b = tri[idx((k + 1) % 3)];
      if (a == b) continue;
      auto [it, fresh] = first.try_emplace(edge_key(a, b), t);
      if (!fresh) uf.join(it->second, t);
    }
  }
  int shells = 0;
  for (int t = 0; t < n; ++t)
    if (uf.find(t) == t) ++shells;
  return shells;
}

std::int64_t euler_characteristic(const BoundaryMesh& mesh) {
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const auto& t : mesh.triangles)
    for (int v : t) used[idx(v)] = 1;
  const std::int64_t v = std::count(used.begin(), used.end(), 1);
  const std::int64_t e = static_cast<std::int64_t>(edge_uses(mesh).size());
  return v - e + static_cast<std::int64_t>(mesh.triangles.size());
}

}  // namespace trivox::vmodel
