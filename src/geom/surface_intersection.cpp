#include "trivox/geom/surface_intersection.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "trivox/error.hpp"
#include "trivox/spline/fit.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::geom {

namespace {

using spline::Surface;
using V3 = Eigen::Vector3d;

struct Frame {
  V3 x, du, dv;
};

Frame frame(const Surface& s, const std::array<double, 2>& t, std::vector<double>& buf) {
  buf.resize(static_cast<std::size_t>(3 * s.dim()));
  s.eval_derivatives(t, 1, buf.data());
  const double* b = buf.data();
  const int k = s.dim();
  return {V3(b[0], b[1], b[2]), V3(b[k], b[k + 1], b[k + 2]), V3(b[2 * k], b[2 * k + 1], b[2 * k + 2])};
}

struct Box2 {
  std::array<double, 2> lo, hi;
};

Box2 domain_of(const Surface& s) { return {{s.domain(0)[0], s.domain(1)[0]}, {s.domain(0)[1], s.domain(1)[1]}}; }

/// The extra equation of a Newton solve besides S_1 = S_2: none (minimum-norm steps), a plane
/// (X - q) . n = 0, or one parameter held at a value (0..3: u1, v1, u2, v2).
struct Constraint {
  enum Kind { none, plane, parameter } kind = none;
  V3 q{0, 0, 0}, n{0, 0, 0};
  int index = 0;
  double value = 0.0;
};

class Solver {
public:
  Solver(const Surface& a, const Surface& b, double tol) : a_(a), b_(b), da_(domain_of(a)), db_(domain_of(b)), tol_(tol) {}

  /// Newton from p (parameters clamped to the domains); true when |S_1 - S_2| < tol and the
  /// constraint holds to tol.
  bool solve(IntersectionPoint& p, const Constraint& c, int max_iter = 25) const {
    std::array<double, 4> t{p.uv1[0], p.uv1[1], p.uv2[0], p.uv2[1]};
    clamp(t);
    for (int it = 0; it < max_iter; ++it) {
      const Frame f1 = frame(a_, {t[0], t[1]}, buf1_), f2 = frame(b_, {t[2], t[3]}, buf2_);
      const V3 F = f1.x - f2.x;
      double g = 0.0;
      if (c.kind == Constraint::plane) g = (f1.x - c.q).dot(c.n);
      if (c.kind == Constraint::parameter) g = t[static_cast<std::size_t>(c.index)] - c.value;
      if (F.norm() < tol_ && std::abs(g) < tol_) {
        p.uv1 = {t[0], t[1]};
        p.uv2 = {t[2], t[3]};
        p.xyz = {0.5 * (f1.x[0] + f2.x[0]), 0.5 * (f1.x[1] + f2.x[1]), 0.5 * (f1.x[2] + f2.x[2])};
        return true;
      }
      Eigen::Matrix<double, 3, 4> J;
      J.col(0) = f1.du;
      J.col(1) = f1.dv;
      J.col(2) = -f2.du;
      J.col(3) = -f2.dv;
      Eigen::Vector4d step;
      if (c.kind == Constraint::none) {
        const Eigen::Matrix3d JJ = J * J.transpose();
        const Eigen::Vector3d y = JJ.ldlt().solve(-F);
        step = J.transpose() * y;
      } else {
        Eigen::Matrix4d A;
        A.topRows<3>() = J;
        Eigen::Vector4d r;
        r.head<3>() = -F;
        if (c.kind == Constraint::plane) {
          A.row(3) << c.n.dot(f1.du), c.n.dot(f1.dv), 0.0, 0.0;
        } else {
          A.row(3).setZero();
          A(3, c.index) = 1.0;
        }
        r(3) = -g;
        step = A.fullPivLu().solve(r);
      }
      if (!step.allFinite()) return false;
      for (std::size_t k = 0; k < 4; ++k) t[k] += step(static_cast<Eigen::Index>(k));
      clamp(t);
    }
    return false;
  }

