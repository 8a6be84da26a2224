// Success rates of the kernel-based constructors on the random datasets of Fadila, Hong & Elber
// (Fadila et al. 2023, Sec. 5.1), beside the paper's figures (captions of
// Figs. 6, 7, 9, 10, 13, 14).
//
// Nine datasets: {Boolean sum, half Boolean sum, ruling} x {cubic Bezier, quartic Bezier,
// uniform quadratic B-spline with five control points}. Curves run between corners of [-1, 1]^2
// (left from (-1,-1) to (-1,1), inner control points x in (-2, 0), y in (-2, 2); the others
// alike); Boolean sum takes four curves, half Boolean sum the left and top ones (sharing
// (-1, 1)), ruling the bottom and top ones (ruling direction at order 3). A sample is kept when
// its boundary loop (from the inputs, as Lemmas 1-3 give it) turns by less than 180 degrees at
// each of the four corners (with a 1 degree margin) and is simple (no two non-adjacent edges of
// a polyline of 40 points per curve cross), its regular construction is invalid
// (geom::check_validity) and its boundary has a conservative kernel. Each kept
// sample runs Alg. 1 with degree raising (up to degree 17; 40 for quadratic ruling) and with
// refinement (up to 20 knots per span); success is Acceptance::nonnegative (det J >= 0 with the
// boundary's orientation, decided exactly from the Bezier coefficients of det J with
// subdivision: the paper's criterion, Sec. 1 and Theorem 4). "1st" is success at iteration 0
// (interior points moved, nothing added: Alg. 1's loop starts at i = 0 with S_0 itself),
// "all" success within the maximum. Each dataset runs twice: with the interior points at the
// kernel centroid (Alg. 1 line 9, "centroid") and with KernelPoint::fitted ("fitted": the
// centroid first, then a point of a tighter conservative kernel where det J's coefficients
// allow it; Fadila et al. 2023, Sec. 7).
//
// Deterministic: candidate i of a dataset draws from its own splitmix64 stream seeded by
// (seed, dataset, i), candidates are screened in parallel but kept in index order, and each
// kept sample's runs are independent, so the table does not depend on the thread count.
// Screening tests the corners from the control polygons first (clamped curves) and prunes the
// polyline's segment pairs by bounding boxes; the samples kept are the same as testing
// everything on the curves.
//
// The paper does not say whether the inner control points are ordered along the curve: by
// default they are drawn as they come (the literal reading); `--inner sorted` orders them along
// the curve's direction (x for bottom and top, y for left and right).
//
// Usage: trivox_bench_kernel_success --help
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "trivox/construct/kernel_construct.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/kernel.hpp"
#include "trivox/geom/validity.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox;
using construct::AddDof;
using construct::KernelOp;
using spline::Curve;
using spline::KnotVector;
using Clock = std::chrono::steady_clock;

