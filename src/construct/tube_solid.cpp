#include "trivox/construct/tube_solid.hpp"

#include <cmath>
#include <cstdio>

#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::construct {

namespace {

using spline::KnotVector;

/// a + f (b - a), control point by control point (curves of one space).
Curve lerp(const Curve& a, const Curve& b, double f) {
  std::vector<double> p(a.points().begin(), a.points().end());
  for (std::size_t i = 0; i < p.size(); ++i) p[i] += f * (b.points()[i] - p[i]);
  return Curve(a.knot_vectors(), a.dim(), std::move(p));
}

/// The segment from a(t) to b(t): a linear curve on [0, 1].
Curve segment(const Curve& a, const Curve& b, double t) {
  std::vector<double> p = a.eval({t});
  const std::vector<double> q = b.eval({t});
  p.insert(p.end(), q.begin(), q.end());
  return Curve({KnotVector::bezier(2)}, a.dim(), std::move(p));
}

/// (1 - s) a(v) + s b(v) as a surface in (s, v).
Surface ruled_sv(const Curve& a, const Curve& b) { return spline::swap_directions(ruled(a, b), 0, 1); }

double det_at_centre(const Trivariate& t) {
  const auto d = t.eval_derivatives({0.5, 0.5, 0.5}, 1);
  const int k = t.dim();
  const auto col = [&](std::array<int, 3> a) { return d.data() + spline::derivative_slot<3>(a) * k; };
  const double *a = col({1, 0, 0}), *b = col({0, 1, 0}), *c = col({0, 0, 1});
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
}

std::vector<TubeCell> build(const Surface& s, double core) {
  std::array<Curve, 5> q, k;
  for (int i = 0; i < 4; ++i) q[static_cast<std::size_t>(i)] = spline::iso(s, 0, i / 4.0);
  q[4] = q[0];
  // c = the mean of the four quarter curves (one v-space: iso curves of one surface).
  Curve c = q[0];
  for (std::size_t i = 0; i < c.points().size(); ++i)
    c.points()[i] = (q[0].points()[i] + q[1].points()[i] + q[2].points()[i] + q[3].points()[i]) / 4.0;
  for (std::size_t i = 0; i < 5; ++i) k[i] = lerp(c, q[i], core);
  std::vector<TubeCell> out;
  {
    // The core (s, t, v): corners K_0 (0,0), K_1 (1,0), K_2 (1,1), K_3 (0,1).
    const std::array<Surface, 6> faces{ruled_sv(k[0], k[3]), ruled_sv(k[1], k[2]),
                                       ruled_sv(k[0], k[1]), ruled_sv(k[3], k[2]),
                                       ruled(segment(k[0], k[1], 0.0), segment(k[3], k[2], 0.0)),
                                       ruled(segment(k[0], k[1], 1.0), segment(k[3], k[2], 1.0))};
    out.push_back({"core", boolean_sum(faces)});
  }
  for (std::size_t i = 0; i < 4; ++i) {
    // Side i (s, v, w): from the core's side K_i K_{i+1} (w = 0) to the tube's quarter (w = 1).
    const Surface quarter = normalized(spline::restrict_to(s, 0, static_cast<double>(i) / 4, (i + 1.0) / 4));
    const std::array<Surface, 6> faces{ruled(k[i], q[i]),
                                       ruled(k[i + 1], q[i + 1]),
                                       ruled(segment(k[i], k[i + 1], 0.0), spline::iso(quarter, 1, 0.0)),
                                       ruled(segment(k[i], k[i + 1], 1.0), spline::iso(quarter, 1, 1.0)),
                                       ruled_sv(k[i], k[i + 1]),
                                       quarter};
    std::string part(1, 's');  // not "s" + to_string: g++ 12 warns -Wrestrict on that
    part += std::to_string(i);
    out.push_back({std::move(part), boolean_sum(faces)});
  }
  return out;
}

}  // namespace

std::vector<TubeCell> tube_solid(const Surface& tube, double core, double tolerance) {
  if (tube.rational()) throw Error("tube solid: the tube is rational; expected a polynomial surface");
  if (tube.dim() < 3)
    throw Error("tube solid: the tube has " + std::to_string(tube.dim()) + " coordinates; expected 3 or more");
  if (!(core > 0.0 && core < 1.0)) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", core);
    throw Error(std::string("tube solid: core ") + buf + "; expected a relative size in (0, 1)");
  }
  const Surface s = normalized(tube);
  // Closed in u: the first and last control columns agree (clamped, so these are S(0, v), S(1, v)).
  double gap = 0.0;
  for (int j = 0; j < s.count(1); ++j) {
    const auto a = s.point(s.row({0, j})), b = s.point(s.row({s.count(0) - 1, j}));
    double d2 = 0.0;
    for (int c = 0; c < 3; ++c) d2 += (a[static_cast<std::size_t>(c)] - b[static_cast<std::size_t>(c)]) *
                                      (a[static_cast<std::size_t>(c)] - b[static_cast<std::size_t>(c)]);
    gap = std::max(gap, std::sqrt(d2));
  }
  if (!(gap <= tolerance)) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", gap);
    throw Error(std::string("tube solid: the surface is not closed in u (S(0, v) and S(1, v) are up to ") + buf +
                " apart); expected a tube, u running around it");
  }
  auto cells = build(s, core);
  if (det_at_centre(cells.front().volume) < 0.0) cells = build(spline::reverse(s, 0), core);
  return cells;
}

}  // namespace trivox::construct
