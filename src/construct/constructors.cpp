#include "trivox/construct/constructors.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>

#include "trivox/error.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/fit.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::construct {

using spline::KnotVector;
using spline::TensorSpline;

namespace {

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

template <int P>
std::string at_params(const std::array<double, P>& t) {
  std::string s = "(";
  for (int d = 0; d < P; ++d) s += (d ? ", " : "") + num(t[static_cast<std::size_t>(d)]);
  return s + ")";
}

int geometry_coords(const MatchOptions& m, int dim) {
  return m.geometry_coords < 0 ? std::min(3, dim) : std::min(m.geometry_coords, dim);
}

double distance(const std::vector<double>& a, const std::vector<double>& b, int coords) {
  double s = 0.0;
  for (int c = 0; c < coords; ++c) {
    const double d = a[static_cast<std::size_t>(c)] - b[static_cast<std::size_t>(c)];
    s += d * d;
  }
  return std::sqrt(s);
}

template <int P>
void require_polynomial(const TensorSpline<P>& s, const std::string& what) {
  if (s.rational()) throw Error(what + " is rational; expected a polynomial (non-rational) spline");
}

template <int P>
void require_same_dim(std::span<const TensorSpline<P>> s, const std::string& what) {
  for (std::size_t i = 1; i < s.size(); ++i)
    if (s[i].dim() != s[0].dim())
      throw Error(what + " " + std::to_string(i) + " has " + std::to_string(s[i].dim()) + " coordinates, " + what +
                  " 0 has " + std::to_string(s[0].dim()) + "; expected equal coordinate counts");
}

/// The spline with every control point scaled by `f` (polynomial splines: the function scales).
template <int P>
TensorSpline<P> scaled(TensorSpline<P> s, double f) {
  for (double& x : s.points()) x *= f;
  return s;
}

/// (a + b) / 2 in their common space: the compromise between two boundaries that agree within
/// the tolerance (exactly one of them when they are equal).
template <int P>
TensorSpline<P> average(const TensorSpline<P>& a, const TensorSpline<P>& b) {
  if (a == b) return a;
  return scaled(spline::add(a, b, 1.0), 0.5);
}

/// The constant spline with value `p` on [0, 1]^P (order 2, all control points p).
template <int P>
TensorSpline<P> constant(const std::vector<double>& p) {
  std::array<KnotVector, P> kv;
  kv.fill(KnotVector::bezier(2));
  std::vector<double> pts;
  for (int i = 0; i < (1 << P); ++i) pts.insert(pts.end(), p.begin(), p.end());
  return TensorSpline<P>(std::move(kv), static_cast<int>(p.size()), std::move(pts));
}

/// The largest distance between two curves with the same domain [0, 1], over `samples`
/// parameters, and where it occurs.
std::pair<double, double> curve_gap(const Curve& a, const Curve& b, int coords, int samples = 33) {
  double worst = 0.0, where = 0.0;
  for (int i = 0; i < samples; ++i) {
    const double t = static_cast<double>(i) / (samples - 1);
    const double d = distance(a.eval({t}), b.eval({t}), coords);
    if (d > worst) worst = d, where = t;
  }
  return {worst, where};
}

void check_points_match(const std::vector<double>& a, const std::vector<double>& b, const MatchOptions& m,
                        const std::string& what_a, const std::string& what_b) {
  const int coords = geometry_coords(m, static_cast<int>(a.size()));
  const double d = distance(a, b, coords);
  if (!(d <= m.tolerance))
    throw Error(what_a + " and " + what_b + " are " + num(d) + " apart; expected them to coincide (within " +
                num(m.tolerance) + ")");
}

void check_curves_match(const Curve& a, const Curve& b, const MatchOptions& m, const std::string& what_a,
                        const std::string& what_b, const std::string& param) {
  const auto [gap, t] = curve_gap(a, b, geometry_coords(m, a.dim()));
  if (!(gap <= m.tolerance))
    throw Error(what_a + " and " + what_b + " differ by " + num(gap) + " (at " + param + " = " + num(t) +
                "); expected them to coincide (within " + num(m.tolerance) + ")");
}

/// Counts of a net with P directions, first fastest.
template <int P>
int flat(const std::array<int, P>& idx, const std::array<int, P>& counts) {
  int r = 0;
  for (int d = P - 1; d >= 0; --d) r = r * counts[static_cast<std::size_t>(d)] + idx[static_cast<std::size_t>(d)];
  return r;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Building blocks

template <int P>
TensorSpline<P> normalized(const TensorSpline<P>& s) {
  TensorSpline<P> r = spline::clamp(s);
  for (int d = 0; d < P; ++d) {
    const auto dom = r.domain(d);
    if (dom[0] != 0.0 || dom[1] != 1.0) r = spline::reparametrize(r, d, 0.0, 1.0);
  }
  return r;
}

template <int P>
std::vector<TensorSpline<P>> common_space(std::span<const TensorSpline<P>> splines) {
  std::vector<TensorSpline<P>> out;
  if (splines.empty()) return out;
  require_same_dim(splines, "spline");
  const bool any_rational = std::any_of(splines.begin(), splines.end(), [](const auto& s) { return s.rational(); });
  for (const auto& s : splines) {
    TensorSpline<P> n = normalized(s);
    if (any_rational && !n.rational())
      n = TensorSpline<P>(n.knot_vectors(), n.dim(), std::vector<double>(n.points().begin(), n.points().end()),
                          std::vector<double>(static_cast<std::size_t>(n.size()), 1.0));
    out.push_back(std::move(n));
  }
  // The common space grows by merging every spline into it; then each is brought there.
  TensorSpline<P> acc = out[0];
  for (std::size_t i = 1; i < out.size(); ++i) acc = spline::make_compatible(acc, out[i]).first;
  for (auto& s : out)
    for (int d = 0; d < P; ++d) s = spline::to_space(s, d, acc.knots(d));
  return out;
}

template <int P>
TensorSpline<P> stack(std::span<const TensorSpline<P - 1>> layers, int dir, const KnotVector& knots) {
  static_assert(P >= 2 && P <= 3);
  if (dir < 0 || dir >= P)
    throw Error("stack direction " + std::to_string(dir) + "; expected 0.." + std::to_string(P - 1));
  const int n = static_cast<int>(layers.size());
  if (n != knots.size())
    throw Error("stack of " + std::to_string(n) + " layers on a knot vector of " + std::to_string(knots.size()) +
                " functions; expected equal counts");
  const auto& first = layers[0];
  for (int i = 1; i < n; ++i) {
    const auto& l = layers[static_cast<std::size_t>(i)];
    if (l.knot_vectors() != first.knot_vectors() || l.dim() != first.dim() || l.rational() != first.rational())
      throw Error("stack layer " + std::to_string(i) + " is in another function space than layer 0; expected "
                  "layers brought to one space (common_space)");
  }
  std::array<KnotVector, P> kv;
  std::array<int, P> counts{};
  for (int d = 0, e = 0; d < P; ++d) {
    kv[static_cast<std::size_t>(d)] = d == dir ? knots : first.knots(e++);
    counts[static_cast<std::size_t>(d)] = kv[static_cast<std::size_t>(d)].size();
  }
  const int dim = first.dim();
  const int total = first.size() * n;
  std::vector<double> pts(static_cast<std::size_t>(total) * static_cast<std::size_t>(dim));
  std::vector<double> w(first.rational() ? static_cast<std::size_t>(total) : 0);
  const auto lcounts = first.counts();
  for (int r = 0; r < total; ++r) {
    std::array<int, P> idx{};
    for (int d = 0, q = r; d < P; ++d) {
      idx[static_cast<std::size_t>(d)] = q % counts[static_cast<std::size_t>(d)];
      q /= counts[static_cast<std::size_t>(d)];
    }
    std::array<int, P - 1> lidx{};
    for (int d = 0, e = 0; d < P; ++d)
      if (d != dir) lidx[static_cast<std::size_t>(e++)] = idx[static_cast<std::size_t>(d)];
    const auto& layer = layers[static_cast<std::size_t>(idx[static_cast<std::size_t>(dir)])];
    const int lr = flat<P - 1>(lidx, lcounts);
    const auto p = layer.point(lr);
    std::copy(p.begin(), p.end(), pts.begin() + static_cast<std::ptrdiff_t>(r) * dim);
    if (!w.empty()) w[static_cast<std::size_t>(r)] = layer.weights()[static_cast<std::size_t>(lr)];
  }
  return TensorSpline<P>(std::move(kv), dim, std::move(pts), std::move(w));
}

template <int P>
TensorSpline<P> extend_constant(const TensorSpline<P - 1>& s, int dir) {
  const TensorSpline<P - 1> layers[2] = {s, s};
  return stack<P>(layers, dir, KnotVector::bezier(2));
}

// ---------------------------------------------------------------------------------------------
// Extrusion and ruling

namespace {

template <int P>
TensorSpline<P + 1> ruled_impl(const TensorSpline<P>& a, const TensorSpline<P>& b, int ruling_order) {
  if (ruling_order < 2)
    throw Error("ruling order " + std::to_string(ruling_order) + "; expected an order >= 2");
  const TensorSpline<P> in[2] = {a, b};
  const auto cs = common_space<P>(in);
  TensorSpline<P + 1> r = stack<P + 1>(cs, P, KnotVector::bezier(2));
  if (ruling_order > 2) r = spline::elevate(r, P, ruling_order - 2);
  return r;
}

template <int P>
TensorSpline<P + 1> extrude_impl(const TensorSpline<P>& s, std::span<const double> vector) {
  const int dim = s.dim();
  if (vector.empty() || static_cast<int>(vector.size()) > dim)
    throw Error("extrusion vector of " + std::to_string(vector.size()) + " values; expected 1.." +
                std::to_string(dim) + " (the input's coordinates)");
  for (double v : vector)
    if (!std::isfinite(v)) throw Error("extrusion vector holds " + num(v) + "; expected finite values");
  TensorSpline<P> top = s;
  for (int i = 0; i < top.size(); ++i) {
    auto p = top.point(i);
    for (std::size_t c = 0; c < vector.size(); ++c) p[c] += vector[c];
  }
  return ruled_impl<P>(s, top, 2);
}

}  // namespace

Surface ruled(const Curve& bottom, const Curve& top, int ruling_order) {
  return ruled_impl<1>(bottom, top, ruling_order);
}
Trivariate ruled(const Surface& s0, const Surface& s1, int ruling_order) {
  return ruled_impl<2>(s0, s1, ruling_order);
}
Surface extrude(const Curve& c, std::span<const double> vector) { return extrude_impl<1>(c, vector); }
Trivariate extrude(const Surface& s, std::span<const double> vector) { return extrude_impl<2>(s, vector); }

// ---------------------------------------------------------------------------------------------
// Revolution

Curve circle_arc(double angle, double tolerance, int order) {
  constexpr double two_pi = 6.283185307179586;
  if (!(angle > 0.0 && angle <= two_pi))
    throw Error("revolution angle " + num(angle) + "; expected a value in (0, 2 pi]");
  if (!(tolerance > 0.0) || !std::isfinite(tolerance))
    throw Error("revolution tolerance " + num(tolerance) + "; expected a positive value");
  if (order < 3 || order > 12) throw Error("revolution order " + std::to_string(order) + "; expected 3..12");
  const auto exact = [&](double t, double* xy) {
    if (t >= 1.0 && angle == two_pi) {  // close the full circle exactly
      xy[0] = 1.0, xy[1] = 0.0;
      return;
    }
    xy[0] = std::cos(t * angle), xy[1] = std::sin(t * angle);
  };
  // Uniform segments, at least one per quarter turn; doubled until the interpolant at the
  // Greville abscissae (exact at both ends) is within half the tolerance on a dense sample.
  int segments = std::max(1, static_cast<int>(std::ceil(angle / (two_pi / 4) - 1e-12)));
  for (;;) {
    const KnotVector kv = KnotVector::uniform(order, segments);
    const std::vector<double> g = kv.greville();
    std::vector<double> values(2 * g.size());
    for (std::size_t i = 0; i < g.size(); ++i) exact(g[i], values.data() + 2 * i);
    Curve c = spline::interpolate_curve(g, 2, values, kv);
    // The ends are exact by construction (clamped interpolation); make them bit-exact.
    exact(0.0, c.point(0).data());
    exact(1.0, c.point(c.size() - 1).data());
    double err = 0.0;
    const int samples = 64 * segments;
    for (int i = 0; i <= samples; ++i) {
      const double t = static_cast<double>(i) / samples;
      double xy[2], p[2];
      exact(t, xy);
      c.eval({t}, p);
      err = std::max(err, std::hypot(p[0] - xy[0], p[1] - xy[1]));
    }
    if (err <= 0.5 * tolerance) return c;
    if (segments > 4096)
      throw Error("revolution tolerance " + num(tolerance) + " needs more than 4096 segments; expected a "
                  "tolerance above about 1e-13");
    segments *= 2;
  }
}

namespace {

template <int P>
TensorSpline<P + 1> revolve_impl(const TensorSpline<P>& in, const Revolution& r) {
  require_polynomial(in, "the profile of a revolution");
  if (in.dim() < 3)
    throw Error("the profile of a revolution has " + std::to_string(in.dim()) +
                " coordinates; expected at least 3 (xyz)");
  const double alen = std::sqrt(r.axis[0] * r.axis[0] + r.axis[1] * r.axis[1] + r.axis[2] * r.axis[2]);
  if (!(alen > 0.0) || !std::isfinite(alen)) throw Error("revolution axis has zero length; expected a non-zero vector");
  for (double o : r.origin)
    if (!std::isfinite(o)) throw Error("revolution origin holds " + num(o) + "; expected finite values");
  const std::array<double, 3> a{r.axis[0] / alen, r.axis[1] / alen, r.axis[2] / alen};
  if (!(r.relative_tolerance > 0.0))
    throw Error("revolution tolerance " + num(r.relative_tolerance) + "; expected a positive value");
  // |error| = |arc error| * distance from the axis, so the arc's tolerance is the relative one.
  const Curve arc = circle_arc(r.angle, r.relative_tolerance, r.order);
  const TensorSpline<P> s = normalized(in);
  // One layer per arc control point j: every profile control point rotated to (c_j, s_j).
  std::vector<TensorSpline<P>> layers;
  layers.reserve(static_cast<std::size_t>(arc.size()));
  for (int j = 0; j < arc.size(); ++j) {
    const double cj = arc.point(j)[0], sj = arc.point(j)[1];
    TensorSpline<P> layer = s;
    for (int i = 0; i < s.size(); ++i) {
      auto p = layer.point(i);
      const double d[3] = {p[0] - r.origin[0], p[1] - r.origin[1], p[2] - r.origin[2]};
      const double h = d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
      const double R[3] = {d[0] - h * a[0], d[1] - h * a[1], d[2] - h * a[2]};
      const double Q[3] = {a[1] * R[2] - a[2] * R[1], a[2] * R[0] - a[0] * R[2], a[0] * R[1] - a[1] * R[0]};
      for (int c = 0; c < 3; ++c) p[static_cast<std::size_t>(c)] = r.origin[static_cast<std::size_t>(c)] + h * a[static_cast<std::size_t>(c)] + cj * R[c] + sj * Q[c];
    }
    layers.push_back(std::move(layer));
  }
  return stack<P + 1>(layers, P, arc.knots(0));
}

}  // namespace

Surface revolve(const Curve& c, const Revolution& r) { return revolve_impl<1>(c, r); }
Trivariate revolve(const Surface& s, const Revolution& r) { return revolve_impl<2>(s, r); }

// ---------------------------------------------------------------------------------------------
// Boolean sums

Surface boolean_sum(const Curve& bottom_in, const Curve& top_in, const Curve& left_in, const Curve& right_in,
                    const MatchOptions& match) {
  const Curve all[4] = {bottom_in, top_in, left_in, right_in};
  require_same_dim<1>(all, "curve");
  for (int i = 0; i < 4; ++i) require_polynomial(all[i], "curve " + std::to_string(i));
  const Curve b = normalized(bottom_in), t = normalized(top_in), l = normalized(left_in), r = normalized(right_in);
  // Corners: S(0,0), S(1,0), S(0,1), S(1,1), each seen by two curves.
  const std::vector<double> c00b = b.eval({0.0}), c00l = l.eval({0.0});
  const std::vector<double> c10b = b.eval({1.0}), c10r = r.eval({0.0});
  const std::vector<double> c01t = t.eval({0.0}), c01l = l.eval({1.0});
  const std::vector<double> c11t = t.eval({1.0}), c11r = r.eval({1.0});
  check_points_match(c00b, c00l, match, "bottom(0)", "left(0)");
  check_points_match(c10b, c10r, match, "bottom(1)", "right(0)");
  check_points_match(c01t, c01l, match, "top(0)", "left(1)");
  check_points_match(c11t, c11r, match, "top(1)", "right(1)");
  const auto mid = [](const std::vector<double>& x, const std::vector<double>& y) {
    std::vector<double> m(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) m[i] = x[i] == y[i] ? x[i] : 0.5 * (x[i] + y[i]);
    return m;
  };
  const Surface along_v = ruled(b, t);  // (1 - v) bottom(u) + v top(u)
  const Curve lr[2] = {l, r};
  const auto lr_c = common_space<1>(lr);
  const Surface along_u = stack<2>(lr_c, 0, KnotVector::bezier(2));  // (1 - u) left(v) + u right(v)
  std::vector<double> corners;
  const std::vector<double> m00 = mid(c00b, c00l), m10 = mid(c10b, c10r), m01 = mid(c01t, c01l), m11 = mid(c11t, c11r);
  for (const auto* c : {&m00, &m10, &m01, &m11}) corners.insert(corners.end(), c->begin(), c->end());
  const Surface bilinear({KnotVector::bezier(2), KnotVector::bezier(2)}, b.dim(), corners);
  return spline::add(spline::add(along_v, along_u), bilinear, -1.0);
}

Trivariate boolean_sum(std::span<const Surface> faces_in, const MatchOptions& match) {
  if (faces_in.size() != 6)
    throw Error("volumetric Boolean sum of " + std::to_string(faces_in.size()) +
                " surfaces; expected six (u0 u1 v0 v1 w0 w1)");
  require_same_dim(faces_in, "surface");
  static const char* names[6] = {"u0", "u1", "v0", "v1", "w0", "w1"};
  std::vector<Surface> F;
  for (int i = 0; i < 6; ++i) {
    require_polynomial(faces_in[static_cast<std::size_t>(i)], std::string("face ") + names[i]);
    F.push_back(normalized(faces_in[static_cast<std::size_t>(i)]));
  }
  const auto face_name = [](int f) { return std::string("face ") + names[f]; };
  // The edge shared by faces f (direction df of its parameters fixed at value a) and g
  // (direction dg fixed at b), as one curve: the average of the two, after checking they agree.
  const auto edge = [&](int f, int df, double a, int g, int dg, double b, const char* param) {
    const Curve x = spline::iso(F[static_cast<std::size_t>(f)], df, a);
    const Curve y = spline::iso(F[static_cast<std::size_t>(g)], dg, b);
    check_curves_match(x, y, match, face_name(f), face_name(g), param);
    return average(x, y);
  };
  // Edges along w at (u = a, v = b): u-face (params v,w) at v = b; v-face (params u,w) at u = a.
  // Edges along v at (u = a, w = c): u-face at w = c; w-face (params u,v) at u = a.
  // Edges along u at (v = b, w = c): v-face at w = c; w-face at v = b.
  Curve Ew[2][2], Ev[2][2], Eu[2][2];
  for (int x = 0; x < 2; ++x)
    for (int y = 0; y < 2; ++y) {
      Ew[x][y] = edge(0 + x, 0, y, 2 + y, 0, x, "w");
      Ev[x][y] = edge(0 + x, 1, y, 4 + y, 0, x, "v");
      Eu[x][y] = edge(2 + x, 1, y, 4 + y, 1, x, "u");
    }
  const KnotVector lin = KnotVector::bezier(2);
  const auto pair_stack2 = [&](const Curve& c0, const Curve& c1, int dir) {
    const Curve in[2] = {c0, c1};
    return stack<2>(common_space<1>(in), dir, lin);
  };
  const auto pair_stack3 = [&](const Surface& s0, const Surface& s1, int dir) {
    const Surface in[2] = {s0, s1};
    return stack<3>(common_space<2>(in), dir, lin);
  };
  // Linear blends between opposite faces.
  const Trivariate Pu = pair_stack3(F[0], F[1], 0);
  const Trivariate Pv = pair_stack3(F[2], F[3], 1);
  const Trivariate Pw = pair_stack3(F[4], F[5], 2);
  // Bilinear blends of the four edges along each direction.
  const Trivariate Puv = pair_stack3(pair_stack2(Ew[0][0], Ew[0][1], 0), pair_stack2(Ew[1][0], Ew[1][1], 0), 0);
  const Trivariate Puw = pair_stack3(pair_stack2(Ev[0][0], Ev[0][1], 1), pair_stack2(Ev[1][0], Ev[1][1], 1), 0);
  const Trivariate Pvw = pair_stack3(pair_stack2(Eu[0][0], Eu[0][1], 1), pair_stack2(Eu[1][0], Eu[1][1], 1), 1);
  // Trilinear corner blend: corner (a, b, c) from the three edges meeting there, averaged.
  const int dim = F[0].dim();
  std::vector<double> corners;
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) {
        const auto p = Ew[a][b].eval({static_cast<double>(c)});
        const auto q = Ev[a][c].eval({static_cast<double>(b)});
        const auto s = Eu[b][c].eval({static_cast<double>(a)});
        for (int k = 0; k < dim; ++k) {
          const std::size_t kk = static_cast<std::size_t>(k);
          corners.push_back(p[kk] == q[kk] && q[kk] == s[kk] ? p[kk] : (p[kk] + q[kk] + s[kk]) / 3.0);
        }
      }
  const Trivariate Puvw({lin, lin, lin}, dim, corners);
  Trivariate T = spline::add(spline::add(Pu, Pv), Pw);
  T = spline::add(T, Puv, -1.0);
  T = spline::add(T, Puw, -1.0);
  T = spline::add(T, Pvw, -1.0);
  return spline::add(T, Puvw);
}

namespace {

/// The inputs of a constructor, checked (same coordinates, polynomial) and normalized().
template <int P>
std::vector<TensorSpline<P>> prepared(std::initializer_list<TensorSpline<P>> in, const char* what) {
  const std::vector<TensorSpline<P>> all(in);
  require_same_dim<P>(all, what);
  std::vector<TensorSpline<P>> out;
  for (std::size_t i = 0; i < all.size(); ++i) {
    require_polynomial(all[i], std::string(what) + " " + std::to_string(i));
    out.push_back(normalized(all[i]));
  }
  return out;
}

}  // namespace

Surface half_boolean_sum(const Curve& c1_in, const Curve& c2_in, const MatchOptions& match) {
  const auto in = prepared<1>({c1_in, c2_in}, "curve");
  const Curve &c1 = in[0], &c2 = in[1];
  const auto p1 = c1.eval({0.0}), p2 = c2.eval({0.0});
  check_points_match(p1, p2, match, "curve 0 at its start", "curve 1 at its start");
  std::vector<double> P(p1.size());
  for (std::size_t i = 0; i < P.size(); ++i) P[i] = p1[i] == p2[i] ? p1[i] : 0.5 * (p1[i] + p2[i]);
  // S(u, v) = c1(u) + c2(v) - P: Fadila et al. 2023, Sec. 3.1.
  return spline::add(spline::add(extend_constant<2>(c1, 1), extend_constant<2>(c2, 0)), constant<2>(P), -1.0);
}

Trivariate half_boolean_sum(const Surface& s1_in, const Surface& s2_in, const MatchOptions& match) {
  const auto in = prepared<2>({s1_in, s2_in}, "surface");
  const Surface &s1 = in[0], &s2 = in[1];
  const Curve a = spline::iso(s1, 1, 0.0), b = spline::iso(s2, 1, 0.0);
  check_curves_match(a, b, match, "surface 0 at v = 0", "surface 1 at w = 0", "u");
  const Curve C = average(a, b);
  // T(u, v, w) = s1(u, v) + s2(u, w) - C(u): Fadila et al. 2023, Sec. 3.2, Lemma 2.
  Trivariate T = spline::add(extend_constant<3>(s1, 2), extend_constant<3>(s2, 1));
  return spline::add(T, extend_constant<3>(extend_constant<2>(C, 1), 2), -1.0);
}

Trivariate half_boolean_sum(const Surface& s1_in, const Surface& s2_in, const Surface& s3_in,
                            const MatchOptions& match) {
  const auto in = prepared<2>({s1_in, s2_in, s3_in}, "surface");
  const Surface &s1 = in[0], &s2 = in[1], &s3 = in[2];
  // C1(u) = s1(u, 0) = s3(u, 0); C2(v) = s1(0, v) = s2(v, 0); C3(w) = s2(0, w) = s3(0, w).
  const Curve a1 = spline::iso(s1, 1, 0.0), b1 = spline::iso(s3, 1, 0.0);
  const Curve a2 = spline::iso(s1, 0, 0.0), b2 = spline::iso(s2, 1, 0.0);
  const Curve a3 = spline::iso(s2, 0, 0.0), b3 = spline::iso(s3, 0, 0.0);
  check_curves_match(a1, b1, match, "surface 0 at v = 0", "surface 2 at w = 0", "u");
  check_curves_match(a2, b2, match, "surface 0 at u = 0", "surface 1 at w = 0", "v");
  check_curves_match(a3, b3, match, "surface 1 at v = 0", "surface 2 at u = 0", "w");
  const Curve C1 = average(a1, b1), C2 = average(a2, b2), C3 = average(a3, b3);
  const auto p1 = C1.eval({0.0}), p2 = C2.eval({0.0}), p3 = C3.eval({0.0});
  std::vector<double> P(p1.size());
  for (std::size_t i = 0; i < P.size(); ++i)
    P[i] = p1[i] == p2[i] && p2[i] == p3[i] ? p1[i] : (p1[i] + p2[i] + p3[i]) / 3.0;
  // T = s1(u,v) + s2(v,w) + s3(u,w) - (C1(u) + C2(v) + C3(w)) + P: Fadila et
  // al. 2023, Sec. 3.2, Lemma 3.
  Trivariate T = spline::add(extend_constant<3>(s1, 2), extend_constant<3>(s2, 0));
  T = spline::add(T, extend_constant<3>(s3, 1));
  T = spline::add(T, extend_constant<3>(extend_constant<2>(C1, 1), 2), -1.0);
  T = spline::add(T, extend_constant<3>(extend_constant<2>(C2, 0), 2), -1.0);
  T = spline::add(T, extend_constant<3>(extend_constant<2>(C3, 0), 1), -1.0);
  return spline::add(T, constant<3>(P));
}

// ---------------------------------------------------------------------------------------------
// Sweep

namespace {

/// sweep_params for sections already in their common space (`cs`, empty until needed).
template <int P>
std::vector<double> params_of(std::span<const TensorSpline<P - 1>> sections_in, std::span<const double> params,
                              std::vector<TensorSpline<P - 1>>& cs) {
  const std::size_t n = sections_in.size();
  if (n < 2) throw Error("sweep through " + std::to_string(n) + " section(s); expected at least 2");
  if (!params.empty()) {
    if (params.size() != n)
      throw Error("sweep with " + std::to_string(params.size()) + " parameters for " + std::to_string(n) +
                  " sections; expected one parameter per section");
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(params[i])) throw Error("sweep parameter " + std::to_string(i) + " is not finite");
      if (i > 0 && !(params[i] > params[i - 1]))
        throw Error("sweep parameter " + std::to_string(i) + " = " + num(params[i]) + " does not exceed parameter " +
                    std::to_string(i - 1) + " = " + num(params[i - 1]) + "; expected strictly increasing values");
    }
    std::vector<double> t(params.begin(), params.end());
    const double a = t.front(), b = t.back();
    for (double& x : t) x = (x - a) / (b - a);
    t.back() = 1.0;
    return t;
  }
  // Chord length between consecutive sections: the root mean square distance of their control
  // points in the common space (NURBS Book eq. 9.5, averaged over the net as in Sec. 9.2.5).
  if (cs.empty()) cs = common_space<P - 1>(sections_in);
  const int coords = std::min(3, cs[0].dim());
  std::vector<double> t(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) {
    double s = 0.0;
    for (int r = 0; r < cs[i].size(); ++r)
      for (int c = 0; c < coords; ++c) {
        const double d = cs[i].point(r)[static_cast<std::size_t>(c)] - cs[i - 1].point(r)[static_cast<std::size_t>(c)];
        s += d * d;
      }
    const double step = std::sqrt(s / cs[i].size());
    if (!(step > 0.0))
      throw Error("sweep sections " + std::to_string(i - 1) + " and " + std::to_string(i) +
                  " coincide; expected distinct sections (or explicit parameters)");
    t[i] = t[i - 1] + step;
  }
  const double total = t.back();
  for (double& x : t) x /= total;
  t.back() = 1.0;
  return t;
}

}  // namespace