  /// Unit tangent n_1 x n_2 at p (zero where the surfaces touch tangentially), and the rate of
  /// change of the four parameters along it.
  bool tangent(const IntersectionPoint& p, V3& T, Eigen::Vector4d& dt) const {
    const Frame f1 = frame(a_, p.uv1, buf1_), f2 = frame(b_, p.uv2, buf2_);
    const V3 n1 = f1.du.cross(f1.dv), n2 = f2.du.cross(f2.dv);
    const V3 c = n1.cross(n2);
    const double scale = n1.norm() * n2.norm();
    if (!(scale > 0) || c.norm() < 1e-9 * scale) return false;
    T = c.normalized();
    Eigen::Matrix<double, 3, 2> A1, A2;
    A1 << f1.du, f1.dv;
    A2 << f2.du, f2.dv;
    dt.head<2>() = A1.colPivHouseholderQr().solve(T);
    dt.tail<2>() = A2.colPivHouseholderQr().solve(T);
    return dt.allFinite();
  }

  bool inside(const std::array<double, 4>& t) const {
    for (std::size_t k = 0; k < 4; ++k) {
      const Box2& d = k < 2 ? da_ : db_;
      if (t[k] < d.lo[k & 1] || t[k] > d.hi[k & 1]) return false;
    }
    return true;
  }

  void clamp(std::array<double, 4>& t) const {
    for (std::size_t k = 0; k < 4; ++k) {
      const Box2& d = k < 2 ? da_ : db_;
      t[k] = std::clamp(t[k], d.lo[k & 1], d.hi[k & 1]);
    }
  }

private:
  const Surface& a_;
  const Surface& b_;
  Box2 da_, db_;
  double tol_;
  mutable std::vector<double> buf1_, buf2_;
};

std::array<double, 6> control_box(const Surface& s) {
  std::array<double, 6> b{1e300, 1e300, 1e300, -1e300, -1e300, -1e300};
  for (int i = 0; i < s.size(); ++i)
    for (std::size_t d = 0; d < 3; ++d) {
      b[d] = std::min(b[d], s.point(i)[d]);
      b[d + 3] = std::max(b[d + 3], s.point(i)[d]);
    }
  return b;
}

double diag(const std::array<double, 6>& b) { return std::hypot(b[3] - b[0], b[4] - b[1], b[5] - b[2]); }

bool overlap(const std::array<double, 6>& a, const std::array<double, 6>& b, double pad) {
  for (std::size_t d = 0; d < 3; ++d)
    if (a[d] > b[d + 3] + pad || b[d] > a[d + 3] + pad) return false;
  return true;
}

/// A Bezier patch as the seed search needs it: its control net in homogeneous xyz (w x, w y,
/// w z, w; w = 1 when polynomial), point (i, j) at 4 (i + n0 j), its parameter box, and the box
/// of its control points. Halving it is de Casteljau's step at the middle, one allocation per
/// half, where a spline::split of a TensorSpline builds knot vectors and refinement matrices:
/// the subdivision makes thousands of halves per pair of faces.
struct Patch {
  int n0 = 0, n1 = 0;
  std::vector<double> net;
  std::array<double, 4> dom{};  // u0, u1, v0, v1
  std::array<double, 6> box{};

  const double* at(int i, int j) const { return net.data() + 4 * (static_cast<std::size_t>(i) + static_cast<std::size_t>(n0) * static_cast<std::size_t>(j)); }
  double* at(int i, int j) { return net.data() + 4 * (static_cast<std::size_t>(i) + static_cast<std::size_t>(n0) * static_cast<std::size_t>(j)); }