namespace {

enum class Kind { cubic, quartic, quadratic };
const char* kind_name(Kind k) { return k == Kind::cubic ? "cubic Bezier" : k == Kind::quartic ? "quartic Bezier" : "quadratic B-spline"; }

struct Rng {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform(double a, double b) { return a + (b - a) * static_cast<double>(next() >> 11) * 0x1.0p-53; }
};

using V2 = std::array<double, 2>;

double cross(const V2& a, const V2& b) { return a[0] * b[1] - a[1] * b[0]; }
V2 sub(const V2& a, const V2& b) { return {a[0] - b[0], a[1] - b[1]}; }

using Ctl = std::vector<V2>;

/// The control points of a random curve from `from` to `to` with inner control points in the
/// box [lo, hi]; `sorted`: the inner points ordered along the direction from `from` to `to`.
Ctl random_points(Rng& rng, Kind kind, V2 from, V2 to, V2 lo, V2 hi, bool sorted) {
  const int n = kind == Kind::cubic ? 4 : 5;
  Ctl p{from};
  for (int i = 1; i + 1 < n; ++i) p.push_back({rng.uniform(lo[0], hi[0]), rng.uniform(lo[1], hi[1])});
  if (sorted) {
    const auto axis = static_cast<std::size_t>(from[0] == to[0] ? 1 : 0);
    const bool up = to[axis] > from[axis];
    std::sort(p.begin() + 1, p.end(), [&](const V2& a, const V2& b) { return up ? a[axis] < b[axis] : a[axis] > b[axis]; });
  }
  p.push_back(to);
  return p;
}

Curve make_curve(Kind kind, const Ctl& c) {
  std::vector<double> p;
  for (const V2& q : c) p.insert(p.end(), q.begin(), q.end());
  const int n = static_cast<int>(c.size());
  const KnotVector kv = kind == Kind::quadratic ? KnotVector::uniform(3, n - 2) : KnotVector::bezier(n);
  return Curve({kv}, 2, std::move(p));
}

/// The control polygons of one random input (Fadila et al. 2023, Sec. 5.1), in the order the
/// regular constructor takes the curves: Boolean sum [bottom, top, left, right]; half Boolean sum
/// the top and the left curves, both starting at their shared corner (-1, 1); ruling [bottom, top].
std::vector<Ctl> random_input(Rng& r, KernelOp op, Kind k, bool sorted) {
  auto left = [&] { return random_points(r, k, {-1, -1}, {-1, 1}, {-2, -2}, {0, 2}, sorted); };
  auto right = [&] { return random_points(r, k, {1, -1}, {1, 1}, {0, -2}, {2, 2}, sorted); };
  auto bottom = [&] { return random_points(r, k, {-1, -1}, {1, -1}, {-2, -2}, {2, 0}, sorted); };
  auto top = [&] { return random_points(r, k, {-1, 1}, {1, 1}, {-2, 0}, {2, 2}, sorted); };
  switch (op) {
    case KernelOp::boolean_sum: {
      Ctl b = bottom(), t = top(), l = left(), rr = right();
      return {b, t, l, rr};
    }
    case KernelOp::half_boolean_sum: {
      Ctl l = left(), t = top();
      std::reverse(l.begin(), l.end());
      return {t, l};
    }
    default: {
      Ctl b = bottom(), t = top();
      return {b, t};
    }
  }
}

/// The corners of the boundary loop from the control polygons alone (clamped curves: the end
/// tangents point along the first and last legs): the same verdict as screen_boundary's corner
/// test, without building a curve. Loops as input_loop builds them.
bool corners_ok(KernelOp op, const std::vector<Ctl>& c) {
  struct Ends {
    V2 start, end;  // tangent directions at the start and the end
  };
  auto ends = [](const Ctl& p) { return Ends{sub(p[1], p[0]), sub(p.back(), p[p.size() - 2])}; };
  auto reversed = [](Ends e) { return Ends{{-e.end[0], -e.end[1]}, {-e.start[0], -e.start[1]}}; };
  auto segment = [](const V2& a, const V2& b) { return Ends{sub(b, a), sub(b, a)}; };
  std::vector<Ends> loop;
  switch (op) {
    case KernelOp::boolean_sum: loop = {ends(c[0]), ends(c[3]), reversed(ends(c[1])), reversed(ends(c[2]))}; break;
    case KernelOp::half_boolean_sum: loop = {ends(c[0]), ends(c[1]), reversed(ends(c[0])), reversed(ends(c[1]))}; break;
    default: loop = {ends(c[0]), segment(c[0].back(), c[1].back()), reversed(ends(c[1])), segment(c[1][0], c[0][0])};
  }
  int turn = 0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const V2& ta = loop[(i + loop.size() - 1) % loop.size()].end;
    const V2& tb = loop[i].start;
    const double la = std::hypot(ta[0], ta[1]), lb = std::hypot(tb[0], tb[1]);
    if (!(la > 0 && lb > 0)) return false;
    const double sine = cross(ta, tb) / (la * lb);
    const int s = sine > std::sin(M_PI / 180) ? 1 : sine < -std::sin(M_PI / 180) ? -1 : 0;
    if (s == 0 || (turn != 0 && s != turn)) return false;
    turn = s;
  }
  return true;
}

