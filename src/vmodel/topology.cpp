#include "trivox/vmodel/topology.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>

#include "trivox/error.hpp"

namespace trivox::vmodel {

namespace {

using spline::Face;
using spline::Trivariate;
using Vec3 = std::array<double, 3>;

double dist2(const Vec3& a, const Vec3& b) noexcept {
  const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return x * x + y * y + z * z;
}

std::size_t idx(int i) noexcept { return static_cast<std::size_t>(i); }

/// Points in buckets of side 8 * radius over xyz, so a query near the middle of its bucket looks
/// in that bucket alone and one near a side also in the neighbour across it: every stored point
/// within `radius` (per coordinate) of the query is a candidate, at about one bucket per query.
/// Ids, not points, are stored: the caller owns the geometry.
class SpatialHash {
public:
  /// @param origin  a corner of the region the points lie in (keeps the keys small)
  /// @param radius  the matching distance, >= 0
  /// @param floor   smallest bucket side (> 0), for a zero radius
  SpatialHash(const Vec3& origin, double radius, double floor)
      : origin_(origin), side_(std::max(8.0 * radius, floor)), margin_(radius / side_ * 1.01) {}

  void insert(const Vec3& p, int id) { buckets_[key(p)].push_back(id); }

  void erase(const Vec3& p, int id) {
    auto it = buckets_.find(key(p));
    if (it == buckets_.end()) return;
    auto& v = it->second;
    v.erase(std::remove(v.begin(), v.end(), id), v.end());
    if (v.empty()) buckets_.erase(it);
  }

  /// Calls f(id) for the candidates near p, bucket by bucket in insertion order; stops at the
  /// first for which f returns true and returns that id, else -1.
  template <class F>
  int find(const Vec3& p, F&& f) const {
    Key k{};
    std::array<std::array<int, 2>, 3> range{};  // offsets to visit per coordinate
    for (std::size_t d = 0; d < 3; ++d) {
      const double q = (p[d] - origin_[d]) / side_;
      const double fl = std::floor(q);
      k[d] = static_cast<std::int64_t>(fl);
      range[d] = {q - fl < margin_ ? -1 : 0, q - fl > 1.0 - margin_ ? 1 : 0};
    }
    for (int dz = range[2][0]; dz <= range[2][1]; ++dz)
      for (int dy = range[1][0]; dy <= range[1][1]; ++dy)
        for (int dx = range[0][0]; dx <= range[0][1]; ++dx) {
          auto it = buckets_.find({k[0] + dx, k[1] + dy, k[2] + dz});
          if (it == buckets_.end()) continue;
          for (int id : it->second)
            if (f(id)) return id;
        }
    return -1;
  }

private:
  using Key = std::array<std::int64_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const noexcept {
      // splitmix64 finaliser per coordinate, folded: keys of nearby buckets spread evenly.
      std::uint64_t h = 0;
      for (auto v : k) {
        std::uint64_t x = static_cast<std::uint64_t>(v) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
        x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
        x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
        h ^= x ^ (x >> 31);
      }
      return static_cast<std::size_t>(h);
    }
  };

  Key key(const Vec3& p) const noexcept {
    Key k{};
    for (std::size_t d = 0; d < 3; ++d) k[d] = static_cast<std::int64_t>(std::floor((p[d] - origin_[d]) / side_));
    return k;
  }