  void bound() {
    box = {1e300, 1e300, 1e300, -1e300, -1e300, -1e300};
    for (std::size_t k = 0; k < net.size(); k += 4)
      for (std::size_t d = 0; d < 3; ++d) {
        const double x = net[k + d] / net[k + 3];
        box[d] = std::min(box[d], x);
        box[d + 3] = std::max(box[d + 3], x);
      }
  }
};

/// The patch of a Bezier piece (spline::bezier_pieces) of a surface.
Patch to_patch(const Surface& s) {
  Patch p;
  const auto n = s.counts();
  p.n0 = n[0];
  p.n1 = n[1];
  p.net.resize(4 * static_cast<std::size_t>(n[0]) * static_cast<std::size_t>(n[1]));
  for (int j = 0; j < n[1]; ++j)
    for (int i = 0; i < n[0]; ++i) {
      const int r = s.row({i, j});
      const double w = s.rational() ? s.weights()[static_cast<std::size_t>(r)] : 1.0;
      const auto x = s.point(r);
      double* q = p.at(i, j);
      q[0] = w * x[0];
      q[1] = w * x[1];
      q[2] = w * x[2];
      q[3] = w;
    }
  const auto du = s.domain(0), dv = s.domain(1);
  p.dom = {du[0], du[1], dv[0], dv[1]};
  p.bound();
  return p;
}

/// Splits a Bezier patch at the middle of the parameter direction along which its control net
/// is longer (de Casteljau at 1/2: exact, as the refinement of its knots would be).
std::pair<Patch, Patch> halve(const Patch& s) {
  double len[2] = {0.0, 0.0};
  const auto pt = [&](int i, int j, std::size_t d) { return s.at(i, j)[d] / s.at(i, j)[3]; };
  for (int j = 0; j < s.n1; ++j)
    for (int i = 0; i + 1 < s.n0; ++i)
      len[0] += std::hypot(pt(i, j, 0) - pt(i + 1, j, 0), pt(i, j, 1) - pt(i + 1, j, 1), pt(i, j, 2) - pt(i + 1, j, 2));
  for (int j = 0; j + 1 < s.n1; ++j)
    for (int i = 0; i < s.n0; ++i)
      len[1] += std::hypot(pt(i, j, 0) - pt(i, j + 1, 0), pt(i, j, 1) - pt(i, j + 1, 1), pt(i, j, 2) - pt(i, j + 1, 2));
  const int d = len[0] / s.n1 >= len[1] / s.n0 ? 0 : 1;
  std::pair<Patch, Patch> out{s, s};
  Patch& l = out.first;
  Patch& r = out.second;
  const int n = d == 0 ? s.n0 : s.n1, lines = d == 0 ? s.n1 : s.n0;
  std::vector<double> tri(4 * static_cast<std::size_t>(n));
  for (int line = 0; line < lines; ++line) {
    const auto src = [&](int k) { return d == 0 ? s.at(k, line) : s.at(line, k); };
    const auto dst = [&](Patch& p, int k) { return d == 0 ? p.at(k, line) : p.at(line, k); };
    for (int k = 0; k < n; ++k) std::copy_n(src(k), 4, tri.data() + 4 * static_cast<std::size_t>(k));
    // Level m of the triangle: the left half takes its first point, the right half its last.
    for (int m = 0; m < n; ++m) {
      std::copy_n(tri.data(), 4, dst(l, m));
      std::copy_n(tri.data() + 4 * static_cast<std::size_t>(n - 1 - m), 4, dst(r, n - 1 - m));
      for (int k = 0; k + 1 < n - m; ++k)
        for (std::size_t c = 0; c < 4; ++c) {
          const std::size_t a = 4 * static_cast<std::size_t>(k) + c;
          tri[a] = 0.5 * (tri[a] + tri[a + 4]);
        }
    }
  }
  const double mid = 0.5 * (s.dom[2 * d] + s.dom[2 * d + 1]);
  l.dom[2 * d + 1] = mid;
  r.dom[2 * d] = mid;
  l.bound();
  r.bound();
  return out;
}

void find_seeds(const Patch& p1, const Patch& p2, double small, double pad, const Solver& solver, int depth,
                std::vector<IntersectionPoint>& seeds) {
  if (!overlap(p1.box, p2.box, pad)) return;
  const double d1 = diag(p1.box), d2 = diag(p2.box);
  if ((d1 <= small && d2 <= small) || depth >= 24) {
    IntersectionPoint p;
    p.uv1 = {0.5 * (p1.dom[0] + p1.dom[1]), 0.5 * (p1.dom[2] + p1.dom[3])};
    p.uv2 = {0.5 * (p2.dom[0] + p2.dom[1]), 0.5 * (p2.dom[2] + p2.dom[3])};
    if (solver.solve(p, {})) seeds.push_back(p);
    return;
  }
  if (d1 >= d2) {
    const auto [l, r] = halve(p1);
    find_seeds(l, p2, small, pad, solver, depth + 1, seeds);
    find_seeds(r, p2, small, pad, solver, depth + 1, seeds);
  } else {
    const auto [l, r] = halve(p2);
    find_seeds(p1, l, small, pad, solver, depth + 1, seeds);
    find_seeds(p1, r, small, pad, solver, depth + 1, seeds);
  }
}

double dist(const IntersectionPoint& a, const IntersectionPoint& b) {
  return std::hypot(a.xyz[0] - b.xyz[0], a.xyz[1] - b.xyz[1], a.xyz[2] - b.xyz[2]);
}

/// Distance from point x to the polyline of `pts`.
double polyline_distance(const std::vector<IntersectionPoint>& pts, const std::array<double, 3>& x) {
  double best = 1e300;
  const V3 p(x[0], x[1], x[2]);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const V3 a(pts[i].xyz[0], pts[i].xyz[1], pts[i].xyz[2]);
    best = std::min(best, (p - a).norm());
    if (i + 1 == pts.size()) break;
    const V3 b(pts[i + 1].xyz[0], pts[i + 1].xyz[1], pts[i + 1].xyz[2]);
    const V3 ab = b - a;
    const double L = ab.squaredNorm();
    if (L == 0) continue;
    const double s = std::clamp((p - a).dot(ab) / L, 0.0, 1.0);
    best = std::min(best, (p - (a + s * ab)).norm());
  }
  return best;
}

