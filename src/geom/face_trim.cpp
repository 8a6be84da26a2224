#include "trivox/geom/face_trim.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <utility>

#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::geom {
namespace {

using Pt = std::array<double, 2>;
using Poly = std::vector<Pt>;

constexpr std::size_t kMaxSegments = 200'000;
constexpr std::int64_t kMaxPairTests = 50'000'000;
constexpr std::size_t kMaxEvents = 100'000;

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

std::string at(Pt p) {
  std::ostringstream s;
  s.precision(6);
  s << '(' << p[0] << ", " << p[1] << ')';
  return s.str();
}

spline::Curve line(Pt a, Pt b) {
  return spline::Curve({spline::KnotVector::bezier(2)}, 2, std::vector<double>{a[0], a[1], b[0], b[1]});
}

Pt eval2(const spline::Curve& c, double t) {
  double p[2];
  c.eval({t}, p);
  return {p[0], p[1]};
}

double dist(Pt a, Pt b) { return std::hypot(a[0] - b[0], a[1] - b[1]); }

// A curve's polyline: at most 16 points per knot span (4096 per curve), with their parameters.
struct Sampled {
  std::vector<double> t;
  Poly p;
};

Sampled sample(const spline::Curve& c) {
  const auto& kv = c.knots(0);
  std::vector<double> br;
  for (double k : kv.knots())
    if (k >= kv.front() && k <= kv.back() && (br.empty() || k > br.back())) br.push_back(k);
  const int per = std::max(2, std::min(16, 4096 / std::max<int>(1, static_cast<int>(br.size()) - 1)));
  Sampled s;
  for (std::size_t i = 0; i + 1 < br.size(); ++i)
    for (int j = 0; j < per; ++j) s.t.push_back(br[i] + (br[i + 1] - br[i]) * j / per);
  s.t.push_back(kv.back());
  for (double t : s.t) s.p.push_back(eval2(c, t));
  return s;
}

double signed_area(const Poly& p) {
  double a = 0;
  for (std::size_t i = 0; i + 1 < p.size(); ++i) a += p[i][0] * p[i + 1][1] - p[i + 1][0] * p[i][1];
  a += p.back()[0] * p[0][1] - p[0][0] * p.back()[1];
  return 0.5 * a;
}

// Winding number of a closed polyline (last point joined to the first) around q.
int winding(const Poly& p, Pt q) {
  int w = 0;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Pt& a = p[i];
    const Pt& b = p[(i + 1) % n];
    const double cr = (b[0] - a[0]) * (q[1] - a[1]) - (q[0] - a[0]) * (b[1] - a[1]);
    if (a[1] <= q[1]) {
      if (b[1] > q[1] && cr > 0) ++w;
    } else if (b[1] <= q[1] && cr < 0) {
      --w;
    }
  }
  return w;
}

// Distance from q to segment ab and the segment parameter of the closest point.
std::pair<double, double> seg_closest(Pt q, Pt a, Pt b) {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return {std::hypot(q[0] - a[0] - t * dx, q[1] - a[1] - t * dy), t};
}

double orient(Pt p, Pt q, Pt r) { return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]); }

// Distance between segments ab and cd with the segment parameters of a closest pair (the
// crossing when they cross).
struct SegPair {
  double d, s, t;
};
SegPair seg_seg(Pt a, Pt b, Pt c, Pt d) {
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
    return {0.0, o3 / (o3 - o4), o1 / (o1 - o2)};
  SegPair best{std::numeric_limits<double>::infinity(), 0, 0};
  auto take = [&](double dd, double s, double t) {
    if (dd < best.d) best = {dd, s, t};
  };
  {
    auto [dd, t] = seg_closest(a, c, d);
    take(dd, 0.0, t);
  }
  {
    auto [dd, t] = seg_closest(b, c, d);
    take(dd, 1.0, t);
  }
  {
    auto [dd, s] = seg_closest(c, a, b);
    take(dd, s, 0.0);
  }
  {
    auto [dd, s] = seg_closest(d, a, b);
    take(dd, s, 1.0);
  }
  return best;
}

// Closest point of curve c to q by Gauss-Newton from t (kept in the domain).
double project(const spline::Curve& c, Pt q, double t) {
  const auto dom = c.domain(0);
  double d[4];
  for (int it = 0; it < 50; ++it) {
    c.eval_derivatives({t}, 1, d);
    const double g = (d[0] - q[0]) * d[2] + (d[1] - q[1]) * d[3], h = d[2] * d[2] + d[3] * d[3];
    if (!(h > 0)) break;
    const double nt = std::clamp(t - g / h, dom[0], dom[1]);
    if (std::abs(nt - t) <= 1e-15 * (dom[1] - dom[0])) {
      t = nt;
      break;
    }
    t = nt;
  }
  return t;
}