template <int P>
std::vector<double> sweep_params(std::span<const TensorSpline<P - 1>> sections, std::span<const double> params) {
  std::vector<TensorSpline<P - 1>> cs;
  return params_of<P>(sections, params, cs);
}

namespace {

template <int P>
TensorSpline<P> sweep_impl(std::span<const TensorSpline<P - 1>> sections, std::span<const double> params_in,
                           int order) {
  for (std::size_t i = 0; i < sections.size(); ++i)
    require_polynomial(sections[i], "sweep section " + std::to_string(i));
  std::vector<TensorSpline<P - 1>> cs;
  const std::vector<double> t = params_of<P>(sections, params_in, cs);
  if (order < 1) throw Error("sweep order " + std::to_string(order) + "; expected >= 1");
  if (cs.empty()) cs = common_space<P - 1>(sections);
  const int n = static_cast<int>(cs.size());
  const int k = std::min(order, n);
  // Interpolating every control point's sequence at once: one curve in R^(size * dim), linear in
  // the data, so T(.., t_i) = S_i exactly (up to rounding).
  const int width = cs[0].size() * cs[0].dim();
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(n) * static_cast<std::size_t>(width));
  for (const auto& s : cs) values.insert(values.end(), s.points().begin(), s.points().end());
  const Curve c = spline::interpolate_curve(t, width, values, k);
  std::vector<TensorSpline<P - 1>> layers;
  for (int j = 0; j < c.size(); ++j) {
    TensorSpline<P - 1> l = cs[0];
    const auto p = c.point(j);
    std::copy(p.begin(), p.end(), l.points().begin());
    layers.push_back(std::move(l));
  }
  return stack<P>(layers, P - 1, c.knots(0));
}

}  // namespace

