#include "trivox/slice/trimmed_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "../detail/union_find.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/trimmed_surface.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/piece_measures.hpp"
#include "trivox/slice/trim.hpp"
#include "trivox/spline/extract.hpp"

namespace trivox::slice {

namespace {

using Vec3 = std::array<double, 3>;

std::size_t idx(int i) noexcept { return static_cast<std::size_t>(i); }
std::size_t idx(std::int64_t i) noexcept { return static_cast<std::size_t>(i); }

Vec3 sub(const Vec3& a, const Vec3& b) noexcept { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec3& a, const Vec3& b) noexcept { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) noexcept {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) noexcept { return std::sqrt(dot(a, a)); }

/// Distance from p to the segment [a, b] and the segment's parameter of the nearest point.
std::pair<double, double> segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) noexcept {
  const Vec3 d = sub(b, a);
  const double l2 = dot(d, d);
  double t = l2 > 0.0 ? dot(sub(p, a), d) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const Vec3 q{a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2]};
  return {norm(sub(p, q)), t};
}

/// Distance from p to the line through a and b (to a when they coincide).
double line_distance(const Vec3& p, const Vec3& a, const Vec3& b) noexcept {
  const Vec3 d = sub(b, a);
  const double l = norm(d);
  if (!(l > 0.0)) return norm(sub(p, a));
  return norm(cross(sub(p, a), d)) / l;
}

using detail::UnionFind;

/// Integer cell of a uniform hash grid, packed into one key.
struct GridKey {
  std::int64_t x, y, z;
  bool operator==(const GridKey&) const = default;
};
struct GridKeyHash {
  std::size_t operator()(const GridKey& k) const noexcept {
    const auto h = static_cast<std::uint64_t>(k.x) * 0x9E3779B97F4A7C15ULL ^
                   static_cast<std::uint64_t>(k.y) * 0xC2B2AE3D27D4EB4FULL ^ static_cast<std::uint64_t>(k.z) * 0x165667B19E3779F9ULL;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};
using HashGrid = std::unordered_map<GridKey, std::vector<int>, GridKeyHash>;

GridKey key_of(const Vec3& p, double h) noexcept {
  return {static_cast<std::int64_t>(std::floor(p[0] / h)), static_cast<std::int64_t>(std::floor(p[1] / h)),
          static_cast<std::int64_t>(std::floor(p[2] / h))};
}

/// A patch to tessellate, its grid and its four sides' samples.
struct Patch {
  const spline::Surface* surface = nullptr;
  const spline::Surface* domain = nullptr;  ///< the quad map into the face's parameters
  int face = -1;
  bool flip = false;  ///< reverse the natural orientation X_s x X_t
  int ns = 2, nt = 2;
  int dim = 3;
  std::vector<double> grid;  ///< (ns + 1) x (nt + 1) points, i (along s) fastest, dim values each
  int first_vertex = 0;      ///< index of grid point (0, 0) in the global vertex list
  /// Per side (0: t = 0, s rising; 1: s = 1, t rising; 2: t = 1, s rising; 3: s = 0, t rising)
  /// and per segment of its grid, the vertices inserted from other patches, in the side's order.
  std::array<std::vector<std::vector<int>>, 4> extra;
  std::array<bool, 4> collapsed{};

  const double* at(int i, int j) const noexcept {
    return grid.data() + (idx(j) * idx(ns + 1) + idx(i)) * idx(dim);
  }
  Vec3 xyz(int i, int j) const noexcept {
    const double* p = at(i, j);
    return {p[0], p[1], p[2]};
  }
  int vertex(int i, int j) const noexcept { return first_vertex + j * (ns + 1) + i; }
  int side_count(int k) const noexcept { return (k % 2 == 0) ? ns : nt; }
  /// Grid indices of sample m of side k.
  std::pair<int, int> side_ij(int k, int m) const noexcept {
    switch (k) {
      case 0: return {m, 0};
      case 1: return {ns, m};
      case 2: return {m, nt};
      default: return {0, m};
    }
  }
};

/// (s, t) of side k at parameter tau.
std::array<double, 2> side_st(int k, double tau) noexcept {
  switch (k) {
    case 0: return {tau, 0.0};
    case 1: return {1.0, tau};
    case 2: return {tau, 1.0};
    default: return {0.0, tau};
  }
}

Vec3 eval_xyz(const spline::Surface& s, double a, double b, std::vector<double>& buf) {
  buf.resize(idx(s.dim()));
  s.eval({a, b}, buf.data());
  return {buf[0], buf[1], buf[2]};
}

/// The point and unit normal (zero where X_s x X_t vanishes) at (a, b).
std::pair<Vec3, Vec3> eval_normal(const spline::Surface& s, double a, double b, std::vector<double>& buf) {
  const auto d = idx(s.dim());
  buf.resize(3 * d);
  s.eval_derivatives({a, b}, 1, buf.data());
  const Vec3 p{buf[0], buf[1], buf[2]}, xs{buf[d], buf[d + 1], buf[d + 2]}, xt{buf[2 * d], buf[2 * d + 1], buf[2 * d + 2]};
  Vec3 n = cross(xs, xt);
  const double l = norm(n);
  if (l > 0.0 && std::isfinite(l)) {
    n = {n[0] / l, n[1] / l, n[2] / l};
  } else {
    n = {0, 0, 0};
  }
  return {p, n};
}

/// Distance along the unit normal n of m from the chord midpoint c (the whole distance where n
/// is zero).
double normal_distance(const Vec3& m, const Vec3& c, const Vec3& n) noexcept {
  if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) return norm(sub(m, c));
  return std::abs(dot(sub(m, c), n));
}