  Vec3 origin_;
  double side_;
  double margin_;
  std::unordered_map<Key, std::vector<int>, KeyHash> buckets_;
};

/// The cell's xyz part: matching never looks at properties, so it need not evaluate them.
Trivariate xyz_only(const Trivariate& s) {
  if (s.dim() == 3) return s;
  std::vector<double> pts(idx(s.size()) * 3);
  for (int r = 0; r < s.size(); ++r)
    for (int h = 0; h < 3; ++h) pts[idx(r) * 3 + idx(h)] = s.point(r)[idx(h)];
  return Trivariate(s.knot_vectors(), 3, std::move(pts), s.weights());
}

/// The two directions other than d, ascending.
std::array<int, 2> others(int d) noexcept { return {d == 0 ? 1 : 0, d == 2 ? 1 : 2}; }

/// Parameter at normalised position i / (n - 1) of direction d, the ends exact.
double param(const Trivariate& s, int d, int i, int n) noexcept {
  const auto dom = s.domain(d);
  if (i <= 0) return dom[0];
  if (i >= n - 1) return dom[1];
  return dom[0] + (dom[1] - dom[0]) * static_cast<double>(i) / static_cast<double>(n - 1);
}

Vec3 eval3(const Trivariate& s, const std::array<double, 3>& t) noexcept {
  Vec3 p{};
  s.eval(t, p.data());
  return p;
}

Vec3 centroid(const std::vector<Vec3>& pts) noexcept {
  Vec3 c{};
  for (const auto& p : pts)
    for (std::size_t d = 0; d < 3; ++d) c[d] += p[d];
  for (auto& x : c) x /= static_cast<double>(pts.size());
  return c;
}

/// Face f sampled on an n x n grid, sample (i, j) at index i + n * j, i along s.
std::vector<Vec3> sample_face(const Trivariate& s, Face f, int n) {
  const int d = static_cast<int>(f) / 2;
  const auto [d1, d2] = others(d);
  std::array<double, 3> t{};
  t[idx(d)] = (static_cast<int>(f) % 2 == 0) ? s.domain(d)[0] : s.domain(d)[1];
  std::vector<Vec3> out(idx(n * n));
  for (int j = 0; j < n; ++j) {
    t[idx(d2)] = param(s, d2, j, n);
    for (int i = 0; i < n; ++i) {
      t[idx(d1)] = param(s, d1, i, n);
      out[idx(i + n * j)] = eval3(s, t);
    }
  }
  return out;
}

/// Midpoint-rule area of face f: the integral of |S_s x S_t|.
double face_area(const Trivariate& s, Face f, int m) {
  const int d = static_cast<int>(f) / 2;
  const auto [d1, d2] = others(d);
  const auto dom1 = s.domain(d1), dom2 = s.domain(d2);
  std::array<double, 3> t{};
  t[idx(d)] = (static_cast<int>(f) % 2 == 0) ? s.domain(d)[0] : s.domain(d)[1];
  const double h1 = (dom1[1] - dom1[0]) / m, h2 = (dom2[1] - dom2[0]) / m;
  std::array<double, 4 * 3> der{};  // value, d/du, d/dv, d/dw
  double area = 0.0;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      t[idx(d1)] = dom1[0] + (i + 0.5) * h1;
      t[idx(d2)] = dom2[0] + (j + 0.5) * h2;
      s.eval_derivatives(t, 1, der.data());
      const double* a = &der[idx(3 * (1 + d1))];
      const double* b = &der[idx(3 * (1 + d2))];
      const double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2], cz = a[0] * b[1] - a[1] * b[0];
      area += std::sqrt(cx * cx + cy * cy + cz * cz);
    }
  return area * h1 * h2;
}

double extent(const std::vector<Vec3>& pts) noexcept {
  Vec3 lo{pts[0]}, hi{pts[0]};
  for (const auto& p : pts)
    for (std::size_t d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], p[d]);
      hi[d] = std::max(hi[d], p[d]);
    }
  return std::sqrt(dist2(lo, hi));
}

/// Edge e sampled at n normalised parameters, from its start corner to its end corner.
std::vector<Vec3> sample_edge(const Trivariate& s, int e, int n) {
  const int d = e / 4;
  const auto [d1, d2] = others(d);
  std::array<double, 3> t{};
  t[idx(d1)] = s.domain(d1)[idx(e & 1)];
  t[idx(d2)] = s.domain(d2)[idx((e >> 1) & 1)];
  std::vector<Vec3> out(idx(n));
  for (int i = 0; i < n; ++i) {
    t[idx(d)] = param(s, d, i, n);
    out[idx(i)] = eval3(s, t);
  }
  return out;
}

/// Edge running along direction `dir` with the others at sides side[other].
int edge_index(int dir, const std::array<int, 3>& side) noexcept {
  const auto [o1, o2] = others(dir);
  return 4 * dir + side[idx(o1)] + 2 * side[idx(o2)];
}

/// Start (end = 0) or end (end = 1) corner of edge e.
int edge_corner(int e, int end) noexcept {
  const int d = e / 4;
  const auto [d1, d2] = others(d);
  std::array<int, 3> side{};
  side[idx(d)] = end;
  side[idx(d1)] = e & 1;
  side[idx(d2)] = (e >> 1) & 1;
  return side[0] + 2 * side[1] + 4 * side[2];
}