bool segments_cross(const V2& a, const V2& b, const V2& c, const V2& d) {
  const double d1 = cross(sub(b, a), sub(c, a)), d2 = cross(sub(b, a), sub(d, a));
  const double d3 = cross(sub(d, c), sub(a, c)), d4 = cross(sub(d, c), sub(b, c));
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

Curve translated(Curve c, double dx, double dy) {
  for (int i = 0; i < c.size(); ++i) c.point(i)[0] += dx, c.point(i)[1] += dy;
  return c;
}

Curve segment(const std::vector<double>& a, const std::vector<double>& b) {
  return Curve({KnotVector::bezier(2)}, 2, {a[0], a[1], b[0], b[1]});
}

/// The boundary loop that the regular construction will have (Fadila et al. 2023 Lemmas 1-3), built
/// from the inputs directly so that screening needs no construction: S(u,0), S(1,v), S(u,1) and
/// S(0,v), the last two reversed.
std::vector<Curve> input_loop(KernelOp op, const std::vector<Curve>& c) {
  switch (op) {
    case KernelOp::boolean_sum: return {c[0], c[3], spline::reverse(c[1], 0), spline::reverse(c[2], 0)};
    case KernelOp::half_boolean_sum: {
      const auto p = c[0].eval({0.0}), e1 = c[0].eval({1.0}), e2 = c[1].eval({1.0});
      return {c[0], translated(c[1], e1[0] - p[0], e1[1] - p[1]),
              spline::reverse(translated(c[0], e2[0] - p[0], e2[1] - p[1]), 0), spline::reverse(c[1], 0)};
    }
    default:
      return {c[0], segment(c[0].eval({1.0}), c[1].eval({1.0})), spline::reverse(c[1], 0),
              segment(c[1].eval({0.0}), c[0].eval({0.0}))};
  }
}

/// Simple boundary and corners turning by less than 180 degrees (Fadila et al. 2023, Sec. 4's
/// assumptions). Cheapest test first: the corners need only the end tangents, and the sign s for
/// which all four turn the right way; the orientation (from the signed area) must then be s. The
/// same verdicts as testing the corners against the orientation directly.
const char* screen_boundary(const std::vector<Curve>& loop) {
  // Corners: the incoming tangent of curve c-1 and the outgoing one of curve c.
  int turn = 0;  // +1: every corner turns left, -1: every corner turns right
  for (std::size_t c = 0; c < loop.size(); ++c) {
    const Curve& a = loop[(c + loop.size() - 1) % loop.size()];
    const Curve& b = loop[c];
    const auto da = a.eval_derivatives({a.domain(0)[1]}, 1), db = b.eval_derivatives({b.domain(0)[0]}, 1);
    const V2 ta{da[2], da[3]}, tb{db[2], db[3]};
    const double la = std::hypot(ta[0], ta[1]), lb = std::hypot(tb[0], tb[1]);
    if (!(la > 0 && lb > 0)) return "corner";
    const double sine = cross(ta, tb) / (la * lb);
    const int s = sine > std::sin(M_PI / 180) ? 1 : sine < -std::sin(M_PI / 180) ? -1 : 0;
    if (s == 0 || (turn != 0 && s != turn)) return "corner";
    turn = s;
  }
  const int per = 40;
  std::vector<V2> poly;
  poly.reserve(loop.size() * per);
  double basis[16];
  for (const Curve& c : loop) {
    const KnotVector& kv = c.knots(0);
    const int k = kv.order();
    for (int i = 0; i < per; ++i) {
      const double t = c.domain(0)[0] + (c.domain(0)[1] - c.domain(0)[0]) * i / per;
      const int span = kv.find_span(t);
      kv.basis(span, t, basis);
      V2 p{0.0, 0.0};
      for (int j = 0; j < k; ++j) {
        const auto q = c.point(span - k + 1 + j);
        p[0] += basis[j] * q[0];
        p[1] += basis[j] * q[1];
      }
      poly.push_back(p);
    }
  }
  // Every pair of non-adjacent segments, pruned by the bounding boxes of runs of 8 segments
  // (inclusive overlap: the same verdict as testing every pair).
  const std::size_t n = poly.size(), run = 8, runs = (n + run - 1) / run;
  std::vector<std::array<double, 4>> box(runs, {HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL});
  for (std::size_t i = 0; i < n; ++i)
    for (const V2& p : {poly[i], poly[(i + 1) % n]}) {
      auto& b = box[i / run];
      b = {std::min(b[0], p[0]), std::min(b[1], p[1]), std::max(b[2], p[0]), std::max(b[3], p[1])};
    }
  for (std::size_t a = 0; a < runs; ++a)
    for (std::size_t b = a; b < runs; ++b) {
      const auto &x = box[a], &y = box[b];
      if (x[0] > y[2] || y[0] > x[2] || x[1] > y[3] || y[1] > x[3]) continue;
      for (std::size_t i = a * run; i < std::min(n, (a + 1) * run); ++i)
        for (std::size_t j = std::max(i + 2, b * run); j < std::min(n, (b + 1) * run); ++j) {
          if (i == 0 && j == n - 1) continue;
          if (segments_cross(poly[i], poly[i + 1], poly[j], poly[(j + 1) % n])) return "self-intersecting";
        }
    }
  // Orientation from the signed area (geom::planar_kernel computes it the same way, exactly).
  double area2 = 0.0;
  for (const Curve& c : loop)
    for (int i = 0; i <= 64; ++i) {
      const double t = c.domain(0)[0] + (c.domain(0)[1] - c.domain(0)[0]) * i / 64;
      const auto d = c.eval_derivatives({t}, 1);
      area2 += (i == 0 || i == 64 ? 0.5 : 1.0) * (d[0] * d[3] - d[1] * d[2]) * (c.domain(0)[1] - c.domain(0)[0]) / 64;
    }
  if ((area2 > 0 ? 1 : -1) != turn) return "corner";
  return nullptr;
}

struct Paper {
  const char* elevate_first;
  const char* elevate_all;
  const char* refine_first;
  const char* refine_all;
};

/// Figure captions: Figs. 6/7 (Boolean sum), 9/10 (half Boolean sum), 13/14 (ruling). Fig. 13's
/// caption gives no numbers; its first iteration equals Fig. 14's (nothing added yet), and the
/// text says quadratic ruling stays "over 80%" after raising to degree 40.
Paper paper(KernelOp op, Kind k) {
  const int i = static_cast<int>(k);
  switch (op) {
    case KernelOp::boolean_sum: {
      static const Paper p[3] = {{"98.8", "99.9", "98.8", "99.9"}, {"97.3", "99.4", "97.3", "99.9"}, {"81.7", "90.1", "81.7", "100"}};
      return p[i];
    }
    case KernelOp::half_boolean_sum: {
      static const Paper p[3] = {{"79.2", "100", "79.2", "100"}, {"85", "99.9", "85", "100"}, {"99.7", "100", "99.7", "100"}};
      return p[i];
    }
    default: {
      static const Paper p[3] = {{"(93)", "n/a", "93", "99.8"}, {"(84.8)", "n/a", "84.8", "98.9"}, {"(8.5)", ">80", "8.5", "99.4"}};
      return p[i];
    }
  }
}

struct Candidate {
  bool kept = false;
  const char* rejected = nullptr;
  std::vector<Curve> curves;
  spline::Surface s0;
};

Candidate screen(KernelOp op, Kind kind, std::uint64_t seed, int dataset, std::uint64_t index, bool sorted) {
  Rng rng{seed * 0x100000001B3ull ^ (static_cast<std::uint64_t>(dataset) << 48) ^ index * 0xD6E8FEB86659FD93ull};
  Candidate c;
  const auto ctl = random_input(rng, op, kind, sorted);
  if (!corners_ok(op, ctl)) return c.rejected = "corner", c;
  for (const Ctl& p : ctl) c.curves.push_back(make_curve(kind, p));
  try {
    construct::KernelConstructOptions o;
    if (const char* why = screen_boundary(input_loop(op, c.curves))) return c.rejected = why, c;
    c.s0 = construct::regular_construct(op, c.curves, o);
    if (geom::check_validity(c.s0).verdict == geom::Validity::valid) return c.rejected = "regular valid", c;
    if (geom::planar_kernel(c.s0, o.kernel).empty()) return c.rejected = "no kernel", c;
  } catch (const Error&) {
    return c.rejected = "error", c;
  }
  c.kept = true;
  return c;
}

// ---------------------------------------------------------------------------------------------
// --bounds: necessary conditions on the interior point. With every interior control point at K,
// det J(K)(u,v) = A(u,v) + G(u,v) . K (terms with K twice are K x K = 0); requiring det J(K) >= 0
// (with the boundary's orientation, the acceptance's tolerance) at samples (u,v) gives
// half-planes in K. If they leave nothing of a region, no K in it can be accepted: an upper bound
// on what any choice of a single point could give.

spline::Surface with_interior(spline::Surface s, const V2& k) {
  for (int r = 0; r < s.size(); ++r) {
    const auto i = s.multi_index(r);
    if (i[0] == 0 || i[1] == 0 || i[0] == s.count(0) - 1 || i[1] == s.count(1) - 1) continue;
    s.point(r)[0] = k[0];
    s.point(r)[1] = k[1];
  }
  return s;
}

std::vector<V2> clip_polygon(const std::vector<V2>& poly, double a, double b, double c) {
  std::vector<V2> out;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const V2 &p = poly[i], &q = poly[(i + 1) % n];
    const double dp = a * p[0] + b * p[1] + c, dq = a * q[0] + b * q[1] + c;
    if (dp >= 0) out.push_back(p);
    if ((dp > 0 && dq < 0) || (dp < 0 && dq > 0)) {
      const double t = dp / (dp - dq);
      out.push_back({p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])});
    }
  }
  return out;
}