/// Evaluates the grid of `p` and the midpoint check (see the header): the largest deviation along
/// s and along t.
std::array<double, 2> sample_patch(Patch& p, std::vector<double>& buf) {
  const auto& X = *p.surface;
  p.dim = X.dim();
  p.grid.assign(idx(p.ns + 1) * idx(p.nt + 1) * idx(p.dim), 0.0);
  for (int j = 0; j <= p.nt; ++j)
    for (int i = 0; i <= p.ns; ++i)
      X.eval({static_cast<double>(i) / p.ns, static_cast<double>(j) / p.nt},
             p.grid.data() + (idx(j) * idx(p.ns + 1) + idx(i)) * idx(p.dim));
  // The deviation of the segment a-b from the surface at its middle (s, t): from the side's curve
  // on the patch's boundary, along the normal inside.
  const auto deviation = [&](double s, double t, const Vec3& a, const Vec3& b, bool on_side) {
    if (on_side) return line_distance(eval_xyz(X, s, t, buf), a, b);
    const auto [m, n] = eval_normal(X, s, t, buf);
    return normal_distance(m, {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}, n);
  };
  double ds = 0.0, dt = 0.0;
  // Segments along s, rows j.
  for (int j = 0; j <= p.nt; ++j)
    for (int i = 0; i < p.ns; ++i)
      ds = std::max(ds, deviation((i + 0.5) / p.ns, static_cast<double>(j) / p.nt, p.xyz(i, j), p.xyz(i + 1, j),
                                  j == 0 || j == p.nt));
  // Segments along t, columns i.
  for (int i = 0; i <= p.ns; ++i)
    for (int j = 0; j < p.nt; ++j)
      dt = std::max(dt, deviation(static_cast<double>(i) / p.ns, (j + 0.5) / p.nt, p.xyz(i, j), p.xyz(i, j + 1),
                                  i == 0 || i == p.ns));
  // Quad centres against the triangulating diagonal (i, j) - (i + 1, j + 1).
  for (int j = 0; j < p.nt; ++j)
    for (int i = 0; i < p.ns; ++i) {
      const auto [m, n] = eval_normal(X, (i + 0.5) / p.ns, (j + 0.5) / p.nt, buf);
      const Vec3 a = p.xyz(i, j), b = p.xyz(i + 1, j + 1);
      const double dev = normal_distance(m, {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}, n);
      ds = std::max(ds, dev);
      dt = std::max(dt, dev);
    }
  return {ds, dt};
}

/// The point of side k of patch p nearest q by Gauss-Newton from tau0: (tau, distance).
std::pair<double, double> project_on_side(const Patch& p, int k, const Vec3& q, double tau0, std::vector<double>& buf) {
  const auto& X = *p.surface;
  const auto d = idx(X.dim());
  buf.resize(3 * d);
  const std::size_t slot = (k % 2 == 0) ? d : 2 * d;  // derivative along the side
  double tau = tau0;
  for (int it = 0; it < 30; ++it) {
    const auto st = side_st(k, tau);
    X.eval_derivatives({st[0], st[1]}, 1, buf.data());
    const Vec3 r{buf[0] - q[0], buf[1] - q[1], buf[2] - q[2]}, D{buf[slot], buf[slot + 1], buf[slot + 2]};
    const double dd = dot(D, D);
    if (!(dd > 0.0)) break;
    const double step = dot(r, D) / dd;
    const double next = std::clamp(tau - step, 0.0, 1.0);
    const bool done = std::abs(next - tau) < 1e-15;
    tau = next;
    if (done) break;
  }
  const auto st = side_st(k, tau);
  const Vec3 c = eval_xyz(X, st[0], st[1], buf);
  return {tau, norm(sub(c, q))};
}

/// Lengths below this fraction of the weld distance are nothing (a side of no length, a patch of
/// no width).
constexpr double kSameFace = 1e-4;