// Newton on a(s) = b(t) from (s, t), kept in the domains; true when it converged to a point
// where the curves meet within `eps`.
bool meet(const spline::Curve& a, const spline::Curve& b, double& s, double& t, double eps) {
  const auto da = a.domain(0), db = b.domain(0);
  double p[4], q[4];
  for (int it = 0; it < 40; ++it) {
    a.eval_derivatives({s}, 1, p);
    b.eval_derivatives({t}, 1, q);
    const double fx = p[0] - q[0], fy = p[1] - q[1];
    if (std::hypot(fx, fy) <= 0.01 * eps) return true;
    // [p' -q'] (ds, dt) = -f
    const double det = p[2] * (-q[3]) - (-q[2]) * p[3];
    if (!(std::abs(det) > 0)) return false;
    const double ds = (-fx * (-q[3]) - (-q[2]) * (-fy)) / det;
    const double dt = (p[2] * (-fy) - (-fx) * p[3]) / det;
    s = std::clamp(s + ds, da[0], da[1]);
    t = std::clamp(t + dt, db[0], db[1]);
  }
  a.eval({s}, p);
  b.eval({t}, q);
  return std::hypot(p[0] - q[0], p[1] - q[1]) <= eps;
}

// A uniform grid of buckets over a rectangle, holding items by their boxes.
struct Buckets {
  double x0 = 0, y0 = 0, cw = 1, ch = 1;
  int n = 1;
  std::vector<std::vector<int>> cells;
  Buckets(double ax, double ay, double w, double h, int nb) : x0(ax), y0(ay), cw(w / nb), ch(h / nb), n(nb), cells(static_cast<std::size_t>(nb) * nb) {}
  std::array<int, 4> range(double lx, double ly, double hx, double hy) const {
    auto cx = [&](double x) { return std::clamp(static_cast<int>(std::floor((x - x0) / cw)), 0, n - 1); };
    auto cy = [&](double y) { return std::clamp(static_cast<int>(std::floor((y - y0) / ch)), 0, n - 1); };
    return {cx(lx), cy(ly), cx(hx), cy(hy)};
  }
  void add(int item, double lx, double ly, double hx, double hy) {
    const auto r = range(lx, ly, hx, hy);
    for (int j = r[1]; j <= r[3]; ++j)
      for (int i = r[0]; i <= r[2]; ++i) cells[static_cast<std::size_t>(j) * n + i].push_back(item);
  }
};

// One piece of a curve between two vertices of the arrangement, or a straight piece of the
// rectangle's boundary (curve < 0).
struct Edge {
  int curve = -1;
  double s0 = 0, s1 = 0;
  int va = -1, vb = -1;
  Poly poly;  // from va to vb
  Pt a{}, b{};  // the boundary line's ends
  bool removed = false;
};

struct Event {
  int curve;  // -1: a corner of the rectangle
  double t;
  Pt p;
};

struct Region {
  std::vector<int> outer;               // half-edges
  std::vector<std::vector<int>> holes;  // half-edge cycles, clockwise
  Poly outer_poly;
  std::vector<Poly> hole_polys;
  double lo[2], hi[2];
};

}  // namespace