/// The signed gap, along the unit normal n at p, between surface a at the point of its tangent
/// plane offset by `offset` from p (mapped to a's parameters by its first derivatives) and
/// surface b; nullopt where either point falls outside its parameter rectangle or the solve for
/// b's point on a's normal line does not converge.
std::optional<double> normal_gap(const Surface& a, const Surface& b, const IntersectionPoint& p, const V3& n,
                                 const V3& offset, double tol, std::vector<double>& buf) {
  const Frame f1 = frame(a, p.uv1, buf);
  Eigen::Matrix<double, 3, 2> A1;
  A1 << f1.du, f1.dv;
  const Eigen::Vector2d d1 = A1.colPivHouseholderQr().solve(offset);
  const std::array<double, 2> uv1{p.uv1[0] + d1(0), p.uv1[1] + d1(1)};
  const Box2 da = domain_of(a), db = domain_of(b);
  for (std::size_t k = 0; k < 2; ++k)
    if (!(uv1[k] >= da.lo[k] && uv1[k] <= da.hi[k])) return std::nullopt;
  const Frame x1 = frame(a, uv1, buf);
  // b(s, t) = X + g n: three equations in s, t, g.
  std::array<double, 2> uv2 = p.uv2;
  {
    const Frame f2 = frame(b, uv2, buf);
    Eigen::Matrix<double, 3, 2> A2;
    A2 << f2.du, f2.dv;
    const Eigen::Vector2d d2 = A2.colPivHouseholderQr().solve(x1.x - f2.x);
    uv2 = {uv2[0] + d2(0), uv2[1] + d2(1)};
  }
  double g = 0.0;
  for (int it = 0; it < 30; ++it) {
    for (std::size_t k = 0; k < 2; ++k)
      if (!(uv2[k] >= db.lo[k] && uv2[k] <= db.hi[k])) return std::nullopt;
    const Frame f2 = frame(b, uv2, buf);
    const V3 F = f2.x - x1.x - g * n;
    if (F.norm() < 0.1 * tol) return g;
    Eigen::Matrix3d J;
    J << f2.du, f2.dv, -n;
    const Eigen::Vector3d step = J.fullPivLu().solve(-F);
    if (!step.allFinite()) return std::nullopt;
    uv2 = {uv2[0] + step(0), uv2[1] + step(1)};
    g += step(2);
  }
  return std::nullopt;
}