/// Whether some K in the convex polygon `region` meets det J(K) >= -1e-9 max|det J| at every
/// point of a 101 x 101 parameter grid (false proves that no K in it is accepted).
bool some_point_possible(const spline::Surface& s, int orientation, std::vector<V2> region) {
  const spline::Surface d0 = spline::jacobian_determinant(with_interior(s, {0, 0}));
  const spline::Surface dx = spline::jacobian_determinant(with_interior(s, {1, 0}));
  const spline::Surface dy = spline::jacobian_determinant(with_interior(s, {0, 1}));
  const int n = 100;
  std::vector<std::array<double, 3>> h;
  double scale = 0.0;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const std::array<double, 2> uv{s.domain(0)[0] + (s.domain(0)[1] - s.domain(0)[0]) * i / n,
                                     s.domain(1)[0] + (s.domain(1)[1] - s.domain(1)[0]) * j / n};
      const double a = d0.eval(uv)[0];
      h.push_back({orientation * (dx.eval(uv)[0] - a), orientation * (dy.eval(uv)[0] - a), orientation * a});
      scale = std::max(scale, std::abs(a));
    }
  const double tau = 1e-9 * scale;
  for (const auto& c : h) {
    const double len = std::hypot(c[0], c[1]);
    if (len <= 1e-14 * scale) {
      if (c[2] < -tau) return false;
      continue;
    }
    region = clip_polygon(region, c[0] / len, c[1] / len, (c[2] + tau) / len);
    if (region.size() < 3) return false;
  }
  return true;
}