/// The length of a patch's boundary polyline at 8 segments a side.
double boundary_length(const spline::Surface& s, std::vector<double>& buf) {
  double len = 0.0;
  for (int k = 0; k < 4; ++k) {
    auto st = side_st(k, 0.0);
    Vec3 a = eval_xyz(s, st[0], st[1], buf);
    for (int m = 1; m <= 8; ++m) {
      st = side_st(k, m / 8.0);
      const Vec3 b = eval_xyz(s, st[0], st[1], buf);
      len += norm(sub(b, a));
      a = b;
    }
  }
  return len;
}

}  // namespace

bool has_trimmed_cells(const vmodel::VModel& model) noexcept {
  return std::any_of(model.cells.begin(), model.cells.end(), [](const vmodel::VCell& c) { return !c.plain(); });
}

namespace {

/// mesh_faces with the face of every vertex (the patch that made it first).
vmodel::BoundaryMesh mesh_faces_impl(const std::vector<BoundaryFace>& faces, double tol, double eps,
                                     const std::vector<std::string>& property_names, const vmodel::MeshOptions& o,
                                     std::vector<int>* vertex_face) {
  if (!(std::isfinite(tol) && tol > 0.0))
    throw Error("mesh: tolerance " + std::to_string(tol) + "; expected a finite value > 0");
  if (!(std::isfinite(eps) && eps > 0.0 && eps <= 0.5 * tol))
    throw Error("mesh: weld distance " + std::to_string(eps) + "; expected a value in (0, tolerance / 2]");
  // A side shorter than this is a point, a patch narrower than this a line.
  const double eps_face = kSameFace * eps;
  vmodel::BoundaryMesh mesh;
  mesh.tolerance = tol;
  mesh.property_names = property_names;
  const std::size_t nprops = property_names.size();

  // Patches of the faces with area, each sampled to the tolerance.
  std::vector<Patch> patches;
  std::vector<double> buf;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const auto& face = faces[f];
    if (!(face.area > 0.0)) continue;
    ++mesh.faces;
    if (face.patches.domains.size() != face.patches.patches.size())
      throw Error("mesh: face of cell " + std::to_string(face.cell) + ": " + std::to_string(face.patches.patches.size()) +
                  " patches but " + std::to_string(face.patches.domains.size()) + " quad maps; expected one per patch");
    for (std::size_t pi = 0; pi < face.patches.patches.size(); ++pi) {
      const auto& s = face.patches.patches[pi];
      if (s.dim() < 3 || idx(s.dim()) < 3 + nprops)
        throw Error("mesh: face of cell " + std::to_string(face.cell) + ": patch with " + std::to_string(s.dim()) +
                    " coordinates; expected xyz and " + std::to_string(nprops) + " properties");
      // A patch narrower than the same-face weld distance (a sliver of the untrimming) would
      // fold onto itself once its sides are welded; without it, its neighbours' sides weld.
      if (!(geom::surface_area(s, 2) > eps_face * boundary_length(s, buf))) continue;
      Patch p;
      p.surface = &s;
      p.domain = &face.patches.domains[pi];
      p.face = static_cast<int>(f);
      p.flip = face.orientation < 0;
      patches.push_back(std::move(p));
    }
  }
  // Patches of one face meet where the untrimming made them meet, in the face's parameters: to
  // rounding, and across the gaps of its trimming loops (up to half the trimmed surface's
  // tolerance, geom::face_trim), while untrim merges events closer than that tolerance, so no
  // slab is narrower. Points of one face are one where their parameters are within 3/4 of it.
  std::vector<double> ptol(faces.size(), 0.0);
  double hw = eps;  // a 3D distance beyond which no two points weld
  for (std::size_t f = 0; f < faces.size(); ++f) {
    ptol[f] = 0.75 * faces[f].surface.tolerance();
    const auto& S = faces[f].surface.surface();
    const auto d = idx(S.dim());
    buf.resize(3 * d);
    double lip = 0.0;
    for (int a = 0; a <= 8; ++a)
      for (int b = 0; b <= 8; ++b) {
        const auto du = S.domain(0), dv = S.domain(1);
        S.eval_derivatives({du[0] + (du[1] - du[0]) * a / 8.0, dv[0] + (dv[1] - dv[0]) * b / 8.0}, 1, buf.data());
        lip = std::max({lip, norm({buf[d], buf[d + 1], buf[d + 2]}), norm({buf[2 * d], buf[2 * d + 1], buf[2 * d + 2]})});
      }
    hw = std::max(hw, 4.0 * lip * ptol[f]);
  }
  // Refined to a third of the tolerance, as vmodel::mesh_boundary's estimate bounds each term of
  // its interpolation bound by T / 3: a patch is one side of a whole monotone piece of its
  // trimming curve (geom::untrim), so nothing but this check refines it, and the volume between
  // the chords and a curved face (about 2/3 of the deviation times the area) stays that small.
  const double target = tol / 3;
  for (auto& p : patches) {
    for (int round = 0;; ++round) {
      const auto dev = sample_patch(p, buf);
      mesh.rounds = std::max(mesh.rounds, round + 1);
      if ((dev[0] <= target && dev[1] <= target) || round == 7) {
        mesh.max_deviation = std::max(mesh.max_deviation, std::max(dev[0], dev[1]));
        break;
      }
      for (int d = 0; d < 2; ++d) {
        if (dev[idx(d)] <= target) continue;
        int& n = d == 0 ? p.ns : p.nt;
        const double factor = std::min(16.0, std::sqrt(dev[idx(d)] / target) * 1.1);
        const int next = std::max(n + 1, static_cast<int>(std::ceil(n * factor)));
        if (next > o.max_segments)
          throw Error("mesh: face of cell " + std::to_string(faces[idx(p.face)].cell) + ": tolerance " +
                      std::to_string(tol) + " needs more than " + std::to_string(o.max_segments) +
                      " segments along one direction of a patch; expected a coarser tolerance");
        n = next;
      }
    }
  }
  std::int64_t triangles = 0;
  for (const auto& p : patches) triangles += 2 * static_cast<std::int64_t>(p.ns) * p.nt;
  if (triangles > o.max_triangles)
    throw Error("mesh: tolerance " + std::to_string(tol) + " needs " + std::to_string(triangles) +
                " triangles; expected at most " + std::to_string(o.max_triangles) + " (a coarser tolerance)");