/// What surfaces a and b do around p, a point of both where their normals are (nearly) parallel:
/// the normal gap between them at distance r from p in 16 directions of a's tangent plane (those
/// inside both parameter rectangles) is fitted by g = r (D c + E s) + r^2 / 2 (A c^2 + 2 B c s +
/// C s^2), c and s the direction's cosine and sine: the first-order term is the angle between the
/// surfaces, the quadratic form the difference of their second fundamental forms along the
/// common normal, whose rank tells the kind of contact (Patrikalakis & Maekawa 2002, Ch. 6,
/// tangential intersection curves). All gaps within 10 tol: the surfaces coincide around p
/// (region). A first-order term above a tenth of the largest gap: they cross at an angle (no
/// contact). The form indefinite: they cross along two curves through p (no contact). Otherwise
/// the form's smaller eigenvalue decides: within 1e-3 of the larger one (plus 10 tol in gap), the
/// surfaces touch along a curve through p, whose direction the gap grows in as r^4 only (curve);
/// else at p alone (point). nullopt also where fewer than 5 directions could be probed.
std::optional<IntersectionContact::Kind> classify_contact(const Surface& a, const Surface& b, const IntersectionPoint& p,
                                                          double r, double tol) {
  std::vector<double> buf;
  const Frame f1 = frame(a, p.uv1, buf);
  const V3 n = f1.du.cross(f1.dv).normalized(), e1 = f1.du.normalized(), e2 = n.cross(e1);
  if (!n.allFinite() || !e1.allFinite()) return std::nullopt;
  Eigen::Matrix<double, 5, 5> N = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 1> rhs = Eigen::Matrix<double, 5, 1>::Zero();
  double largest = 0.0;
  int valid = 0;
  for (int k = 0; k < 16; ++k) {
    const double th = k * M_PI / 8, c = std::cos(th), s = std::sin(th);
    const auto g = normal_gap(a, b, p, n, r * (c * e1 + s * e2), tol, buf);
    if (!g) continue;
    ++valid;
    largest = std::max(largest, std::abs(*g));
    // Unknowns scaled to gaps: D r, E r, A r^2 / 2, B r^2, C r^2 / 2.
    Eigen::Matrix<double, 5, 1> row;
    row << c, s, c * c, c * s, s * s;
    N += row * row.transpose();
    rhs += row * *g;
  }
  if (valid < 5) return std::nullopt;
  if (largest <= 10 * tol) return IntersectionContact::Kind::region;
  const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, 5, 5>> qr(N);
  if (qr.rank() < 5) return std::nullopt;
  const Eigen::Matrix<double, 5, 1> q = qr.solve(rhs);
  if (std::hypot(q(0), q(1)) > 0.1 * largest) return std::nullopt;  // crossing at an angle
  Eigen::Matrix2d form;  // in gap units: g = v^T form v for unit directions v
  form << q(2), 0.5 * q(3), 0.5 * q(3), q(4);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(form);
  const Eigen::Vector2d lam = eig.eigenvalues();
  const int null = std::abs(lam(0)) <= std::abs(lam(1)) ? 0 : 1;
  const double small = std::abs(lam(null)), big = std::abs(lam(1 - null));
  const double threshold = 1e-3 * big + 10 * tol;
  if (small <= threshold) return IntersectionContact::Kind::curve;
  if (lam(0) * lam(1) < 0) return std::nullopt;  // crossing along two curves
  return IntersectionContact::Kind::point;
}

/// The largest sine of the angle between the surfaces' normals over c's points: small (about
/// sqrt(tol x curvature)) on a curve traced along a tangential contact, whose points lie within
/// the tolerance of both surfaces only near the contact.
double largest_normal_angle(const Surface& a, const Surface& b, const IntersectionCurve& c) {
  std::vector<double> buf1, buf2;
  double best = 0.0;
  for (const auto& p : c.points) {
    const Frame f1 = frame(a, p.uv1, buf1), f2 = frame(b, p.uv2, buf2);
    const V3 n1 = f1.du.cross(f1.dv), n2 = f2.du.cross(f2.dv);
    const double scale = n1.norm() * n2.norm();
    if (!(scale > 0)) continue;
    best = std::max(best, n1.cross(n2).norm() / scale);
  }
  return best;
}