std::vector<FaceRegion> face_regions(const spline::Surface& face, const std::vector<spline::Curve>& cuts,
                                     const KeepPredicate& keep, const FaceTrimOptions& options) {
  const std::string& name = options.face_name;
  if (face.dim() < 3) throw Error(name + ": the face has " + std::to_string(face.dim()) + " coordinates; expected at least 3 (xyz)");
  if (!(options.tolerance > 0 && options.tolerance < 1e-3))
    throw Error(name + ": tolerance " + fmt(options.tolerance) + "; expected > 0 and < 1e-3");
  if (static_cast<int>(cuts.size()) > options.max_curves)
    throw Error(name + ": " + std::to_string(cuts.size()) + " cutting curves; expected at most " + std::to_string(options.max_curves));
  if (!keep) throw Error(name + ": no predicate given");
  const auto du = face.domain(0), dv = face.domain(1);
  const double u0 = du[0], u1 = du[1], v0 = dv[0], v1 = dv[1];
  const double W = u1 - u0, H = v1 - v0, L = std::max(W, H);
  const double tol = options.tolerance * L;
  if (!(W > 10 * tol && H > 10 * tol && std::isfinite(L)))
    throw Error(name + ": the parameter rectangle [" + fmt(u0) + ", " + fmt(u1) + "] x [" + fmt(v0) + ", " + fmt(v1) +
                "] is too thin for the tolerance; expected sides longer than 10 x " + fmt(tol));
  const Pt corners[4] = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
  const double perimeter = 2 * (W + H);
  auto off_boundary = [&](Pt q) {
    return std::min({std::abs(q[0] - u0), std::abs(q[0] - u1), std::abs(q[1] - v0), std::abs(q[1] - v1)});
  };
  auto perim = [&](Pt q) {
    const double d[4] = {std::abs(q[1] - v0), std::abs(q[0] - u1), std::abs(q[1] - v1), std::abs(q[0] - u0)};
    const int side = static_cast<int>(std::min_element(d, d + 4) - d);
    switch (side) {
      case 0: return std::clamp(q[0] - u0, 0.0, W);
      case 1: return W + std::clamp(q[1] - v0, 0.0, H);
      case 2: return W + H + std::clamp(u1 - q[0], 0.0, W);
      default: {
        const double s = 2 * W + H + std::clamp(v1 - q[1], 0.0, H);
        return s >= perimeter ? 0.0 : s;
      }
    }
  };

  // 1. Validation and polylines; curves lying along the boundary and curves covered by another
  //    curve (the same intersection found from two faces that share it) add nothing and are set
  //    aside.
  const std::size_t nc = cuts.size();
  std::vector<Sampled> smp(nc);
  std::size_t total_segments = 0;
  for (std::size_t i = 0; i < nc; ++i) {
    const auto& c = cuts[i];
    const std::string who = name + ": cutting curve " + std::to_string(i);
    if (c.dim() != 2) throw Error(who + " has " + std::to_string(c.dim()) + " coordinates; expected 2 (u, v)");
    if (c.rational()) throw Error(who + " is rational; expected a polynomial curve");
    smp[i] = sample(c);
    total_segments += smp[i].p.size() - 1;
    if (total_segments > kMaxSegments)
      throw Error(name + ": cutting curves too long (more than " + std::to_string(kMaxSegments) + " polyline segments)");
    for (const Pt& q : smp[i].p)
      if (!std::isfinite(q[0]) || !std::isfinite(q[1])) throw Error(who + " has a point that is not finite");
    for (const Pt& q : smp[i].p)
      if (q[0] < u0 - tol || q[0] > u1 + tol || q[1] < v0 - tol || q[1] > v1 + tol)
        throw Error(who + " leaves the parameter rectangle at " + at(q));
  }
  std::vector<bool> closed(nc), active(nc, true);
  std::vector<double> length(nc, 0.0);
  std::vector<std::array<double, 4>> box(nc);  // lo u, lo v, hi u, hi v
  for (std::size_t i = 0; i < nc; ++i) {
    const Poly& p = smp[i].p;
    for (std::size_t k = 0; k + 1 < p.size(); ++k) length[i] += dist(p[k], p[k + 1]);
    box[i] = {p[0][0], p[0][1], p[0][0], p[0][1]};
    for (const Pt& q : p)
      box[i] = {std::min(box[i][0], q[0]), std::min(box[i][1], q[1]), std::max(box[i][2], q[0]), std::max(box[i][3], q[1])};
    closed[i] = dist(p.front(), p.back()) <= tol;
    if (closed[i] && std::abs(signed_area(p)) <= tol * L)
      throw Error(name + ": cutting curve " + std::to_string(i) + " is closed but encloses no area");
    if (length[i] <= tol) active[i] = false;  // a point
    const double along[4] = {box[i][3] - v0, u1 - box[i][0], v1 - box[i][1], box[i][2] - u0};
    for (int s = 0; s < 4; ++s)
      if (along[s] <= tol) active[i] = false;  // along a side
  }
  // Polyline segments in buckets of a uniform grid, by their boxes grown by twice the tolerance.
  struct Seg {
    int curve, k;
    std::array<int, 4> cells;
  };
  std::vector<Seg> segs;
  const int nb = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(total_segments) / 4)), 1, 256);
  const double grow = 2 * tol;
  Buckets bk(u0 - grow, v0 - grow, W + 2 * grow, H + 2 * grow, nb);
  for (std::size_t i = 0; i < nc; ++i) {
    if (!active[i]) continue;
    const Poly& p = smp[i].p;
    for (std::size_t k = 0; k + 1 < p.size(); ++k) {
      const double lx = std::min(p[k][0], p[k + 1][0]) - grow, ly = std::min(p[k][1], p[k + 1][1]) - grow;
      const double hx = std::max(p[k][0], p[k + 1][0]) + grow, hy = std::max(p[k][1], p[k + 1][1]) + grow;
      bk.add(static_cast<int>(segs.size()), lx, ly, hx, hy);
      segs.push_back({static_cast<int>(i), static_cast<int>(k), bk.range(lx, ly, hx, hy)});
    }
  }
  // Distance from q to curve j (infinite beyond twice the tolerance): the nearest of its
  // polyline segments in q's bucket, then refined on the curve.
  auto to_curve = [&](std::size_t j, Pt q, double* param) {
    const Sampled& s = smp[j];
    double best = std::numeric_limits<double>::infinity(), bt = s.t[0];
    const auto r = bk.range(q[0], q[1], q[0], q[1]);
    for (int x : bk.cells[static_cast<std::size_t>(r[1]) * static_cast<std::size_t>(nb) + static_cast<std::size_t>(r[0])]) {
      const Seg& g = segs[static_cast<std::size_t>(x)];
      if (g.curve != static_cast<int>(j)) continue;
      const std::size_t k = static_cast<std::size_t>(g.k);
      const auto [d, f] = seg_closest(q, s.p[k], s.p[k + 1]);
      if (d < best) best = d, bt = s.t[k] + f * (s.t[k + 1] - s.t[k]);
    }
    if (!(best <= grow)) return std::numeric_limits<double>::infinity();
    const double t = project(cuts[j], q, bt);
    if (param) *param = t;
    return std::min(best, dist(eval2(cuts[j], t), q));
  };
  {
    std::vector<std::size_t> order(nc);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return length[a] > length[b]; });
    std::vector<std::size_t> kept;
    for (std::size_t j : order) {
      if (!active[j]) continue;
      const Poly& p = smp[j].p;
      for (std::size_t i : kept) {
        if (box[j][0] < box[i][0] - tol || box[j][1] < box[i][1] - tol || box[j][2] > box[i][2] + tol || box[j][3] > box[i][3] + tol) continue;
        if (to_curve(i, p.front(), nullptr) > tol || to_curve(i, p.back(), nullptr) > tol || to_curve(i, p[p.size() / 2], nullptr) > tol) continue;
        bool covered = true;
        for (const Pt& q : p)
          if (to_curve(i, q, nullptr) > tol) {
            covered = false;
            break;
          }
        if (covered) {
          active[j] = false;
          break;
        }
      }
      if (active[j]) kept.push_back(j);
    }
  }

  // 2. Vertices: the corners, the curves' ends (a closed curve's start), the points where a
  //    curve's end meets another curve (a junction) and where curves cross; events within the
  //    tolerance of one another are one vertex.
  std::vector<Event> events;
  for (int c = 0; c < 4; ++c) events.push_back({-1, 0.0, corners[c]});
  std::vector<std::vector<std::size_t>> on_curve(nc);  // event indices per curve
  auto add_event = [&](std::size_t curve, double t, Pt p) {
    on_curve[curve].push_back(events.size());
    events.push_back({static_cast<int>(curve), t, p});
  };
  for (std::size_t i = 0; i < nc; ++i) {
    if (!active[i]) continue;
    const auto dom = cuts[i].domain(0);
    add_event(i, dom[0], smp[i].p.front());
    add_event(i, dom[1], smp[i].p.back());
  }
  // Junctions: an open curve's end on another curve (or on itself, away from that end).
  std::vector<std::pair<int, int>> junction_of_end;  // (curve, other curve) for ends that met one
  std::vector<Pt> junction_point;
  for (std::size_t i = 0; i < nc; ++i) {
    if (!active[i] || closed[i]) continue;
    for (int e = 0; e < 2; ++e) {
      const Pt p = e ? smp[i].p.back() : smp[i].p.front();
      const auto r = bk.range(p[0] - tol, p[1] - tol, p[0] + tol, p[1] + tol);
      std::vector<int> near;
      for (int y = r[1]; y <= r[3]; ++y)
        for (int x = r[0]; x <= r[2]; ++x)
          for (int s : bk.cells[static_cast<std::size_t>(y) * nb + x])
            if (active[static_cast<std::size_t>(segs[static_cast<std::size_t>(s)].curve)]) near.push_back(segs[static_cast<std::size_t>(s)].curve);
      std::sort(near.begin(), near.end());
      near.erase(std::unique(near.begin(), near.end()), near.end());
      for (int j : near) {
        double t = 0;
        if (j == static_cast<int>(i)) continue;  // its own end; crossings with itself come below
        if (to_curve(static_cast<std::size_t>(j), p, &t) > tol) continue;
        add_event(static_cast<std::size_t>(j), t, eval2(cuts[static_cast<std::size_t>(j)], t));
        junction_of_end.push_back({static_cast<int>(i), j});
        junction_point.push_back(p);
      }
    }
  }
  // Crossings: segment pairs within the tolerance, refined by Newton on the curves.
  {
    // Crossings found per curve pair, to merge repeats.
    std::map<std::pair<std::size_t, std::size_t>, std::vector<Pt>> found;
    std::int64_t tests = 0;
    std::vector<std::pair<int, int>> pairs;
    for (int cy = 0; cy < nb; ++cy)
      for (int cx = 0; cx < nb; ++cx) {
        // Each pair once: in the first bucket the two segments share.
        const auto& cell = bk.cells[static_cast<std::size_t>(cy) * static_cast<std::size_t>(nb) + static_cast<std::size_t>(cx)];
        pairs.clear();
        for (std::size_t a = 0; a < cell.size(); ++a)
          for (std::size_t b = a + 1; b < cell.size(); ++b) {
            const Seg& A = segs[static_cast<std::size_t>(cell[a])];
            const Seg& B = segs[static_cast<std::size_t>(cell[b])];
            if (!active[static_cast<std::size_t>(A.curve)] || !active[static_cast<std::size_t>(B.curve)]) continue;
            if (std::max(A.cells[0], B.cells[0]) != cx || std::max(A.cells[1], B.cells[1]) != cy) continue;
            if (++tests > kMaxPairTests)
              throw Error(name + ": cutting curves too dense (more than " + std::to_string(kMaxPairTests) +
                          " pairs of polyline segments near one another)");
            pairs.push_back({std::min(cell[a], cell[b]), std::max(cell[a], cell[b])});
          }
        std::sort(pairs.begin(), pairs.end());
        for (const auto& [x, y] : pairs) {
          const Seg& A = segs[static_cast<std::size_t>(x)];
          const Seg& B = segs[static_cast<std::size_t>(y)];
          const std::size_t i = static_cast<std::size_t>(A.curve), j = static_cast<std::size_t>(B.curve);
          const Poly& pi = smp[i].p;
          const Poly& pj = smp[j].p;
          if (i == j) {
            const int n = static_cast<int>(pi.size()) - 1;
            const int k = std::abs(A.k - B.k);
            if (k <= 1 || (closed[i] && k == n - 1)) continue;
          }
          const SegPair sp = seg_seg(pi[static_cast<std::size_t>(A.k)], pi[static_cast<std::size_t>(A.k) + 1],
                                     pj[static_cast<std::size_t>(B.k)], pj[static_cast<std::size_t>(B.k) + 1]);
          if (sp.d > tol) continue;
          const auto& ti = smp[i].t;
          const auto& tj = smp[j].t;
          double s = ti[static_cast<std::size_t>(A.k)] + sp.s * (ti[static_cast<std::size_t>(A.k) + 1] - ti[static_cast<std::size_t>(A.k)]);
          double t = tj[static_cast<std::size_t>(B.k)] + sp.t * (tj[static_cast<std::size_t>(B.k) + 1] - tj[static_cast<std::size_t>(B.k)]);
          const Pt guess = eval2(cuts[i], s);
          // An end of one curve near the pair that meets the other curve there (a junction, ends
          // meeting end to end, or both ends on the boundary): that meeting is already a vertex, and
          // only a crossing Newton finds away from it is another.
          const double window = 4 * tol + dist(pi[static_cast<std::size_t>(A.k)], pi[static_cast<std::size_t>(A.k) + 1]) +
                                dist(pj[static_cast<std::size_t>(B.k)], pj[static_cast<std::size_t>(B.k) + 1]);
          std::vector<Pt> meetings;
          for (std::size_t q = 0; q < junction_of_end.size(); ++q) {
            const auto [a, b] = junction_of_end[q];
            if ((a == static_cast<int>(i) && b == static_cast<int>(j)) || (a == static_cast<int>(j) && b == static_cast<int>(i)))
              if (dist(junction_point[q], guess) <= window) meetings.push_back(junction_point[q]);
          }
          if (!(i == j && closed[i])) {
            const Pt ends[4] = {pi.front(), pi.back(), pj.front(), pj.back()};
            for (int x = 0; x < 4; ++x) {
              if (dist(ends[x], guess) > window) continue;
              bool met = off_boundary(ends[x]) <= tol;
              for (int y = (x < 2 ? 2 : 0); y < (x < 2 ? 4 : 2); ++y) met = met || dist(ends[x], ends[y]) <= tol;
              if (met) meetings.push_back(ends[x]);
            }
          }
          const bool ok = meet(cuts[i], cuts[j], s, t, 1e-3 * tol);
          const Pt p = eval2(cuts[i], s);
          if (!meetings.empty()) {
            bool away = ok;
            for (const Pt& m : meetings) away = away && dist(m, p) > 2 * tol;
            if (!away) continue;
          }
          if (!ok || (i == j && std::abs(s - t) <= 1e-12 * (cuts[i].domain(0)[1] - cuts[i].domain(0)[0])))
            throw Error(name + ": cutting curves " + std::to_string(i) + " and " + std::to_string(j) + " touch or overlap near " + at(guess) +
                        " without crossing; expected curves that cross, or meet at their ends, within " + fmt(tol));
          auto& f = found[{i, j}];
          bool seen = false;
          for (const Pt& q : f) seen = seen || dist(q, p) <= tol;
          if (seen) continue;
          f.push_back(p);
          if (events.size() > kMaxEvents)
            throw Error(name + ": cutting curves cross or meet at more than " + std::to_string(kMaxEvents) + " points");
          add_event(i, s, p);
          add_event(j, t, eval2(cuts[j], t));
        }
      }
  }
  // Clusters of events within the tolerance (single linkage), numbered in event order.
  const std::size_t nev = events.size();
  std::vector<std::size_t> parent(nev);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  {
    std::vector<std::size_t> order(nev);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return events[a].p[0] < events[b].p[0] || (events[a].p[0] == events[b].p[0] && a < b); });
    for (std::size_t x = 0; x < nev; ++x)
      for (std::size_t y = x + 1; y < nev && events[order[y]].p[0] - events[order[x]].p[0] <= tol; ++y)
        if (dist(events[order[x]].p, events[order[y]].p) <= tol) {
          const std::size_t a = root(order[x]), b = root(order[y]);
          if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
  }
  std::vector<int> vertex_of(nev, -1);
  std::vector<Pt> vpos;
  std::vector<bool> vboundary;
  for (std::size_t e = 0; e < nev; ++e) {
    const std::size_t r = root(e);
    if (vertex_of[r] < 0) {
      vertex_of[r] = static_cast<int>(vpos.size());
      vpos.push_back(events[r].p);
      vboundary.push_back(false);
    }
    vertex_of[e] = vertex_of[r];
    const Pt& p = events[e].p;
    const Pt& q = vpos[static_cast<std::size_t>(vertex_of[e])];
    if (dist(p, q) > tol)
      throw Error(name + ": cutting curves meet ambiguously near " + at(q) + ": points " + fmt(dist(p, q)) +
                  " apart are joined through others; expected meeting points within " + fmt(tol));
    if (off_boundary(p) <= tol) vboundary[static_cast<std::size_t>(vertex_of[e])] = true;
  }
  const std::size_t nv = vpos.size();

  // 3. Edges: every curve split at its vertices; the boundary split at its vertices.
  std::vector<Edge> edges;
  for (std::size_t i = 0; i < nc; ++i) {
    if (!active[i]) continue;
    std::vector<std::pair<double, int>> cut;  // parameter, vertex
    for (std::size_t e : on_curve[i]) cut.push_back({events[e].t, vertex_of[e]});
    std::sort(cut.begin(), cut.end());
    // Consecutive cuts at one vertex: keep the first (the piece between them is shorter than
    // the tolerance), but keep the curve's last parameter at its end.
    std::vector<std::pair<double, int>> c2;
    for (const auto& x : cut)
      if (c2.empty() || x.second != c2.back().second) c2.push_back(x);
    if (c2.back().first != cut.back().first) {
      if (c2.size() > 1) c2.back().first = cut.back().first;
      else c2.push_back(cut.back());  // a closed curve met nowhere but at its start: one loop
    }
    const Sampled& s = smp[i];
    for (std::size_t k = 0; k + 1 < c2.size(); ++k) {
      Edge e;
      e.curve = static_cast<int>(i);
      e.s0 = c2[k].first, e.s1 = c2[k + 1].first;
      e.va = c2[k].second, e.vb = c2[k + 1].second;
      if (!(e.s1 > e.s0)) continue;
      e.poly.push_back(eval2(cuts[i], e.s0));
      for (std::size_t q = 0; q < s.t.size(); ++q)
        if (s.t[q] > e.s0 && s.t[q] < e.s1) e.poly.push_back(s.p[q]);
      e.poly.push_back(eval2(cuts[i], e.s1));
      edges.push_back(std::move(e));
    }
  }
  const std::size_t n_curve_edges = edges.size();
  {
    std::vector<std::pair<double, int>> bv;
    for (std::size_t v = 0; v < nv; ++v)
      if (vboundary[v]) bv.push_back({v < 4 ? perim(corners[v]) : perim(vpos[v]), static_cast<int>(v)});
    // The corners are vertices 0..3 (their events come first), at positions 0, W, W + H, 2W + H.
    bv[0].first = 0, bv[1].first = W, bv[2].first = W + H, bv[3].first = 2 * W + H;
    std::stable_sort(bv.begin(), bv.end());
    std::vector<Edge> bedges;
    for (std::size_t k = 0; k < bv.size(); ++k) {
      Edge e;
      e.va = bv[k].second, e.vb = bv[(k + 1) % bv.size()].second;
      if (e.va == e.vb) continue;
      e.a = vpos[static_cast<std::size_t>(e.va)], e.b = vpos[static_cast<std::size_t>(e.vb)];
      e.poly = {e.a, e.b};
      bedges.push_back(std::move(e));
    }
    // Boundary edges come first: the regions touching the boundary are found first.
    bedges.insert(bedges.end(), std::make_move_iterator(edges.begin()), std::make_move_iterator(edges.end()));
    edges = std::move(bedges);
  }
  const std::size_t n_boundary_edges = edges.size() - n_curve_edges;
  // Degrees: an end that meets nothing dangles.
  {
    std::vector<int> deg(nv, 0);
    for (const Edge& e : edges) ++deg[static_cast<std::size_t>(e.va)], ++deg[static_cast<std::size_t>(e.vb)];
    for (std::size_t e = 4; e < nev; ++e) {
      const auto v = static_cast<std::size_t>(vertex_of[e]);
      if (deg[v] >= 2 || vboundary[v]) continue;
      const int i = events[e].curve;
      const Pt q = events[e].p;
      throw Error(name + ": cutting curve " + std::to_string(i) + " is open and its end " + at(q) + " lies " + fmt(off_boundary(q)) +
                  " from the parameter rectangle's boundary and meets no other curve; expected a closed curve, ends on the boundary or on another curve within " + fmt(tol));
    }
  }

  // 4. Faces of the arrangement by walking half-edges (2e forward, 2e + 1 backward), turning
  //    at each vertex to the next half-edge clockwise from the one we came along: the face is
  //    on the left, bounded faces counter-clockwise.
  const double delta = 1e-3 * L;
  auto direction = [&](const Poly& p, bool fwd) {
    const std::size_t n = p.size();
    auto P = [&](std::size_t k) { return fwd ? p[k] : p[n - 1 - k]; };
    double len = 0;
    for (std::size_t k = 0; k + 1 < n; ++k) len += dist(p[k], p[k + 1]);
    const double want = std::min(delta, 0.5 * len);
    Pt q = P(n - 1);
    double acc = 0;
    for (std::size_t k = 0; k + 1 < n; ++k) {
      const double d = dist(P(k), P(k + 1));
      if (acc + d >= want) {
        const double f = d > 0 ? (want - acc) / d : 0.0;
        q = {P(k)[0] + f * (P(k + 1)[0] - P(k)[0]), P(k)[1] + f * (P(k + 1)[1] - P(k)[1])};
        break;
      }
      acc += d;
    }
    return std::atan2(q[1] - P(0)[1], q[0] - P(0)[0]);
  };
  auto tail = [&](int h) { const Edge& e = edges[static_cast<std::size_t>(h / 2)]; return h % 2 ? e.vb : e.va; };
  auto head = [&](int h) { const Edge& e = edges[static_cast<std::size_t>(h / 2)]; return h % 2 ? e.va : e.vb; };
  std::vector<std::vector<int>> cycles;
  std::vector<int> cycle_of;
  for (std::size_t round = 0;; ++round) {
    const int nh = static_cast<int>(2 * edges.size());
    std::vector<std::vector<std::pair<double, int>>> out(nv);
    for (int h = 0; h < nh; ++h)
      if (!edges[static_cast<std::size_t>(h / 2)].removed)
        out[static_cast<std::size_t>(tail(h))].push_back({direction(edges[static_cast<std::size_t>(h / 2)].poly, h % 2 == 0), h});
    std::vector<int> pos(static_cast<std::size_t>(nh), -1);
    for (auto& o : out) {
      std::sort(o.begin(), o.end());
      for (std::size_t k = 0; k < o.size(); ++k) pos[static_cast<std::size_t>(o[k].second)] = static_cast<int>(k);
    }
    auto next = [&](int h) {
      const int tw = h ^ 1;
      const auto& o = out[static_cast<std::size_t>(head(h))];
      const int k = pos[static_cast<std::size_t>(tw)];
      return o[static_cast<std::size_t>((k + static_cast<int>(o.size()) - 1) % static_cast<int>(o.size()))].second;
    };
    cycles.clear();
    cycle_of.assign(static_cast<std::size_t>(nh), -1);
    for (int h = 0; h < nh; ++h) {
      if (edges[static_cast<std::size_t>(h / 2)].removed || cycle_of[static_cast<std::size_t>(h)] >= 0) continue;
      std::vector<int> cyc;
      for (int g = h; cycle_of[static_cast<std::size_t>(g)] < 0; g = next(g)) {
        cycle_of[static_cast<std::size_t>(g)] = static_cast<int>(cycles.size());
        cyc.push_back(g);
      }
      cycles.push_back(std::move(cyc));
    }
    // An edge with one face on both sides separates nothing: drop it and walk again (bounded
    // by the number of edges).
    bool changed = false;
    for (std::size_t e = n_boundary_edges; e < edges.size(); ++e)
      if (!edges[e].removed && cycle_of[2 * e] == cycle_of[2 * e + 1]) edges[e].removed = changed = true;
    if (!changed) break;
    if (round > edges.size()) throw Error(name + ": the arrangement of the cutting curves does not settle");
  }
  auto cycle_poly = [&](const std::vector<int>& cyc) {
    Poly p;
    for (int h : cyc) {
      const Poly& q = edges[static_cast<std::size_t>(h / 2)].poly;
      if (h % 2 == 0) p.insert(p.end(), q.begin(), q.end() - 1);
      else p.insert(p.end(), q.rbegin(), q.rend() - 1);
    }
    return p;
  };
  // Components (union of vertices along edges); the rectangle's holds the corners.
  std::vector<std::size_t> comp(nv);
  std::iota(comp.begin(), comp.end(), 0);
  auto croot = [&](std::size_t a) {
    while (comp[a] != a) a = comp[a] = comp[comp[a]];
    return a;
  };
  for (const Edge& e : edges)
    if (!e.removed) {
      const std::size_t a = croot(static_cast<std::size_t>(e.va)), b = croot(static_cast<std::size_t>(e.vb));
      if (a != b) comp[std::max(a, b)] = std::min(a, b);
    }
  std::vector<Region> regions;
  std::vector<int> islands;  // clockwise cycles of components inside the rectangle
  for (std::size_t c = 0; c < cycles.size(); ++c) {
    const auto& cyc = cycles[c];
    Poly p = cycle_poly(cyc);
    const double a = signed_area(p);
    if (a > 0) {
      Region r;
      // Start at the cycle's first half-edge in edge order.
      const auto first = std::min_element(cyc.begin(), cyc.end()) - cyc.begin();
      r.outer.assign(cyc.begin() + first, cyc.end());
      r.outer.insert(r.outer.end(), cyc.begin(), cyc.begin() + first);
      r.outer_poly = std::move(p);
      regions.push_back(std::move(r));
    } else if (croot(static_cast<std::size_t>(tail(cyc.front()))) != croot(0)) {
      islands.push_back(static_cast<int>(c));
    }
  }
  std::stable_sort(regions.begin(), regions.end(), [](const Region& a, const Region& b) { return a.outer.front() < b.outer.front(); });
  std::vector<double> region_area;
  for (auto& r : regions) {
    region_area.push_back(signed_area(r.outer_poly));
    r.lo[0] = r.hi[0] = r.outer_poly[0][0], r.lo[1] = r.hi[1] = r.outer_poly[0][1];
    for (const Pt& q : r.outer_poly)
      for (int d = 0; d < 2; ++d) r.lo[d] = std::min(r.lo[d], q[static_cast<std::size_t>(d)]), r.hi[d] = std::max(r.hi[d], q[static_cast<std::size_t>(d)]);
  }
  for (int c : islands) {
    const auto& cyc = cycles[static_cast<std::size_t>(c)];
    const std::size_t own = croot(static_cast<std::size_t>(tail(cyc.front())));
    const Pt q = edges[static_cast<std::size_t>(cyc.front() / 2)].poly[edges[static_cast<std::size_t>(cyc.front() / 2)].poly.size() / 2];
    std::ptrdiff_t best = -1;
    for (std::size_t r = 0; r < regions.size(); ++r) {
      if (croot(static_cast<std::size_t>(tail(regions[r].outer.front()))) == own) continue;
      if (winding(regions[r].outer_poly, q) != 0 && (best < 0 || region_area[r] < region_area[static_cast<std::size_t>(best)]))
        best = static_cast<std::ptrdiff_t>(r);
    }
    if (best < 0) throw Error(name + ": cannot place the cutting curves near " + at(q) + " in a region");
    regions[static_cast<std::size_t>(best)].holes.push_back(cyc);
    regions[static_cast<std::size_t>(best)].hole_polys.push_back(cycle_poly(cyc));
  }
  const std::size_t nr = regions.size();

  // 5. Interior points: the grid point of each region farthest from every curve and the boundary.
  std::vector<std::pair<Pt, Pt>> dsegs;
  for (std::size_t e = n_boundary_edges; e < edges.size(); ++e) {
    if (edges[e].removed) continue;
    const Poly& p = edges[e].poly;
    for (std::size_t k = 0; k + 1 < p.size(); ++k) dsegs.push_back({p[k], p[k + 1]});
  }
  auto which = [&](Pt q) -> std::ptrdiff_t {
    for (std::size_t r = 0; r < nr; ++r) {
      const Region& R = regions[r];
      if (q[0] < R.lo[0] || q[0] > R.hi[0] || q[1] < R.lo[1] || q[1] > R.hi[1]) continue;
      if (winding(R.outer_poly, q) == 0) continue;
      bool in_hole = false;
      for (const Poly& h : R.hole_polys) in_hole = in_hole || winding(h, q) != 0;
      if (!in_hole) return static_cast<std::ptrdiff_t>(r);
    }
    return -1;
  };
  std::vector<double> best_d(nr, -1.0);
  std::vector<Pt> best_p(nr);
  for (int G = 32;; G *= 2) {
    for (int i = 0; i < G; ++i)
      for (int j = 0; j < G; ++j) {
        const Pt q{u0 + W * (i + 0.5) / G, v0 + H * (j + 0.5) / G};
        const std::ptrdiff_t r = which(q);
        if (r < 0) continue;
        double d = std::min({(q[0] - u0) / W * L, (u1 - q[0]) / W * L, (q[1] - v0) / H * L, (v1 - q[1]) / H * L});
        auto& bd = best_d[static_cast<std::size_t>(r)];
        if (d <= bd) continue;
        for (const auto& s : dsegs) {
          d = std::min(d, seg_closest(q, s.first, s.second).first);
          if (d <= bd) break;
        }
        if (d > bd) {
          bd = d;
          best_p[static_cast<std::size_t>(r)] = q;
        }
      }
    bool all = true;
    for (std::size_t r = 0; r < nr; ++r) all = all && best_d[r] > 1e3 * tol;
    if (all) break;
    if (G >= 256) {
      for (std::size_t r = 0; r < nr; ++r)
        if (!(best_d[r] > 1e3 * tol))
          throw Error(name + ": region " + std::to_string(r) + " of the cut face is too thin to hold an interior point (no grid point of 256 x 256 farther than " + fmt(1e3 * tol) + " from the curves)");
    }
  }

  // 6. Loops: the curves' pieces between vertices (exact restrictions of the curves), the
  //    boundary's straight pieces.
  auto piece = [&](int h) {
    const Edge& e = edges[static_cast<std::size_t>(h / 2)];
    spline::Curve c;
    if (e.curve < 0) {
      c = line(e.a, e.b);
    } else {
      const spline::Curve& full = cuts[static_cast<std::size_t>(e.curve)];
      const auto dom = full.domain(0);
      c = (e.s0 == dom[0] && e.s1 == dom[1]) ? full : spline::restrict_to(full, 0, e.s0, e.s1);
    }
    return h % 2 ? spline::reverse(c, 0) : c;
  };
  auto loop_of = [&](const std::vector<int>& cyc) {
    TrimLoop l;
    for (int h : cyc) {
      const Edge& e = edges[static_cast<std::size_t>(h / 2)];
      if (e.curve < 0 && dist(e.a, e.b) <= 0.01 * tol) continue;
      l.pieces.push_back(piece(h));
    }
    return l;
  };
  std::vector<FaceRegion> out;
  std::vector<double> xyz(static_cast<std::size_t>(face.dim()));
  for (std::size_t r = 0; r < nr; ++r) {
    std::vector<TrimLoop> loops{loop_of(regions[r].outer)};
    for (const auto& h : regions[r].holes) loops.push_back(loop_of(h));
    // untrim merges events closer than the surface's tolerance, which costs area of that order:
    // the loops get the tightest tolerance they meet, twice their largest gap between
    // consecutive pieces and control point outside the rectangle (at least 1e-10, at most
    // options.tolerance; relative to L).
    double gap = 0;
    for (const auto& l : loops)
      for (std::size_t k = 0; k < l.pieces.size(); ++k) {
        const auto& c = l.pieces[k];
        const auto& n = l.pieces[(k + 1) % l.pieces.size()];
        gap = std::max(gap, dist(eval2(c, c.domain(0)[1]), eval2(n, n.domain(0)[0])));
        const auto cp = c.points();
        for (std::size_t m = 0; m + 1 < cp.size(); m += 2)
          gap = std::max({gap, u0 - cp[m], cp[m] - u1, v0 - cp[m + 1], cp[m + 1] - v1});
      }
    const double loop_tol = std::min(options.tolerance, std::max(1e-10, 2 * gap / L));
    const Pt q = best_p[r];
    face.eval({q[0], q[1]}, xyz.data());
    const bool k = keep(xyz.data());
    out.push_back(FaceRegion{TrimmedSurface(face, std::move(loops), loop_tol), q[0], q[1], k});
  }
  return out;
}

std::vector<TrimmedSurface> trim_face(const spline::Surface& face, const std::vector<spline::Curve>& cuts,
                                      const KeepPredicate& keep, const FaceTrimOptions& options) {
  std::vector<TrimmedSurface> out;
  for (auto& r : face_regions(face, cuts, keep, options))
    if (r.kept) out.push_back(std::move(r.surface));
  return out;
}

}  // namespace trivox::geom