/// The edges s=0, s=1, t=0, t=1 of face f.
std::array<int, 4> face_edges(Face f) noexcept {
  const int d = static_cast<int>(f) / 2;
  const auto [d1, d2] = others(d);
  std::array<int, 3> side{};
  side[idx(d)] = static_cast<int>(f) % 2;
  std::array<int, 4> out{};
  for (int k = 0; k < 2; ++k) {
    side[idx(d2)] = 0;
    side[idx(d1)] = k;
    out[idx(k)] = edge_index(d2, side);  // s = k: runs along t
    side[idx(d1)] = 0;
    side[idx(d2)] = k;
    out[idx(2 + k)] = edge_index(d1, side);  // t = k: runs along s
  }
  return out;
}

/// Whether grid a (n x n) equals grid b under orientation o: a(s, t) = b(o(s, t)).
bool same_face(const std::vector<Vec3>& a, const std::vector<Vec3>& b, int n, Orientation o, double tol2) noexcept {
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int p = o.swap ? j : i, q = o.swap ? i : j;
      if (o.reverse_first) p = n - 1 - p;
      if (o.reverse_second) q = n - 1 - q;
      if (dist2(a[idx(i + n * j)], b[idx(p + n * q)]) > tol2) return false;
    }
  return true;
}

/// 0: a == b, 1: a == reversed b, -1: neither.
int same_curve(const std::vector<Vec3>& a, const std::vector<Vec3>& b, double tol2) noexcept {
  const std::size_t n = a.size();
  bool fwd = true, bwd = true;
  for (std::size_t i = 0; i < n && (fwd || bwd); ++i) {
    fwd = fwd && dist2(a[i], b[i]) <= tol2;
    bwd = bwd && dist2(a[i], b[n - 1 - i]) <= tol2;
  }
  return fwd ? 0 : (bwd ? 1 : -1);
}

void check_options(const TopologyOptions& o) {
  if (!(std::isfinite(o.relative_tolerance) && o.relative_tolerance >= 0.0))
    throw Error("topology: relative_tolerance " + std::to_string(o.relative_tolerance) +
                "; expected a finite value >= 0");
  if (o.samples < 2 || o.samples > 1000)
    throw Error("topology: samples " + std::to_string(o.samples) + "; expected 2..1000");
  if (o.area_samples < 1 || o.area_samples > 1000)
    throw Error("topology: area_samples " + std::to_string(o.area_samples) + "; expected 1..1000");
}

void sort_unique(std::vector<int>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

void check_index(int i, std::size_t n, const char* what) {
  if (i < 0 || idx(i) >= n)
    throw Error("topology: " + std::string(what) + " " + std::to_string(i) + "; expected 0.." +
                std::to_string(static_cast<long long>(n) - 1));
}

}  // namespace

std::array<double, 2> Orientation::apply(std::array<double, 2> st) const noexcept {
  std::array<double, 2> ab = swap ? std::array<double, 2>{st[1], st[0]} : st;
  if (reverse_first) ab[0] = 1.0 - ab[0];
  if (reverse_second) ab[1] = 1.0 - ab[1];
  return ab;
}

Orientation Orientation::inverse() const noexcept {
  // Undo the reversals (on the glued face's parameters), then the swap: a reversal of the
  // glued face's first parameter is one of this face's second when swapped.
  if (!swap) return *this;
  return {true, reverse_second, reverse_first};
}