/// One branch from `start` in direction `sign`. Returns the points after start; `closed` when
/// the branch came back to start.
std::vector<IntersectionPoint> march(const Solver& solver, const IntersectionPoint& start, double sign, double hmax,
                                     double tol, bool& closed) {
  std::vector<IntersectionPoint> out;
  closed = false;
  IntersectionPoint cur = start;
  double h = hmax;
  V3 T;
  Eigen::Vector4d dt;
  if (!solver.tangent(cur, T, dt)) return out;
  T *= sign;
  dt *= sign;
  const double hmin = std::max(10 * tol, hmax * 1e-6);
  double travelled = 0.0;
  for (int steps = 0; steps < 200000; ++steps) {
    const std::array<double, 4> t0{cur.uv1[0], cur.uv1[1], cur.uv2[0], cur.uv2[1]};
    std::array<double, 4> pred;
    for (std::size_t k = 0; k < 4; ++k) pred[k] = t0[k] + h * dt(static_cast<Eigen::Index>(k));
    IntersectionPoint next;
    bool ok = false;
    bool ends = false;
    if (!solver.inside(pred)) {
      // The step leaves a parameter rectangle: solve for the point on that boundary, between here
      // and the prediction, with the leaving parameter held there.
      int idx = -1;
      double frac = 2.0, value = 0.0;
      std::array<double, 4> clamped = pred;
      solver.clamp(clamped);
      for (std::size_t k = 0; k < 4; ++k)
        if (clamped[k] != pred[k]) {
          const double f = (clamped[k] - t0[k]) / (pred[k] - t0[k]);
          if (f < frac) frac = f, idx = static_cast<int>(k), value = clamped[k];
        }
      next.uv1 = {t0[0] + frac * h * dt(0), t0[1] + frac * h * dt(1)};
      next.uv2 = {t0[2] + frac * h * dt(2), t0[3] + frac * h * dt(3)};
      Constraint c;
      c.kind = Constraint::parameter;
      c.index = idx;
      c.value = value;
      ok = solver.solve(next, c) && dist(next, cur) < 2.5 * h;
      ends = ok;
    } else {
      next.uv1 = {pred[0], pred[1]};
      next.uv2 = {pred[2], pred[3]};
      Constraint c;
      c.kind = Constraint::plane;
      c.n = T;
      c.q = V3(cur.xyz[0], cur.xyz[1], cur.xyz[2]) + h * T;
      ok = solver.solve(next, c) && dist(next, cur) < 2.5 * h;
    }
    V3 Tn;
    Eigen::Vector4d dtn;
    if (ok && !ends) {
      ok = solver.tangent(next, Tn, dtn);
      if (ok) {
        if (Tn.dot(T) < 0) Tn = -Tn, dtn = -dtn;
        ok = Tn.dot(T) > std::cos(10.0 * M_PI / 180.0);
      }
    }
    if (!ok) {
      h *= 0.5;
      if (h < hmin) return out;  // cannot continue (a tangential contact or a singular point)
      continue;
    }
    // Back at the start, in xyz and in both parameter spaces (a curve that reaches a periodic
    // surface's seam is near its start in xyz only, and goes on to the boundary): closed.
    travelled += dist(next, cur);
    double dpar = 0.0, step_par = 0.0;
    for (std::size_t k = 0; k < 2; ++k) {
      dpar = std::max({dpar, std::abs(next.uv1[k] - start.uv1[k]), std::abs(next.uv2[k] - start.uv2[k])});
      step_par = std::max({step_par, std::abs(next.uv1[k] - cur.uv1[k]), std::abs(next.uv2[k] - cur.uv2[k])});
    }
    if (out.size() >= 3 && travelled > 3 * hmax && dist(next, start) < 1.5 * h && dpar <= 2 * step_par) {
      closed = true;
      return out;
    }
    out.push_back(next);
    if (ends) return out;
    cur = next;
    T = Tn;
    dt = dtn;
    h = std::min(hmax, h * 1.5);
  }
  return out;
}

/// Drops points closer than 10 tolerances to the one kept before them (a boundary end right
/// after a step would repeat a chord-length parameter), keeping the last point of an open
/// branch, and a closed branch's last point where it repeats the first. A closed branch left with
/// fewer than 3 points is no loop: open. Returns the number of points left; fewer than 2 means
/// the branch is a single point (its points all lie within 10 tolerances of one another).
std::size_t drop_repeated(IntersectionCurve& c, double tol) {
  std::vector<IntersectionPoint> pts;
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    if (!pts.empty() && dist(pts.back(), c.points[i]) <= 10 * tol) {
      if (i + 1 == c.points.size() && pts.size() > 1) pts.back() = c.points[i];
      continue;
    }
    pts.push_back(c.points[i]);
  }
  if (c.closed && pts.size() > 2 && dist(pts.back(), pts.front()) <= 10 * tol) pts.pop_back();
  if (pts.size() < 3) c.closed = false;
  c.points = std::move(pts);
  return c.points.size();
}