struct Possible {
  bool plane = false, kernel = false;
};

/// Some point in [-3, 3]^2, some in the conservative kernel with 8 refinements (inside the true
/// kernel), possible for s (S_0 with freedom added).
Possible possible(const spline::Surface& s0, const spline::Surface& s) {
  Possible p;
  const auto k = geom::planar_kernel(s0);
  p.plane = some_point_possible(s, k.orientation, {{-3, -3}, {3, -3}, {3, 3}, {-3, 3}});
  if (p.plane) {
    geom::KernelOptions o;
    o.refinements = 8;
    const auto tight = geom::planar_kernel(s0, o);
    p.kernel = !tight.empty() && some_point_possible(s, k.orientation, {tight.vertices.begin(), tight.vertices.end()});
  }
  return p;
}

/// Iteration of first success (-1: none) of Alg. 1 with the given way of adding freedom.
int run(const spline::Surface& s0, AddDof how, int max_dof, construct::KernelPoint point, double retry_spread) {
  construct::KernelConstructOptions o;
  o.add_dof = how;
  o.max_dof = max_dof;
  o.kernel_point = point;
  o.retry_spread = retry_spread;
  const auto r = construct::kernel_based(s0, o);
  return r.valid ? r.iterations : -1;
}

struct Args {
  int samples = 1000;
  int threads = 2;
  std::uint64_t seed = 2023;
  std::string op = "all";
  std::string curves = "all";
  bool sorted = false;
  std::string point = "both";
  bool bounds = false;
  double retry_spread = 0.5;
};