  // Vertices: every patch's grid, then the points inserted into sides.
  std::vector<Vec3> vx;
  std::vector<int> vpatch;  // the patch that made each vertex
  std::vector<double> vprops;
  std::vector<char> on_side;  // a side sample (welded), not an interior grid point
  std::vector<std::array<double, 2>> vuv;  // the face's parameters of each vertex
  for (std::size_t pi = 0; pi < patches.size(); ++pi) {
    auto& p = patches[pi];
    p.first_vertex = static_cast<int>(vx.size());
    for (int j = 0; j <= p.nt; ++j)
      for (int i = 0; i <= p.ns; ++i) {
        std::array<double, 2> uv{};
        p.domain->eval({static_cast<double>(i) / p.ns, static_cast<double>(j) / p.nt}, uv.data());
        vuv.push_back(uv);
        vx.push_back(p.xyz(i, j));
        vpatch.push_back(static_cast<int>(pi));
        const double* a = p.at(i, j);
        vprops.insert(vprops.end(), a + 3, a + 3 + nprops);
        on_side.push_back(i == 0 || j == 0 || i == p.ns || j == p.nt);
      }
    for (int k = 0; k < 4; ++k) {
      double len = 0.0;
      for (int m = 0; m < p.side_count(k); ++m) {
        const auto [i0, j0] = p.side_ij(k, m);
        const auto [i1, j1] = p.side_ij(k, m + 1);
        len += norm(sub(p.xyz(i1, j1), p.xyz(i0, j0)));
      }
      p.collapsed[idx(k)] = !(len > eps_face);
    }
  }
  const std::size_t grid_vertices = vx.size();

  // Side samples in a hash grid of cells h, a few times the distance at which a curve can stray
  // from its chord, so a segment's neighbourhood is a few cells.
  const double pad = 2.0 * tol + eps, h = 2.0 * pad;
  HashGrid samples;
  for (std::size_t v = 0; v < grid_vertices; ++v)
    if (on_side[v]) samples[key_of(vx[v], h)].push_back(static_cast<int>(v));