/// The chord-length parameters of c's points (the first point repeated at the end of a closed
/// branch); c has at least 2 distinct consecutive points (drop_repeated).
std::vector<double> chord_params(const IntersectionCurve& c) {
  std::vector<double> v;
  for (const auto& p : c.points) v.insert(v.end(), p.xyz.begin(), p.xyz.end());
  if (c.closed) v.insert(v.end(), c.points.front().xyz.begin(), c.points.front().xyz.end());
  return spline::chord_length_params(v, 3);
}

/// Cubic interpolation of the points (chord length), closing the loop for closed curves.
/// False (and no curves) when the branch is a single point.
bool fit_curves(IntersectionCurve& c, double tol) {
  if (drop_repeated(c, tol) < 2) {
    c.xyz = c.uv1 = c.uv2 = {};
    return false;
  }
  std::vector<IntersectionPoint> pts = c.points;
  if (c.closed) pts.push_back(pts.front());
  std::vector<double> xyz, uv1, uv2;
  for (const auto& p : pts) {
    xyz.insert(xyz.end(), p.xyz.begin(), p.xyz.end());
    uv1.insert(uv1.end(), p.uv1.begin(), p.uv1.end());
    uv2.insert(uv2.end(), p.uv2.begin(), p.uv2.end());
  }
  const auto t = chord_params(c);
  for (int order = std::min<int>(4, static_cast<int>(pts.size())); order >= 2; --order) {
    try {
      const auto kv = spline::interpolation_knots(t, order);
      c.xyz = spline::interpolate_curve(t, 3, xyz, kv);
      c.uv1 = spline::interpolate_curve(t, 2, uv1, kv);
      c.uv2 = spline::interpolate_curve(t, 2, uv2, kv);
      return true;
    } catch (const Error&) {
      // Parameters too uneven for this order's averaged knots: one order lower (a polyline, order
      // 2, always interpolates distinct parameters).
    }
  }
  return false;
}

}  // namespace