Topology build_topology(const VModel& model, const TopologyOptions& options) {
  check_options(options);
  const int n_cells = static_cast<int>(model.cells.size());
  const int n = options.samples;
  Topology topo;
  topo.v_cells = n_cells;
  topo.cell_faces.assign(idx(n_cells), {-1, -1, -1, -1, -1, -1});
  topo.cell_edges.assign(idx(n_cells), {-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1});
  topo.cell_corners.assign(idx(n_cells), {-1, -1, -1, -1, -1, -1, -1, -1});
  if (n_cells == 0) return topo;

  std::vector<Trivariate> xyz;
  xyz.reserve(idx(n_cells));
  Vec3 lo{}, hi{};
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (const auto& cell : model.cells) {
    if (cell.volume.dim() < 3)
      throw Error("topology: cell \"" + cell.name + "\" has " + std::to_string(cell.volume.dim()) +
                  " coordinates per control point; expected at least 3 (xyz)");
    xyz.push_back(xyz_only(cell.volume));
    const auto box = xyz.back().control_box();
    for (std::size_t d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], box[0][d]);
      hi[d] = std::max(hi[d], box[1][d]);
    }
  }
  const double diag = std::sqrt(dist2(lo, hi));
  const double tol = options.relative_tolerance * diag;
  const double tol2 = tol * tol;
  topo.tolerance = tol;
  // Buckets no finer than 1e-12 of the model, so keys stay in range even with a zero tolerance.
  const double min_side = std::max(diag * 1e-12, std::numeric_limits<double>::min());

  // V-points.
  SpatialHash point_hash(lo, tol, min_side);
  for (int c = 0; c < n_cells; ++c)
    for (int k = 0; k < 8; ++k) {
      const Trivariate& s = xyz[idx(c)];
      const Vec3 p = eval3(s, {s.domain(0)[idx(k & 1)], s.domain(1)[idx((k >> 1) & 1)], s.domain(2)[idx((k >> 2) & 1)]});
      int id = point_hash.find(p, [&](int q) { return dist2(topo.v_points[idx(q)].position, p) <= tol2; });
      if (id < 0) {
        id = static_cast<int>(topo.v_points.size());
        topo.v_points.push_back({p, {}, {}});
        point_hash.insert(p, id);
      }
      topo.v_points[idx(id)].uses.push_back({c, k});
      topo.cell_corners[idx(c)][idx(k)] = id;
    }

  // V-curves: samples of each curve's first use, for comparing the later ones.
  std::vector<std::vector<Vec3>> curve_samples;
  SpatialHash curve_hash(lo, tol, min_side);
  for (int c = 0; c < n_cells; ++c)
    for (int e = 0; e < 12; ++e) {
      auto pts = sample_edge(xyz[idx(c)], e, n);
      const bool degenerate =
          std::all_of(pts.begin(), pts.end(), [&](const Vec3& p) { return dist2(p, pts[0]) <= tol2; });
      if (degenerate) continue;
      const Vec3 key = centroid(pts);
      int dir = -1;
      int id = curve_hash.find(key, [&](int q) {
        dir = same_curve(pts, curve_samples[idx(q)], tol2);
        return dir >= 0;
      });
      if (id < 0) {
        id = static_cast<int>(topo.v_curves.size());
        dir = 0;
        VCurve curve;
        curve.v_points = {topo.cell_corners[idx(c)][idx(edge_corner(e, 0))],
                          topo.cell_corners[idx(c)][idx(edge_corner(e, 1))]};
        topo.v_curves.push_back(std::move(curve));
        curve_samples.push_back(std::move(pts));
        curve_hash.insert(key, id);
      }
      topo.v_curves[idx(id)].uses.push_back({c, e, dir == 1});
      topo.cell_edges[idx(c)][idx(e)] = id;
    }
  for (int q = 0; q < static_cast<int>(topo.v_curves.size()); ++q)
    for (int p : topo.v_curves[idx(q)].v_points) {
      auto& list = topo.v_points[idx(p)].v_curves;
      if (list.empty() || list.back() != q) list.push_back(q);
    }

  // Half-V-surfaces, glued greedily to the first earlier unglued face of another cell that
  // coincides; only unglued faces stay in the hash (with their samples). A face that coincides
  // with one that has area has area itself, so only the unglued ones need the area estimate.
  std::vector<std::vector<Vec3>> face_samples;
  std::vector<Vec3> face_keys;
  SpatialHash face_hash(lo, tol, min_side);
  for (int c = 0; c < n_cells; ++c)
    for (Face f : spline::all_faces) {
      const Trivariate& s = xyz[idx(c)];
      auto pts = sample_face(s, f, n);
      const double ext = extent(pts);
      if (ext <= tol) continue;
      const Vec3 key = centroid(pts);
      Orientation orient;
      const int twin = face_hash.find(key, [&](int q) {
        if (topo.half_v_surfaces[idx(q)].cell == c) return false;
        for (int o = 0; o < 8; ++o)
          if (same_face(pts, face_samples[idx(q)], n, Orientation::from_index(o), tol2)) {
            orient = Orientation::from_index(o);
            return true;
          }
        return false;
      });
      if (twin < 0 && face_area(s, f, options.area_samples) <= tol * ext) continue;
      const int me = static_cast<int>(topo.half_v_surfaces.size());
      HalfVSurface half;
      half.cell = c;
      half.face = f;
      const auto edges = face_edges(f);
      for (std::size_t k = 0; k < 4; ++k) half.v_curves[k] = topo.cell_edges[idx(c)][idx(edges[k])];
      if (twin >= 0) {
        auto& other = topo.half_v_surfaces[idx(twin)];
        other.twin = me;
        other.to_twin = orient.inverse();
        half.twin = twin;
        half.to_twin = orient;
        half.v_surface = other.v_surface;
        topo.v_surfaces[idx(half.v_surface)].halves[1] = me;
        face_hash.erase(face_keys[idx(twin)], twin);
        std::vector<Vec3>().swap(face_samples[idx(twin)]);
        pts.clear();
      } else {
        half.v_surface = static_cast<int>(topo.v_surfaces.size());
        topo.v_surfaces.push_back({{me, -1}});
        face_hash.insert(key, me);
      }
      face_samples.push_back(std::move(pts));
      face_keys.push_back(key);
      topo.half_v_surfaces.push_back(half);
      topo.cell_faces[idx(c)][idx(static_cast<int>(f))] = me;
    }
  for (const auto& half : topo.half_v_surfaces)
    for (int q : half.v_curves)
      if (q >= 0) topo.v_curves[idx(q)].v_surfaces.push_back(half.v_surface);
  for (auto& curve : topo.v_curves) sort_unique(curve.v_surfaces);
  for (auto& point : topo.v_points) sort_unique(point.v_curves);
  return topo;
}