  // Insertion: every side sample of another patch within the weld distance of a side goes into
  // that side (eps_face for a patch of the same face, eps for another face's).
  std::vector<int> wface(vx.size());  // the face whose parameters vuv holds
  for (std::size_t v = 0; v < vx.size(); ++v) wface[v] = patches[idx(vpatch[v])].face;
  // Whether two vertices are one: parameters within ptol on one face, points within eps apart.
  auto welds = [&](int a, int b) {
    const int f = wface[idx(a)];
    const double d = norm(sub(vx[idx(a)], vx[idx(b)]));
    // (A pole: one point of space at many parameters of one face.)
    if (f == wface[idx(b)])
      return d <= eps_face ||
             std::hypot(vuv[idx(a)][0] - vuv[idx(b)][0], vuv[idx(a)][1] - vuv[idx(b)][1]) <= ptol[idx(f)];
    return d <= eps;
  };
  // First every side's finds; then sides inside their face (every sample of theirs lies on
  // another patch's side of the same face: slab lines, knot lines, separators) drop the finds
  // of other faces: a trimming curve tangent to such a line (at the vertical tangents where the
  // untrimming cuts slabs) passes within the weld distance of it without ending there.
  // Of a grid sample on its patch's boundary: 0 a corner, 1 on side 1 or 3 (a vertical segment
  // of the face's parameters: a slab line), 2 on side 0 or 2 (a curve across a slab). Within a
  // face, sides of one kind meet sides of the same kind; other contacts are corners, or
  // tangencies (a loop turning at a slab line) that are no contact.
  auto side_kind = [&](int v) {
    const auto& q = patches[idx(vpatch[idx(v)])];
    const int local = v - q.first_vertex, i = local % (q.ns + 1), j = local / (q.ns + 1);
    const bool vertical = i == 0 || i == q.ns, across = j == 0 || j == q.nt;
    return vertical && across ? 0 : vertical ? 1 : 2;
  };
  std::vector<int> candidates;
  std::vector<std::array<std::vector<std::pair<double, int>>, 4>> finds(patches.size());  // (tau, vertex)
  std::vector<char> on_face_side(grid_vertices, 0);
  for (std::size_t pi = 0; pi < patches.size(); ++pi) {
    auto& p = patches[pi];
    for (int k = 0; k < 4; ++k) {
      if (p.collapsed[idx(k)]) continue;
      const int n = p.side_count(k);
      auto& found = finds[pi][idx(k)];
      candidates.clear();
      for (int m = 0; m < n; ++m) {
        const auto [i0, j0] = p.side_ij(k, m);
        const auto [i1, j1] = p.side_ij(k, m + 1);
        const Vec3 a = p.xyz(i0, j0), b = p.xyz(i1, j1);
        // Walk the segment in steps of at most h, querying the cells around each step.
        const int steps = std::max(1, static_cast<int>(std::ceil(norm(sub(b, a)) / h)));
        for (int q = 0; q <= steps; ++q) {
          const double t = static_cast<double>(q) / steps;
          const Vec3 c{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])};
          const GridKey kc = key_of(c, h);
          for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
              for (std::int64_t dz = -1; dz <= 1; ++dz) {
                const auto it = samples.find({kc.x + dx, kc.y + dy, kc.z + dz});
                if (it == samples.end()) continue;
                for (const int v : it->second)
                  if (vpatch[idx(v)] != static_cast<int>(pi)) candidates.push_back(v);
              }
        }
      }
      std::sort(candidates.begin(), candidates.end());
      candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
      for (const int v : candidates) {
        const Vec3& q = vx[idx(v)];
        // The nearest chord segment gives the start.
        double best = pad, tau0 = -1.0;
        for (int m = 0; m < n; ++m) {
          const auto [i0, j0] = p.side_ij(k, m);
          const auto [i1, j1] = p.side_ij(k, m + 1);
          const auto [dist, t] = segment_distance(q, p.xyz(i0, j0), p.xyz(i1, j1));
          if (dist <= best) best = dist, tau0 = (m + t) / n;
        }
        if (tau0 < 0.0) continue;
        const auto [tau, dist] = project_on_side(p, k, q, tau0, buf);
        bool on = false;
        if (wface[idx(v)] == p.face) {
          const int kind = side_kind(v);
          if (dist <= hw && (kind == 0 || kind == (k % 2 == 1 ? 1 : 2))) {
            std::array<double, 2> uv{};
            const auto st = side_st(k, tau);
            p.domain->eval({st[0], st[1]}, uv.data());
            on = dist <= eps_face || std::hypot(uv[0] - vuv[idx(v)][0], uv[1] - vuv[idx(v)][1]) <= ptol[idx(p.face)];
            if (on) on_face_side[idx(v)] = 1;
          }
        } else {
          on = dist <= eps;
        }
        if (on) found.emplace_back(tau, v);
      }
    }
  }
  // Sides inside their face, and the samples of the others (the face's boundary: its loops).
  std::vector<std::array<char, 4>> inside(patches.size(), std::array<char, 4>{});
  std::vector<char> on_loop(grid_vertices, 0);
  for (std::size_t pi = 0; pi < patches.size(); ++pi) {
    const auto& p = patches[pi];
    for (int k = 0; k < 4; ++k) {
      if (p.collapsed[idx(k)]) continue;
      bool in = true;
      for (int m = 0; m <= p.side_count(k) && in; ++m) {
        const auto [i, j] = p.side_ij(k, m);
        in = on_face_side[idx(p.vertex(i, j))] != 0;
      }
      inside[pi][idx(k)] = in;
      if (!in)
        for (int m = 0; m <= p.side_count(k); ++m) {
          const auto [i, j] = p.side_ij(k, m);
          on_loop[idx(p.vertex(i, j))] = 1;
        }
    }
  }
  for (std::size_t pi = 0; pi < patches.size(); ++pi) {
    auto& p = patches[pi];
    for (int k = 0; k < 4; ++k) {
      auto& found = finds[pi][idx(k)];
      if (found.empty()) continue;
      const int n = p.side_count(k);
      // Inside a face: its neighbours' samples, not other faces'. On a loop: other faces' loop
      // samples (not the samples of their slab lines, which a loop tangent to them passes
      // within the tolerance of).
      const bool in = inside[pi][idx(k)] != 0;
      found.erase(std::remove_if(found.begin(), found.end(),
                                 [&](const auto& f) {
                                   const int v = f.second;
                                   return wface[idx(v)] != p.face && (in || !on_loop[idx(v)]);
                                 }),
                  found.end());
      std::sort(found.begin(), found.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
      // Keep a point only when no grid sample or point already kept would weld to it.
      int last = -1, last_segment = -1;
      for (const auto& [tau, v] : found) {
        const Vec3 q = vx[idx(v)];
        const int m = std::min(n - 1, static_cast<int>(std::floor(tau * n)));
        const auto [i0, j0] = p.side_ij(k, m);
        const auto [i1, j1] = p.side_ij(k, m + 1);
        if (welds(v, p.vertex(i0, j0)) || welds(v, p.vertex(i1, j1))) continue;
        if (last >= 0 && last_segment == m && welds(v, last)) continue;
        last_segment = m;
        const int vi = static_cast<int>(vx.size());
        last = vi;
        vx.push_back(q);
        vuv.push_back(vuv[idx(v)]);
        vpatch.push_back(static_cast<int>(pi));
        wface.push_back(wface[idx(v)]);
        on_side.push_back(1);
        const auto st = side_st(k, tau);
        buf.resize(idx(p.dim));
        p.surface->eval({st[0], st[1]}, buf.data());
        vprops.insert(vprops.end(), buf.begin() + 3, buf.begin() + 3 + static_cast<std::ptrdiff_t>(nprops));
        auto& e = p.extra[idx(k)];
        if (e.empty()) e.resize(idx(n));
        e[idx(m)].push_back(vi);
      }
    }
  }

  // Weld side samples within the weld distance of one another (single linkage).
  UnionFind uf(vx.size());
  {
    HashGrid weld;
    for (std::size_t v = 0; v < vx.size(); ++v)
      if (on_side[v]) weld[key_of(vx[v], hw)].push_back(static_cast<int>(v));
    for (const auto& [key, list] : weld) {
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy)
          for (std::int64_t dz = -1; dz <= 1; ++dz) {
            const auto it = weld.find({key.x + dx, key.y + dy, key.z + dz});
            if (it == weld.end()) continue;
            for (const int a : list)
              for (const int b : it->second)
                if (a < b && welds(a, b)) uf.join(a, b);
          }
    }
  }

  // Triangles: each grid cell as two triangles, or, where its sides on the patch's boundary
  // carry inserted points, a fan from a corner on no such side.
  std::vector<std::array<int, 3>> tris;
  tris.reserve(idx(triangles));
  std::vector<int> poly;
  for (const auto& p : patches) {
    // Extras of side k between its samples m and m + 1, in the side's direction (reversed).
    auto extras = [&](int k, int m, std::vector<int>& out, bool reverse) {
      const auto& e = p.extra[idx(k)];
      if (e.empty() || e[idx(m)].empty()) return false;
      if (reverse) {
        out.insert(out.end(), e[idx(m)].rbegin(), e[idx(m)].rend());
      } else {
        out.insert(out.end(), e[idx(m)].begin(), e[idx(m)].end());
      }
      return true;
    };
    for (int j = 0; j < p.nt; ++j)
      for (int i = 0; i < p.ns; ++i) {
        const int a = p.vertex(i, j), b = p.vertex(i + 1, j), c = p.vertex(i + 1, j + 1), d = p.vertex(i, j + 1);
        poly.clear();
        std::array<bool, 4> has{};  // edges ab, bc, cd, da carry extras
        std::array<int, 4> corner_pos{};
        corner_pos[0] = static_cast<int>(poly.size());
        poly.push_back(a);
        if (j == 0) has[0] = extras(0, i, poly, false);
        corner_pos[1] = static_cast<int>(poly.size());
        poly.push_back(b);
        if (i == p.ns - 1) has[1] = extras(1, j, poly, false);
        corner_pos[2] = static_cast<int>(poly.size());
        poly.push_back(c);
        if (j == p.nt - 1) has[2] = extras(2, i, poly, true);
        corner_pos[3] = static_cast<int>(poly.size());
        poly.push_back(d);
        if (i == 0) has[3] = extras(3, j, poly, true);
        if (poly.size() == 4) {
          tris.push_back({a, b, c});
          tris.push_back({a, c, d});
          continue;
        }
        // Corner q lies on edges q - 1 (before it) and q (after it).
        int apex = 0;
        for (int q = 0; q < 4; ++q)
          if (!has[idx(q)] && !has[idx((q + 3) % 4)]) {
            apex = q;
            break;
          }
        const int start = corner_pos[idx(apex)], size = static_cast<int>(poly.size());
        for (int r = 1; r + 1 < size; ++r)
          tris.push_back({poly[idx(start)], poly[idx((start + r) % size)], poly[idx((start + r + 1) % size)]});
      }
  }

  // Outward orientation, welded indices, degenerate triangles dropped.
  std::vector<int> renumber(vx.size(), -1);
  mesh.triangles.reserve(tris.size());
  for (const auto& tri : tris) {
    std::array<int, 3> r{};
    for (std::size_t q = 0; q < 3; ++q) r[q] = on_side[idx(tri[q])] ? uf.find(tri[q]) : tri[q];
    if (r[0] == r[1] || r[1] == r[2] || r[0] == r[2]) {
      ++mesh.dropped_triangles;
      continue;
    }
    if (patches[idx(vpatch[idx(tri[0])])].flip) std::swap(r[1], r[2]);
    for (std::size_t q = 0; q < 3; ++q) {
      int& nv = renumber[idx(r[q])];
      if (nv < 0) {
        nv = static_cast<int>(mesh.vertices.size());
        mesh.vertices.push_back(vx[idx(r[q])]);
        mesh.properties.insert(mesh.properties.end(), vprops.begin() + static_cast<std::ptrdiff_t>(idx(r[q]) * nprops),
                               vprops.begin() + static_cast<std::ptrdiff_t>((idx(r[q]) + 1) * nprops));
        if (vertex_face) vertex_face->push_back(patches[idx(vpatch[idx(r[q])])].face);
      }
      r[q] = nv;
    }
    mesh.triangles.push_back(r);
  }
  return mesh;
}

}  // namespace