std::vector<IntersectionCurve> intersect_surfaces(const Surface& a, const Surface& b, const IntersectionOptions& options,
                                                  std::vector<IntersectionContact>* contacts) {
  if (a.dim() < 3 || b.dim() < 3)
    throw Error("surface intersection of surfaces with " + std::to_string(a.dim()) + " and " + std::to_string(b.dim()) +
                " coordinates; expected at least 3 (xyz)");
  if (!(options.tolerance > 0) || !(options.max_step > 0))
    throw Error("surface intersection tolerance " + std::to_string(options.tolerance) + " and step " +
                std::to_string(options.max_step) + "; expected positive values");
  const Solver solver(a, b, options.tolerance);
  const double size = std::max(diag(control_box(a)), diag(control_box(b)));
  const double hmax = options.max_step * size;
  std::vector<IntersectionPoint> seeds;
  std::vector<Patch> pa, pb;
  for (const auto& p : spline::bezier_pieces(a)) pa.push_back(to_patch(p));
  for (const auto& p : spline::bezier_pieces(b)) pb.push_back(to_patch(p));
  for (const auto& p1 : pa)
    for (const auto& p2 : pb) find_seeds(p1, p2, 0.5 * hmax, options.tolerance, solver, 0, seeds);
  std::vector<IntersectionCurve> out;
  for (const auto& seed : seeds) {
    bool known = false;
    for (const auto& c : out)
      if (polyline_distance(c.points, seed.xyz) < 0.75 * hmax) known = true;
    if (known) continue;
    // Tangential contacts and coincident (overlapping) regions are not curves: skipped, and
    // classified for the caller (one seed per 0.75 hmax, at most 32).
    {
      V3 T;
      Eigen::Vector4d dt;
      if (!solver.tangent(seed, T, dt)) {
        if (!contacts || contacts->size() >= 32) continue;
        bool near = false;
        for (const auto& k : *contacts) near = near || dist(k.at, seed) < 0.75 * hmax;
        if (near) continue;
        if (const auto kind = classify_contact(a, b, seed, 0.05 * hmax, options.tolerance))
          contacts->push_back({*kind, seed});
        continue;
      }
    }
    IntersectionCurve c;
    bool closed = false, closed_back = false;
    const auto fwd = march(solver, seed, 1.0, hmax, options.tolerance, closed);
    std::vector<IntersectionPoint> back;
    if (!closed) back = march(solver, seed, -1.0, hmax, options.tolerance, closed_back);
    c.points.assign(back.rbegin(), back.rend());
    c.points.push_back(seed);
    c.points.insert(c.points.end(), fwd.begin(), fwd.end());
    c.closed = closed;
    // A branch whose points all lie within 10 tolerances of one another is a point: where the
    // surfaces meet at a single point (rectangles touching at a corner or an edge's end, a
    // tangential contact whose seed still had a tangent, a curve cut short at a singular point
    // such as a pole). It bounds no region and is dropped; any curve through it is traced from
    // its other seeds.
    if (!fit_curves(c, options.tolerance)) continue;
    // Densify until the xyz curve and both surfaces at the parameter-space curves' midpoints lie
    // within the tolerance of the intersection.
    for (int pass = 0; pass < 6; ++pass) {
      std::vector<IntersectionPoint> dense;
      bool all_good = true;
      const auto t = chord_params(c);
      const std::size_t n = c.points.size();
      for (std::size_t i = 0; i < n; ++i) {
        dense.push_back(c.points[i]);
        if (!c.closed && i + 1 == n) break;
        const double tm = 0.5 * (t[i] + t[i + 1]);
        const auto x = c.xyz.eval({tm}), u1 = c.uv1.eval({tm}), u2 = c.uv2.eval({tm});
        IntersectionPoint m;
        m.uv1 = {u1[0], u1[1]};
        m.uv2 = {u2[0], u2[1]};
        const IntersectionPoint& q = c.points[(i + 1) % n];
        Constraint k;
        k.kind = Constraint::plane;
        k.n = V3(q.xyz[0] - c.points[i].xyz[0], q.xyz[1] - c.points[i].xyz[1], q.xyz[2] - c.points[i].xyz[2]).normalized();
        k.q = V3(x[0], x[1], x[2]);
        if (!solver.solve(m, k)) continue;
        // The xyz curve and the images of both parameter-space curves (the trimming curves of the
        // faces: what the faces are cut along) within the tolerance of the intersection point.
        const auto x1 = a.eval({u1[0], u1[1]}), x2 = b.eval({u2[0], u2[1]});
        const double off = std::max({std::hypot(m.xyz[0] - x[0], m.xyz[1] - x[1], m.xyz[2] - x[2]),
                                     std::hypot(m.xyz[0] - x1[0], m.xyz[1] - x1[1], m.xyz[2] - x1[2]),
                                     std::hypot(m.xyz[0] - x2[0], m.xyz[1] - x2[1], m.xyz[2] - x2[2])});
        if (off > options.tolerance) {
          all_good = false;
          dense.push_back(m);
        }
      }
      if (all_good) break;
      c.points = std::move(dense);
      // The points kept before stay (drop_repeated compares each point with the one kept before
      // it), so the branch keeps at least its 2 points.
      if (!fit_curves(c, options.tolerance)) break;
    }
    if (c.points.size() < 2 || c.xyz.dim() != 3) continue;
    // A curve along which the normals stay within 1e-3 rad may be traced along a tangential
    // contact: classified at its middle point. A point contact's traced curve is a small loop
    // about the point within sqrt(tol / curvature) of it (where the surfaces are within the
    // tolerance): dropped as a point. A curve contact keeps its curve and is reported.
    if (largest_normal_angle(a, b, c) < 1e-3) {
      const IntersectionPoint mid = c.points[c.points.size() / 2];
      const auto kind = classify_contact(a, b, mid, 0.05 * hmax, options.tolerance);
      if (kind == IntersectionContact::Kind::point) continue;
      if (kind && contacts && contacts->size() < 32) contacts->push_back({*kind, mid});
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace trivox::geom