const char* usage =
    "usage: trivox_bench_kernel_success [--samples N=1000] [--threads N=2] [--seed N=2023]\n"
    "         [--op boolean_sum|half_boolean_sum|ruled|all] [--curves cubic|quartic|quadratic|all]\n"
    "         [--inner unsorted|sorted] [--point centroid|fitted|both] [--retry-spread W=0.5] [--bounds]\n"
    "Success rates of the kernel-based constructors on the random datasets of Fadila et al. 2023, Sec. 5.1.\n"
    "  --samples   samples kept per dataset (regular construction invalid, boundary with a kernel)\n"
    "  --threads   TBB threads (the table does not depend on it)\n"
    "  --seed      random seed of the datasets\n"
    "  --inner     inner control points as drawn (the paper's text) or sorted along the curve\n"
    "  --point     interior control points at the kernel centroid (Alg. 1), at the fitted point\n"
    "              when the centroid fails (construct::KernelPoint::fitted, Fadila et al. 2023, Sec. 7), or both\n"
    "  --retry-spread  fitted: last try per iteration on the Sec. 6 grid, W x kernel size wide (0: none)\n"
    "  --bounds    also upper bounds for any single interior point (necessary conditions on a\n"
    "              101 x 101 grid): at iteration 0, and with degree raising (every degree) for the\n"
    "              samples that a single fitted point fails (slow for high degrees)\n"
    "The old positional form [samples] [threads] [seed] [op] [unsorted|sorted] [curves] is accepted.\n";