vmodel::BoundaryMesh mesh_faces(const std::vector<BoundaryFace>& faces, double tolerance, double weld_distance,
                                const std::vector<std::string>& property_names, const vmodel::MeshOptions& options) {
  return mesh_faces_impl(faces, tolerance, weld_distance, property_names, options, nullptr);
}

vmodel::BoundaryMesh mesh_trimmed_boundary(const vmodel::VModel& model, const TrimmedMeshOptions& options) {
  const auto& o = options.mesh;
  if (!(std::isfinite(o.tolerance) && o.tolerance >= 0.0))
    throw Error("mesh: tolerance " + std::to_string(o.tolerance) + "; expected a finite value >= 0 (0: relative to the model)");
  if (!(o.relative_tolerance > 0.0 && o.relative_tolerance <= 0.1))
    throw Error("mesh: relative tolerance " + std::to_string(o.relative_tolerance) + "; expected a value in (0, 0.1]");
  if (o.max_segments < 1 || o.max_segments > 1'000'000)
    throw Error("mesh: max_segments " + std::to_string(o.max_segments) + "; expected 1..1000000");
  if (o.max_triangles < 1) throw Error("mesh: max_triangles " + std::to_string(o.max_triangles) + "; expected at least 1");
  if (!(options.weld > 0.0 && options.weld <= 1e-3))
    throw Error("mesh: weld " + std::to_string(options.weld) + "; expected a value in (0, 1e-3] (relative to the diagonal)");
  if (model.cells.empty()) throw Error("mesh: no cells; expected a model with at least one cell");
  const double diagonal = model_diagonal(model);
  const double tol = o.tolerance > 0.0 ? o.tolerance : o.relative_tolerance * diagonal;
  if (!(tol > 0.0)) throw Error("mesh: the model has no extent (diagonal 0); expected cells with volume");
  const double eps = std::min(options.weld * diagonal, 0.5 * tol);

  // A trimmed cell that its conditions admit whole (`trivox build` restricts a piece that is a
  // parameter box of its trivariate to that box and keeps the conditions) is meshed as a plain
  // cell: its faces then lie on its conditions' faces, which boundary_faces does not cut.
  const double delta = 1e-6 * diagonal;
  LocatorOptions lo;
  lo.tolerance = 1e-3 * delta;
  const Locator loc(model, lo);
  vmodel::VModel work = model;
  for (std::size_t c = 0; c < model.cells.size(); ++c) {
    const auto& cell = model.cells[c];
    if (cell.plain()) continue;
    const double whole = std::abs(geom::volume(cell.volume));
    if (std::abs(trimmed_volume(loc, static_cast<int>(c), 8) - whole) <= 1e-9 * whole) {
      work.cells[c].within.clear();
      work.cells[c].without.clear();
    }
  }
  const ModelBoundary mb = model_boundary(work, options.boundary);
  auto cell_label = [&](int c) {
    return "cell \"" + model.cells[idx(c)].name + "\" (" + std::to_string(c) + ")";
  };

  // Every piece's boundary must close: piece_measures' checks on the same faces, and its volume.
  std::vector<std::vector<BoundaryFace>> by_cell(model.cells.size());
  for (const auto& f : mb.faces) by_cell[idx(f.cell)].push_back(f);
  double cell_volume = 0.0;
  for (std::size_t c = 0; c < by_cell.size(); ++c) {
    try {
      cell_volume += piece_measures(by_cell[c], static_cast<int>(c)).volume;
    } catch (const Error& e) {
      throw Error(cell_label(static_cast<int>(c)) + ": its trimmed boundary does not close (" + e.what() +
                      "); expected a closed boundary to mesh",
                  ErrorKind::failed);
    }
  }

  // The faces to mesh, in groups welded on their own.
  std::vector<std::vector<BoundaryFace>> groups;
  if (o.per_cell) {
    for (auto& g : by_cell)
      if (!g.empty()) groups.push_back(std::move(g));
  } else {
    groups.emplace_back();
    for (const auto& f : mb.faces) {
      if (f.glued) continue;
      if (f.glued_to >= 0)
        throw Error(cell_label(f.cell) + ": face " + std::string(spline::face_name(f.face)) + " of " + f.source_name +
                        " is glued to " + cell_label(f.glued_to) +
                        " over part of its area only (a face is not split where another cell covers it); expected faces "
                        "glued whole or not at all; mesh each cell on its own instead (per cell, --cells)",
                    ErrorKind::failed);
      groups.back().push_back(f);
    }
  }

  vmodel::BoundaryMesh mesh;
  mesh.tolerance = tol;
  mesh.property_names = model.properties;
  std::vector<int> vertex_face;
  std::vector<const BoundaryFace*> face_of;  // vertex -> its face
  for (const auto& g : groups) {
    vmodel::MeshOptions go = o;
    go.max_triangles = o.max_triangles - static_cast<std::int64_t>(mesh.triangles.size());
    if (go.max_triangles < 1) go.max_triangles = 1;
    vertex_face.clear();
    auto part = mesh_faces_impl(g, tol, eps, model.properties, go, &vertex_face);
    const int base = static_cast<int>(mesh.vertices.size());
    for (const int f : vertex_face) face_of.push_back(&g[idx(f)]);
    mesh.vertices.insert(mesh.vertices.end(), part.vertices.begin(), part.vertices.end());
    mesh.properties.insert(mesh.properties.end(), part.properties.begin(), part.properties.end());
    for (auto t : part.triangles) mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    mesh.max_deviation = std::max(mesh.max_deviation, part.max_deviation);
    mesh.faces += part.faces;
    mesh.dropped_triangles += part.dropped_triangles;
    mesh.rounds = std::max(mesh.rounds, part.rounds);
  }
  if (mesh.triangles.empty())
    throw Error("mesh: the model's boundary is empty (every piece is empty or glued to another); expected a solid",
                ErrorKind::failed);
  mesh.cell_volume = cell_volume;

  // The piece's own (blended) properties where the patch's are another cell's or unblended.
  const std::size_t nprops = model.properties.size();
  if (nprops > 0) {
    std::vector<char> needs(mesh.vertices.size(), 0);
    bool any = false;
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      const auto* f = face_of[v];
      needs[v] = f->source >= 0 || !model.cells[idx(f->cell)].within.empty();
      any = any || needs[v];
    }
    if (any) {
      std::vector<Vec3> normal(mesh.vertices.size(), Vec3{0, 0, 0});
      for (const auto& t : mesh.triangles) {
        const auto& a = mesh.vertices[idx(t[0])];
        const Vec3 n = cross(sub(mesh.vertices[idx(t[1])], a), sub(mesh.vertices[idx(t[2])], a));
        for (const int v : t)
          for (std::size_t d = 0; d < 3; ++d) normal[idx(v)][d] += n[d];
      }
      std::vector<double> xyz(3), props(nprops);
      for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
        if (!needs[v]) continue;
        const double l = norm(normal[v]);
        if (!(l > 0.0)) continue;
        const Vec3 p{mesh.vertices[v][0] - delta * normal[v][0] / l, mesh.vertices[v][1] - delta * normal[v][1] / l,
                     mesh.vertices[v][2] - delta * normal[v][2] / l};
        const auto r = loc.locate(p);
        if (!r.inside) continue;
        loc.eval(r.cell, r.uvw, xyz.data(), props.data());
        loc.admits(r.cell, p, props.data());
        std::copy(props.begin(), props.end(), mesh.properties.begin() + static_cast<std::ptrdiff_t>(v * nprops));
      }
    }
  }
  return mesh;
}

}  // namespace trivox::slice