TopologyCounts counts(const Topology& topo) noexcept {
  return {topo.v_cells, static_cast<int>(topo.v_surfaces.size()), static_cast<int>(topo.half_v_surfaces.size()),
          static_cast<int>(topo.v_curves.size()), static_cast<int>(topo.v_points.size())};
}

std::vector<FaceGlue> glued_faces(const Topology& topo) {
  std::vector<FaceGlue> out;
  for (const auto& faces : topo.cell_faces)
    for (int hs : faces) {
      if (hs < 0) continue;
      const auto& half = topo.half_v_surfaces[idx(hs)];
      if (half.twin < 0) continue;
      const auto& twin = topo.half_v_surfaces[idx(half.twin)];
      out.push_back({half.cell, half.face, twin.cell, twin.face, half.to_twin});
    }
  return out;
}

std::vector<int> neighbours(const Topology& topo, int cell) {
  check_index(cell, topo.cell_faces.size(), "cell");
  std::vector<int> out;
  for (int hs : topo.cell_faces[idx(cell)])
    if (hs >= 0 && topo.half_v_surfaces[idx(hs)].twin >= 0)
      out.push_back(topo.half_v_surfaces[idx(topo.half_v_surfaces[idx(hs)].twin)].cell);
  sort_unique(out);
  return out;
}

std::vector<int> cells_around_curve(const Topology& topo, int v_curve) {
  check_index(v_curve, topo.v_curves.size(), "V-curve");
  std::vector<int> out;
  for (const auto& use : topo.v_curves[idx(v_curve)].uses) out.push_back(use.cell);
  sort_unique(out);
  return out;
}

std::vector<int> cells_around_point(const Topology& topo, int v_point) {
  check_index(v_point, topo.v_points.size(), "V-point");
  std::vector<int> out;
  for (const auto& use : topo.v_points[idx(v_point)].uses) out.push_back(use.cell);
  sort_unique(out);
  return out;
}

Contact contact(const Topology& topo, int a, int b) {
  check_index(a, topo.cell_faces.size(), "cell");
  check_index(b, topo.cell_faces.size(), "cell");
  const auto nb = neighbours(topo, a);
  if (std::binary_search(nb.begin(), nb.end(), b)) return Contact::surface;
  auto shares = [](const auto& x, const auto& y) {
    for (int i : x)
      if (i >= 0 && std::find(y.begin(), y.end(), i) != y.end()) return true;
    return false;
  };
  if (shares(topo.cell_edges[idx(a)], topo.cell_edges[idx(b)])) return Contact::curve;
  if (shares(topo.cell_corners[idx(a)], topo.cell_corners[idx(b)])) return Contact::point;
  return Contact::none;
}

}  // namespace trivox::vmodel