Surface sweep(std::span<const Curve> sections, std::span<const double> params, int order) {
  return sweep_impl<2>(sections, params, order);
}
Trivariate sweep(std::span<const Surface> sections, std::span<const double> params, int order) {
  return sweep_impl<3>(sections, params, order);
}

// ---------------------------------------------------------------------------------------------

template TensorSpline<1> normalized(const TensorSpline<1>&);
template TensorSpline<2> normalized(const TensorSpline<2>&);
template TensorSpline<3> normalized(const TensorSpline<3>&);
template std::vector<TensorSpline<1>> common_space(std::span<const TensorSpline<1>>);
template std::vector<TensorSpline<2>> common_space(std::span<const TensorSpline<2>>);
template std::vector<TensorSpline<3>> common_space(std::span<const TensorSpline<3>>);
template TensorSpline<2> stack(std::span<const TensorSpline<1>>, int, const KnotVector&);
template TensorSpline<3> stack(std::span<const TensorSpline<2>>, int, const KnotVector&);
template TensorSpline<2> extend_constant(const TensorSpline<1>&, int);
template TensorSpline<3> extend_constant(const TensorSpline<2>&, int);
template std::vector<double> sweep_params<2>(std::span<const TensorSpline<1>>, std::span<const double>);
template std::vector<double> sweep_params<3>(std::span<const TensorSpline<2>>, std::span<const double>);

}  // namespace trivox::construct