bool parse(int argc, char** argv, Args& a) {
  std::vector<std::string> pos;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (k == "--help" || k == "-h") return std::fputs(usage, stdout), std::exit(0), true;
    if (k == "--bounds") {
      a.bounds = true;
      continue;
    }
    if (k.rfind("--", 0) == 0) {
      if (i + 1 >= argc) return false;
      const std::string v = argv[++i];
      if (k == "--samples") a.samples = std::atoi(v.c_str());
      else if (k == "--threads") a.threads = std::atoi(v.c_str());
      else if (k == "--seed") a.seed = std::strtoull(v.c_str(), nullptr, 10);
      else if (k == "--op") a.op = v;
      else if (k == "--curves") a.curves = v;
      else if (k == "--inner") a.sorted = v == "sorted";
      else if (k == "--point") a.point = v;
      else if (k == "--retry-spread") a.retry_spread = std::atof(v.c_str());
      else return false;
    } else {
      pos.push_back(k);
    }
  }
  if (pos.size() > 0) a.samples = std::atoi(pos[0].c_str());
  if (pos.size() > 1) a.threads = std::atoi(pos[1].c_str());
  if (pos.size() > 2) a.seed = std::strtoull(pos[2].c_str(), nullptr, 10);
  if (pos.size() > 3) a.op = pos[3];
  if (pos.size() > 4) a.sorted = pos[4] == "sorted";
  if (pos.size() > 5) a.curves = pos[5];
  return a.samples >= 1 && a.threads >= 1 && (a.point == "centroid" || a.point == "fitted" || a.point == "both");
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (!parse(argc, argv, args)) {
    std::fputs(usage, stderr);
    return 2;
  }
  const int samples = args.samples, threads = args.threads;
  const std::uint64_t seed = args.seed;
  const std::string only = args.op, only_kind = args.curves;
  const bool sorted = args.sorted;
  std::vector<construct::KernelPoint> points;
  if (args.point != "fitted") points.push_back(construct::KernelPoint::centroid);
  if (args.point != "centroid") points.push_back(construct::KernelPoint::fitted);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  std::printf("Kernel-based constructors on Fadila et al. 2023, Sec. 5.1 random datasets: %d samples each, seed %llu, %d threads, "
              "inner control points %s\n",
              samples, static_cast<unsigned long long>(seed), threads, sorted ? "sorted along the curve" : "unsorted");
  std::printf("success = det J >= 0 (exact: Bezier coefficients of det J, subdivision) after moving the interior control\n"
              "points to the kernel centroid (Alg. 1; \"centroid\") or, where that fails, to the fitted point (\"fitted\")\n\n");
  std::printf("%-17s %-19s %-8s %10s | %-28s | %-28s | %7s\n", "operator", "curves", "point", "screened",
              "degree raising: 1st / all", "refinement: 1st / all", "seconds");
  std::printf("%-17s %-19s %-8s %10s | %-28s | %-28s |\n", "", "", "", "", "  trivox        paper", "  trivox        paper");
  const auto t_all = Clock::now();
  int dataset = 0;
  for (KernelOp op : {KernelOp::boolean_sum, KernelOp::half_boolean_sum, KernelOp::ruled})
    for (Kind kind : {Kind::cubic, Kind::quartic, Kind::quadratic}) {
      ++dataset;
      if (!only.empty() && only != "all" && only != construct::kernel_op_name(op)) continue;
      if (only_kind != "all" && std::string(kind_name(kind)).find(only_kind) == std::string::npos) continue;
      auto t0 = Clock::now();
      // Screen candidates in parallel batches, keep them in index order.
      std::vector<Candidate> kept;
      std::uint64_t next = 0;
      long long rejected_valid = 0, rejected_corner = 0, rejected_crossing = 0, rejected_kernel = 0;
      unsigned long long examined = 0;
      while (static_cast<int>(kept.size()) < samples && next < 2000000000ull) {
        const std::size_t batch = 8192;
        std::vector<Candidate> cs(batch);
        tbb::parallel_for(std::size_t{0}, batch, [&](std::size_t i) { cs[i] = screen(op, kind, seed, dataset, next + i, sorted); });
        next += batch;
        for (auto& c : cs) {
          if (static_cast<int>(kept.size()) >= samples) break;
          ++examined;
          if (c.kept) kept.push_back(std::move(c));
          else if (std::string(c.rejected) == "regular valid") ++rejected_valid;
          else if (std::string(c.rejected) == "no kernel") ++rejected_kernel;
          else if (std::string(c.rejected) == "corner") ++rejected_corner;
          else ++rejected_crossing;
        }
      }
      const double screen_secs = std::chrono::duration<double>(Clock::now() - t0).count();
      const int degree = kind == Kind::cubic ? 3 : kind == Kind::quartic ? 4 : 2;
      const int max_degree = (op == KernelOp::ruled && kind == Kind::quadratic) ? 40 : 17;
      const int n = static_cast<int>(kept.size());
      std::printf("    kept %d; dropped: corner >= 179 degrees %lld, self-intersecting %lld, regular valid %lld, no kernel %lld "
                  "(screening %.1f s)\n",
                  n, rejected_corner, rejected_crossing, rejected_valid, rejected_kernel, screen_secs);
      for (construct::KernelPoint point : points) {
        t0 = Clock::now();
        std::vector<int> elev(static_cast<std::size_t>(n)), refi(static_cast<std::size_t>(n));
        tbb::parallel_for(0, 2 * n, [&](int j) {
          const auto i = static_cast<std::size_t>(j / 2);
          if (j % 2 == 0) elev[i] = run(kept[i].s0, AddDof::elevate, max_degree - degree, point, args.retry_spread);
          else refi[i] = run(kept[i].s0, AddDof::refine, 20, point, args.retry_spread);
        });
        auto rates = [&](const std::vector<int>& it) {
          int first = 0, all = 0;
          for (int v : it) first += v == 0, all += v >= 0;
          return std::array<double, 2>{100.0 * first / std::max(1, n), 100.0 * all / std::max(1, n)};
        };
        const auto e = rates(elev), r = rates(refi);
        const Paper p = paper(op, kind);
        const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
        char ecol[64], rcol[64];
        std::snprintf(ecol, sizeof ecol, "%5.1f / %5.1f  %6s / %-4s", e[0], e[1], p.elevate_first, p.elevate_all);
        std::snprintf(rcol, sizeof rcol, "%5.1f / %5.1f  %6s / %-4s", r[0], r[1], p.refine_first, p.refine_all);
        std::printf("%-17s %-19s %-8s %10llu | %-28s | %-28s | %7.1f\n", construct::kernel_op_name(op), kind_name(kind),
                    point == construct::KernelPoint::centroid ? "centroid" : "fitted", examined, ecol, rcol, secs);
        // Per-iteration first successes (the paper's graphs).
        auto histogram = [&](const std::vector<int>& it, int max_i) {
          std::string h;
          char buf[32];
          for (int i = 0; i <= max_i; ++i) {
            const auto k = std::count(it.begin(), it.end(), i);
            if (k == 0) continue;
            std::snprintf(buf, sizeof buf, " %d:%d", i, static_cast<int>(k));
            h.append(buf);
          }
          std::snprintf(buf, sizeof buf, " failed:%d", static_cast<int>(std::count(it.begin(), it.end(), -1)));
          h.append(buf);
          return h;
        };
        std::printf("    raising, successes per iteration:%s\n", histogram(elev, max_degree - degree).c_str());
        std::printf("    refining, successes per iteration:%s\n", histogram(refi, 20).c_str());
        std::fflush(stdout);
        if (args.bounds && point == points.back()) {
          // Iteration 0 for every sample; raising at every degree for the samples that failed.
          std::vector<Possible> first(static_cast<std::size_t>(n)), raised(static_cast<std::size_t>(n));
          tbb::parallel_for(0, n, [&](int j) {
            const auto i = static_cast<std::size_t>(j);
            first[i] = possible(kept[i].s0, kept[i].s0);
            // Samples that a single point (fitted, no Sec. 6 retry) makes valid need no bound.
            if (run(kept[i].s0, AddDof::elevate, max_degree - degree, construct::KernelPoint::fitted, 0.0) >= 0)
              return raised[i] = {true, true}, void();
            for (int r = 0; r <= max_degree - degree && !raised[i].kernel; ++r) {
              const spline::Surface s = r == 0 ? kept[i].s0 : spline::elevate(spline::elevate(kept[i].s0, 0, r), 1, r);
              const Possible p = r == 0 ? first[i] : possible(kept[i].s0, s);
              raised[i].plane = raised[i].plane || p.plane;
              raised[i].kernel = raised[i].kernel || p.kernel;
            }
          });
          auto share = [&](const std::vector<Possible>& v, bool Possible::*m) {
            return 100.0 * static_cast<double>(std::count_if(v.begin(), v.end(), [&](const Possible& p) { return p.*m; })) /
                   std::max(1, n);
          };
          std::printf("    bounds (any single point; necessary conditions): iteration 0 <= %.1f%% in [-3,3]^2, <= %.1f%% in "
                      "the kernel; raising, all <= %.1f%% / %.1f%%\n",
                      share(first, &Possible::plane), share(first, &Possible::kernel), share(raised, &Possible::plane),
                      share(raised, &Possible::kernel));
          std::fflush(stdout);
        }
      }
    }
  std::printf("\ntotal %.1f s\n", std::chrono::duration<double>(Clock::now() - t_all).count());
  return 0;
}
