#include "trivox/fillet/rails.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "trivox/error.hpp"
#include "trivox/spline/fit.hpp"

namespace trivox::fillet {

namespace {

using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using V2 = Eigen::Vector2d;
using V3 = Eigen::Vector3d;

constexpr int order = 4;            // cubic rails and bases
constexpr int max_rounds = 40;      // densification and trimming rounds
constexpr std::size_t max_samples = 200000;
constexpr int max_trims = 16;       // self-crossings removed per rail

std::string num(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.7g", x);
  return b;
}
std::string str(const V2& p) { return "(" + num(p[0]) + ", " + num(p[1]) + ")"; }
std::string str(const V3& p) { return "(" + num(p[0]) + ", " + num(p[1]) + ", " + num(p[2]) + ")"; }

struct Frame {
  V3 x, du, dv;
  V3 normal() const { return du.cross(dv); }
};

/// Least-squares (du, dv) of [S_u S_v] (du, dv) = D (Flends Sec. II.B, the 3 x 2 system).
V2 parameter_direction(const Frame& f, const V3& D) {
  Eigen::Matrix<double, 3, 2> A;
  A << f.du, f.dv;
  return (A.transpose() * A).ldlt().solve(A.transpose() * D);
}

/// A primary surface with its parameter rectangle. Evaluations clamp to the rectangle.
class Face {
public:
  Face(const Surface& s, int number)
      : s_(s), number_(number), lo_(s.domain(0)[0], s.domain(1)[0]), hi_(s.domain(0)[1], s.domain(1)[1]),
        buf_(static_cast<std::size_t>(3 * s.dim())) {}

  Frame frame(const V2& uv) const {
    s_.eval_derivatives({uv[0], uv[1]}, 1, buf_.data());
    const double* b = buf_.data();
    const int k = s_.dim();
    return {V3(b[0], b[1], b[2]), V3(b[k], b[k + 1], b[k + 2]), V3(b[2 * k], b[2 * k + 1], b[2 * k + 2])};
  }
  V3 point(const V2& uv) const { return frame(uv).x; }
  /// Inside the rectangle, or outside by at most `slack` in model units (a rail along an edge,
  /// off it by rounding, stays on its face; callers clamp).
  bool inside(const V2& uv, double slack) const {
    const V2 c = clamp(uv);
    if (c == uv) return true;
    if (!uv.allFinite()) return false;
    const Frame f = frame(c);
    return (f.du * (uv[0] - c[0]) + f.dv * (uv[1] - c[1])).norm() <= slack;
  }
  V2 clamp(const V2& uv) const { return uv.cwiseMax(lo_).cwiseMin(hi_); }
  /// Where the segment from a (inside) to b (outside) crosses the rectangle's boundary.
  V2 exit_point(const V2& a, const V2& b) const {
    double f = 1.0;
    for (int k = 0; k < 2; ++k) {
      const double d = b[k] - a[k];
      if (b[k] > hi_[k]) f = std::min(f, (hi_[k] - a[k]) / d);
      if (b[k] < lo_[k]) f = std::min(f, (lo_[k] - a[k]) / d);
    }
    return clamp(a + std::max(f, 0.0) * (b - a));
  }
  double extent() const { return (hi_ - lo_).norm(); }
  int number() const { return number_; }

private:
  const Surface& s_;
  int number_;  // 1 or 2, as the messages name it
  V2 lo_, hi_;
  mutable std::vector<double> buf_;
};

/// One parameter t of C with everything at it: C's point on both faces, its unit tangent
/// (along increasing t) and both rail points.
struct Sample {
  double t = 0.0;
  std::array<V2, 2> base;
  V3 x{0, 0, 0};
  V3 tangent{0, 0, 0};
  std::array<V2, 2> rail;
};

/// A trimmed stretch of one rail: constant `point` (a self-crossing) over [t0, t1].
struct Trim {
  double t0, t1;
  V2 point;
};

/// Clamped cubic knots for interpolation at sorted `t` (0 .. 1), with C0 joins (knots of
/// multiplicity order - 1) at `breaks`, so that each piece between breaks is interpolated on its
/// own and constant data on a piece give a constant curve there.
KnotVector piecewise_knots(const std::vector<double>& t, const std::vector<double>& breaks) {
  std::vector<double> knots;
  for (std::size_t k = 0; k + 1 < breaks.size(); ++k) {
    std::vector<double> piece;
    for (const double x : t)
      if (x >= breaks[k] && x <= breaks[k + 1]) piece.push_back(x);
    const auto kv = spline::interpolation_knots(piece, order).knots();
    const std::size_t first = k == 0 ? 0 : order;
    const std::size_t last = k + 2 == breaks.size() ? kv.size() : kv.size() - 1;
    knots.insert(knots.end(), kv.begin() + static_cast<std::ptrdiff_t>(first),
                 kv.begin() + static_cast<std::ptrdiff_t>(last));
  }
  return KnotVector(order, std::move(knots));
}

V2 eval2(const Curve& c, double t) {
  double out[2];
  c.eval({t}, out);
  return {out[0], out[1]};
}

class RailBuilder {
public:
  RailBuilder(const Surface& s1, const Surface& s2, std::array<double, 2> outward, const geom::IntersectionCurve& curve,
              std::array<double, 2> distance, const RailOptions& options)
      : faces_{Face(s1, 1), Face(s2, 2)}, outward_(outward), d_(distance), tol_(options.tolerance),
        flip_(options.flip), closed_(curve.closed) {
    initial_samples(curve);
    decide_sides();
    for (auto& s : samples_) set_rails(s);
    breaks_ = {0.0, 1.0};
  }

  RailPair build() {
    int trims = 0;
    for (int round = 0;; ++round) {
      fill_pieces();
      fit();
      const auto bad = check();
      if (!bad.empty()) {
        if (round >= max_rounds || samples_.size() > max_samples)
          throw Error("rails: no convergence to the tolerance " + num(tol_) + " after " +
                          std::to_string(samples_.size()) + " samples (largest deviation " + num(worst_) + ")",
                      ErrorKind::failed);
        densify(bad);
        continue;
      }
      if (trims < max_trims && (trim_crossing(0) || trim_crossing(1))) {
        ++trims;
        continue;
      }
      break;
    }
    RailPair out;
    out.closed = closed_;
    for (std::size_t i = 0; i < 2; ++i) {
      Rail& r = out.rails[i];
      r.base = fitted_[2 * i];
      r.rail = fitted_[2 * i + 1];
      for (const Trim& m : trims_[i]) r.trimmed.push_back({m.t0, m.t1});
      std::sort(r.trimmed.begin(), r.trimmed.end());
      r.max_error = max_error_[i];
    }
    return out;
  }

private:
  // --- C: points on both faces ----------------------------------------------------------------

  /// Newton on S_1(a) = S_2(b), (S_1(a) - q) . n = 0 (4 x 4), from the sample's base points.
  bool correct(Sample& s, const V3& q, const V3& n) const {
    V2 a = s.base[0], b = s.base[1];
    for (int it = 0; it < 30; ++it) {
      const Frame f1 = faces_[0].frame(a), f2 = faces_[1].frame(b);
      const V3 F = f1.x - f2.x;
      const double g = (f1.x - q).dot(n);
      if (F.norm() <= 1e-3 * tol_ && std::abs(g) <= 1e-3 * tol_) {
        s.base = {a, b};
        s.x = 0.5 * (f1.x + f2.x);
        return true;
      }
      Eigen::Matrix4d A;
      A.block<3, 1>(0, 0) = f1.du;
      A.block<3, 1>(0, 1) = f1.dv;
      A.block<3, 1>(0, 2) = -f2.du;
      A.block<3, 1>(0, 3) = -f2.dv;
      A.row(3) << n.dot(f1.du), n.dot(f1.dv), 0.0, 0.0;
      Eigen::Vector4d r;
      r << -F, -g;
      const Eigen::Vector4d step = A.fullPivLu().solve(r);
      if (!step.allFinite()) return false;
      a = faces_[0].clamp(a + step.head<2>());
      b = faces_[1].clamp(b + step.tail<2>());
    }
    return false;
  }

  /// Unit n_1 x n_2 at the base points, oriented along `along`; none where the faces touch.
  std::optional<V3> tangent_at(const std::array<V2, 2>& base, const V3& along) const {
    const V3 n1 = faces_[0].frame(base[0]).normal(), n2 = faces_[1].frame(base[1]).normal();
    V3 c = n1.cross(n2);
    if (!(c.norm() > 1e-9 * n1.norm() * n2.norm())) return std::nullopt;
    c.normalize();
    return c.dot(along) < 0 ? -c : c;
  }

  void initial_samples(const geom::IntersectionCurve& curve) {
    std::vector<Sample> pts;
    for (std::size_t j = 0; j < curve.points.size(); ++j) {
      const auto& p = curve.points[j];
      Sample s;
      s.base = {V2(p.uv1[0], p.uv1[1]), V2(p.uv2[0], p.uv2[1])};
      s.x = V3(p.xyz[0], p.xyz[1], p.xyz[2]);
      const auto T = tangent_at(s.base, V3(1, 0, 0));
      const V3 q = s.x;
      if (!T || !correct(s, q, *T))
        throw Error("rails: intersection point " + std::to_string(j) + " at " + str(q) +
                        (T ? " does not lie on both faces" : ": the faces touch tangentially there"),
                    ErrorKind::failed);
      // Repeated points would repeat a parameter.
      if (!pts.empty() && (pts.back().x - s.x).norm() <= 10 * tol_) {
        if (j + 1 == curve.points.size() && pts.size() > 1) pts.back() = s;
        continue;
      }
      pts.push_back(s);
    }
    if (closed_) {
      if (pts.size() > 2 && (pts.back().x - pts.front().x).norm() <= 10 * tol_) pts.pop_back();
      pts.push_back(pts.front());
    }
    if (pts.size() < 2)
      throw Error("rails: the intersection curve has " + std::to_string(pts.size()) +
                  " distinct point(s); expected at least 2");
    std::vector<double> xyz;
    for (const auto& s : pts) xyz.insert(xyz.end(), s.x.data(), s.x.data() + 3);
    const auto t = spline::chord_length_params(xyz, 3);
    const std::size_t n = pts.size();
    for (std::size_t j = 0; j < n; ++j) {
      pts[j].t = t[j];
      std::size_t prev = j > 0 ? j - 1 : (closed_ ? n - 2 : 0);
      std::size_t next = j + 1 < n ? j + 1 : (closed_ ? 1 : n - 1);
      const auto T = tangent_at(pts[j].base, pts[next].x - pts[prev].x);
      if (!T)
        throw Error("rails: the faces touch tangentially at t = " + num(t[j]) + ", " + str(pts[j].x) +
                        "; C has no normal plane there",
                    ErrorKind::failed);
      pts[j].tangent = *T;
    }
    pts.front().t = 0.0;
    pts.back().t = 1.0;
    samples_ = std::move(pts);
  }

  // --- The side rule ----------------------------------------------------------------------------

  /// Unit n_i x T at uv on face i (before the side sign).
  static V3 across(const Frame& f, const V3& T) { return f.normal().cross(T).normalized(); }

  /// sigma_i: the sign making sigma_i (n_i x C') point into the other face's outside
  /// (outward_j n_j), from all samples at once; then the flip.
  void decide_sides() {
    for (std::size_t i = 0; i < 2; ++i) {
      const std::size_t o = 1 - i;
      int pos = 0, neg = 0;
      double t_pos = 0.0, t_neg = 0.0;
      for (const auto& s : samples_) {
        const V3 D = across(faces_[i].frame(s.base[i]), s.tangent);
        const V3 N = (outward_[o] * faces_[o].frame(s.base[o]).normal()).normalized();
        const double dot = D.dot(N);
        if (dot > 1e-6) ++pos, t_pos = s.t;
        if (dot < -1e-6) ++neg, t_neg = s.t;
      }
      if (pos == 0 && neg == 0)
        throw Error("rails: face " + std::to_string(i + 1) + " is tangent to face " + std::to_string(o + 1) +
                        " all along C; the side of the rail cannot be decided",
                    ErrorKind::failed);
      if (pos > 0 && neg > 0)
        throw Error("rails: the outside of face " + std::to_string(o + 1) + " is on different sides of C on face " +
                        std::to_string(i + 1) + " (at t = " + num(t_pos) + " and t = " + num(t_neg) +
                        "); the faces touch tangentially between",
                    ErrorKind::failed);
      sigma_[i] = (pos > 0 ? 1.0 : -1.0) * (flip_[i] ? -1.0 : 1.0);
    }
  }

  // --- Rail points ------------------------------------------------------------------------------

  Error leaves(std::size_t i, const Sample& s, const V2& where) const {
    return Error("rails: the rail on face " + std::to_string(i + 1) + " at distance " + num(d_[i]) +
                 " leaves the face at t = " + num(s.t) + " (C at " + str(s.x) + "), through its boundary at (u, v) = " +
                 str(where) + "; expected a distance the face holds there");
  }

  /// Flends Sec. II.B: from C(t) on face i, steps on the face along sigma_i (n_i x T) (the
  /// section of the face by C's normal plane), each pulled back into that plane, until the point
  /// is about d away; then Newton on |S - X|^2 = d^2, (S - X) . T = 0.
  V2 march(std::size_t i, const Sample& s) const {
    const Face& f = faces_[i];
    const double d = d_[i];
    const V3& X = s.x;
    const V3& T = s.tangent;
    V2 uv = s.base[i];
    Frame fr = f.frame(uv);
    V3 D = sigma_[i] * across(fr, T);
    double r = 0.0;
    for (int step = 0;; ++step) {
      r = (fr.x - X).norm();
      if (d - r <= 1e-3 * d) break;
      if (step == 2000)
        throw Error("rails: the rail on face " + std::to_string(i + 1) + " does not reach distance " + num(d) +
                    " from C at t = " + num(s.t) + " (" + str(X) + "); it gets no farther than " + num(r) +
                    " near (u, v) = " + str(uv) + "; expected a distance the face holds there");
      V2 next = uv + std::min(d / 8, d - r) * parameter_direction(fr, D);
      if (!f.inside(next, tol_)) throw leaves(i, s, f.exit_point(uv, next));
      next = f.clamp(next);
      Frame fn = f.frame(next);
      for (int k = 0; k < 3; ++k) {  // back into the normal plane, minimum-norm Newton
        const double g = (fn.x - X).dot(T);
        const V2 grad(T.dot(fn.du), T.dot(fn.dv));
        if (std::abs(g) <= 1e-3 * tol_ || !(grad.squaredNorm() > 0)) break;
        const V2 back = next - g / grad.squaredNorm() * grad;
        if (!f.inside(back, tol_)) throw leaves(i, s, f.exit_point(next, back));
        next = f.clamp(back);
        fn = f.frame(next);
      }
      if (!((fn.x - X).norm() > r))
        throw Error("rails: the rail on face " + std::to_string(i + 1) + " cannot reach distance " + num(d) +
                    " from C at t = " + num(s.t) + " (" + str(X) + "): in C's normal plane the face turns back at " +
                    num(r) + ", (u, v) = " + str(uv) + "; expected a smaller distance");
      V3 Dn = across(fn, T);
      D = Dn.dot(D) < 0 ? -Dn : Dn;
      uv = next;
      fr = fn;
    }
    int settled = 0;
    double res = 1e300;
    for (int it = 0; it < 40 && settled < 2; ++it) {
      const V3 e = fr.x - X;
      const V2 F((e.squaredNorm() - d * d) / (2 * d), e.dot(T));
      res = F.cwiseAbs().maxCoeff();
      if (res <= 1e-3 * tol_) ++settled;
      Eigen::Matrix2d J;
      J << e.dot(fr.du) / d, e.dot(fr.dv) / d, T.dot(fr.du), T.dot(fr.dv);
      const V2 step = J.fullPivLu().solve(-F);
      if (!step.allFinite()) break;
      const V2 next = uv + step;
      if (!f.inside(next, tol_)) throw leaves(i, s, f.exit_point(uv, next));
      uv = f.clamp(next);
      fr = f.frame(uv);
    }
    const V3 e = fr.x - X;
    res = std::max(std::abs(e.norm() - d), std::abs(e.dot(T)));
    if (!(res <= 1e-2 * tol_))
      throw Error("rails: Newton finds no rail point on face " + std::to_string(i + 1) + " at distance " + num(d) +
                      " from C at t = " + num(s.t) + " (" + str(X) + "); last residual " + num(res),
                  ErrorKind::failed);
    return uv;
  }

  const Trim* trim_at(std::size_t i, double t) const {
    for (const Trim& m : trims_[i])
      if (t >= m.t0 && t <= m.t1) return &m;
    return nullptr;
  }

  bool trimmed_between(std::size_t i, double a, double b) const {
    for (const Trim& m : trims_[i])
      if (a >= m.t0 && b <= m.t1) return true;
    return false;
  }

  void set_rails(Sample& s) const {
    for (std::size_t i = 0; i < 2; ++i) {
      const Trim* m = trim_at(i, s.t);
      s.rail[i] = m ? m->point : march(i, s);
    }
  }

  /// A new sample at t, between samples j and j + 1: a true intersection point (Newton onto
  /// both faces in the plane through the guess normal to C) with its rail points.
  Sample make_sample(double t, std::size_t j) const {
    const Sample& a = samples_[j];
    const Sample& b = samples_[j + 1];
    Sample s;
    s.t = t;
    if (have_fit_) {
      s.base = {eval2(fitted_[0], t), eval2(fitted_[2], t)};
    } else {
      const double w = (t - a.t) / (b.t - a.t);
      s.base = {(1 - w) * a.base[0] + w * b.base[0], (1 - w) * a.base[1] + w * b.base[1]};
    }
    const V3 along = b.x - a.x;
    const auto T0 = tangent_at(s.base, along);
    const V3 q = 0.5 * (faces_[0].point(s.base[0]) + faces_[1].point(s.base[1]));
    if (!T0 || !correct(s, q, *T0))
      throw Error("rails: no intersection point of the faces near " + str(q) + " (t = " + num(t) + ")",
                  ErrorKind::failed);
    const auto T = tangent_at(s.base, along);
    if (!T)
      throw Error("rails: the faces touch tangentially at t = " + num(t) + ", " + str(s.x), ErrorKind::failed);
    s.tangent = *T;
    set_rails(s);
    return s;
  }

  // --- Fitting and checking ---------------------------------------------------------------------

  /// Every piece between breaks needs `order` samples for a cubic.
  void fill_pieces() {
    for (bool again = true; again;) {
      again = false;
      for (std::size_t k = 0; k + 1 < breaks_.size(); ++k) {
        std::size_t count = 0, widest = 0;
        double gap = -1.0;
        for (std::size_t j = 0; j + 1 < samples_.size(); ++j) {
          if (samples_[j].t < breaks_[k] || samples_[j + 1].t > breaks_[k + 1]) continue;
          ++count;
          if (samples_[j + 1].t - samples_[j].t > gap) gap = samples_[j + 1].t - samples_[j].t, widest = j;
        }
        if (count + 1 >= static_cast<std::size_t>(order)) continue;
        const double t = 0.5 * (samples_[widest].t + samples_[widest + 1].t);
        const Sample s = make_sample(t, widest);
        samples_.insert(samples_.begin() + static_cast<std::ptrdiff_t>(widest + 1), s);
        again = true;
      }
    }
  }

  void fit() {
    std::vector<double> t;
    std::array<std::vector<double>, 4> v;
    for (const auto& s : samples_) {
      t.push_back(s.t);
      for (std::size_t i = 0; i < 2; ++i) {
        v[2 * i].insert(v[2 * i].end(), s.base[i].data(), s.base[i].data() + 2);
        v[2 * i + 1].insert(v[2 * i + 1].end(), s.rail[i].data(), s.rail[i].data() + 2);
      }
    }
    const KnotVector kv = piecewise_knots(t, breaks_);
    for (std::size_t c = 0; c < 4; ++c) {
      fitted_[c] = spline::interpolate_curve(t, 2, v[c], kv);
      // Clamped ends interpolate their end control points: set them to the data exactly, so a
      // closed curve closes to the last bit.
      auto pts = fitted_[c].points();
      std::copy_n(v[c].begin(), 2, pts.begin());
      std::copy_n(v[c].end() - 2, 2, pts.end() - 2);
    }
    have_fit_ = true;
  }

  /// Between samples (at 1/4, 1/2, 3/4 of each interval): the bases meet, and each rail point is
  /// at d from C and in C's normal plane. Returns the intervals to split.
  std::vector<std::size_t> check() {
    std::vector<std::size_t> bad;
    max_error_ = {0.0, 0.0};
    worst_ = 0.0;
    for (std::size_t j = 0; j + 1 < samples_.size(); ++j) {
      const Sample& a = samples_[j];
      const Sample& b = samples_[j + 1];
      double err = 0.0;
      for (const double w : {0.25, 0.5, 0.75}) {
        const double t = a.t + w * (b.t - a.t);
        const std::array<V2, 2> base{eval2(fitted_[0], t), eval2(fitted_[2], t)};
        const Frame f1 = faces_[0].frame(base[0]), f2 = faces_[1].frame(base[1]);
        const double gap = (f1.x - f2.x).norm();
        const V3 C = 0.5 * (f1.x + f2.x);
        const V3 T = f1.normal().cross(f2.normal()).normalized();
        for (std::size_t i = 0; i < 2; ++i) {
          double e = gap;
          if (!trimmed_between(i, a.t, b.t)) {
            const V3 P = faces_[i].point(eval2(fitted_[2 * i + 1], t)) - C;
            e = std::max({e, std::abs(P.norm() - d_[i]), std::abs(P.dot(T))});
          }
          if (!std::isfinite(e)) e = 1e300;
          max_error_[i] = std::max(max_error_[i], e);
          err = std::max(err, e);
        }
      }
      worst_ = std::max(worst_, err);
      if (err > tol_) bad.push_back(j);
    }
    return bad;
  }

  void densify(const std::vector<std::size_t>& bad) {
    std::vector<Sample> out;
    out.reserve(samples_.size() + bad.size());
    std::size_t k = 0;
    for (std::size_t j = 0; j < samples_.size(); ++j) {
      out.push_back(samples_[j]);
      if (k < bad.size() && bad[k] == j) {
        out.push_back(make_sample(0.5 * (samples_[j].t + samples_[j + 1].t), j));
        ++k;
      }
    }
    samples_ = std::move(out);
  }

  // --- Self-crossings ---------------------------------------------------------------------------

  /// Flends Sec. II.B: Newton on P(ta) - P(tb) = 0 from the linearised segments' crossing.
  bool refine_crossing(const Curve& R, double& ta, double& tb) const {
    double buf_a[4], buf_b[4];
    for (int it = 0; it < 40; ++it) {
      R.eval_derivatives({ta}, 1, buf_a);
      R.eval_derivatives({tb}, 1, buf_b);
      const V2 F(buf_a[0] - buf_b[0], buf_a[1] - buf_b[1]);
      Eigen::Matrix2d J;
      J << buf_a[2], -buf_b[2], buf_a[3], -buf_b[3];
      const V2 step = J.fullPivLu().solve(-F);
      if (!step.allFinite()) return false;
      ta = std::clamp(ta + step[0], 0.0, 1.0);
      tb = std::clamp(tb + step[1], 0.0, 1.0);
      if (step.norm() <= 1e-15) break;
    }
    const V2 pa = eval2(R, ta), pb = eval2(R, tb);
    return (pa - pb).norm() <= 1e-12 * faces_[0].extent() + 1e-12 * faces_[1].extent() && tb - ta > 1e-9;
  }

  /// The self-crossing of rail i's sample polyline with the widest loop, refined on the fitted
  /// rail; removes that loop (Trim) and returns true, or returns false when there is none.
  bool trim_crossing(std::size_t i) {
    const Curve& R = fitted_[2 * i + 1];
    const std::size_t n = samples_.size();
    double best_span = 0.0, best_a = 0.0, best_b = 0.0;
    for (std::size_t a = 0; a + 1 < n; ++a) {
      const V2 p = samples_[a].rail[i], q = samples_[a + 1].rail[i];
      const V2 pq = q - p;
      if (pq.squaredNorm() == 0) continue;
      const V2 lo = p.cwiseMin(q), hi = p.cwiseMax(q);
      for (std::size_t b = a + 2; b + 1 < n; ++b) {
        if (closed_ && a == 0 && b + 2 == n) continue;  // neighbours across the closure
        const V2 r = samples_[b].rail[i], s = samples_[b + 1].rail[i];
        if ((r.cwiseMax(s).array() < lo.array()).any() || (r.cwiseMin(s).array() > hi.array()).any()) continue;
        const V2 rs = s - r;
        const auto cross = [](const V2& x, const V2& y) { return x[0] * y[1] - x[1] * y[0]; };
        // Proper crossings only, with a margin: a shared end (rails whose ends meet) is a touch.
        const double eps = 1e-12 * std::sqrt(pq.squaredNorm() * rs.squaredNorm());
        const double o1 = cross(pq, r - p), o2 = cross(pq, s - p), o3 = cross(rs, p - r), o4 = cross(rs, q - r);
        if (!((o1 > eps && o2 < -eps) || (o1 < -eps && o2 > eps))) continue;
        if (!((o3 > eps && o4 < -eps) || (o3 < -eps && o4 > eps))) continue;
        double ta = samples_[a].t + o3 / (o3 - o4) * (samples_[a + 1].t - samples_[a].t);
        double tb = samples_[b].t + o1 / (o1 - o2) * (samples_[b + 1].t - samples_[b].t);
        if (!refine_crossing(R, ta, tb)) continue;
        if (!closed_ && (ta <= 1e-9 || tb >= 1 - 1e-9)) continue;
        const double span = closed_ ? std::min(tb - ta, 1 - (tb - ta)) : tb - ta;
        if (span > best_span) best_span = span, best_a = ta, best_b = tb;
      }
    }
    if (!(best_span > 0)) return false;
    const V2 point = 0.5 * (eval2(R, best_a) + eval2(R, best_b));
    // The loop is the stretch between the crossing parameters; on a closed rail the shorter of
    // the two ways round.
    if (!closed_ || best_b - best_a <= 0.5) {
      trims_[i].push_back({best_a, best_b, point});
    } else {
      trims_[i].push_back({0.0, best_a, point});
      trims_[i].push_back({best_b, 1.0, point});
    }
    add_break(best_a);
    add_break(best_b);
    for (auto& s : samples_)
      if (const Trim* m = trim_at(i, s.t)) s.rail[i] = m->point;
    return true;
  }

  /// A sample exactly at t, made a C0 break of the common function space. Samples very near t
  /// are dropped first (they would make the interpolation ill-conditioned).
  void add_break(double t) {
    const auto fixed = [&](double x) { return std::find(breaks_.begin(), breaks_.end(), x) != breaks_.end(); };
    if (fixed(t)) return;
    auto it = std::lower_bound(samples_.begin(), samples_.end(), t, [](const Sample& s, double x) { return s.t < x; });
    std::size_t hi = static_cast<std::size_t>(it - samples_.begin());  // first sample with s.t >= t
    std::size_t lo = hi - 1;
    if (samples_[hi].t == t) {
      breaks_.insert(std::upper_bound(breaks_.begin(), breaks_.end(), t), t);
      return;
    }
    const double gap = samples_[hi].t - samples_[lo].t;
    if (t - samples_[lo].t < 0.1 * gap && !fixed(samples_[lo].t)) {
      samples_.erase(samples_.begin() + static_cast<std::ptrdiff_t>(lo));
      --hi, --lo;
    }
    if (samples_[hi].t - t < 0.1 * gap && !fixed(samples_[hi].t))
      samples_.erase(samples_.begin() + static_cast<std::ptrdiff_t>(hi));
    const Sample s = make_sample(t, lo);
    samples_.insert(samples_.begin() + static_cast<std::ptrdiff_t>(lo + 1), s);
    breaks_.insert(std::upper_bound(breaks_.begin(), breaks_.end(), t), t);
  }

  std::array<Face, 2> faces_;
  std::array<double, 2> outward_, d_;
  double tol_;
  std::array<bool, 2> flip_;
  bool closed_;
  std::array<double, 2> sigma_{1.0, 1.0};
  std::vector<Sample> samples_;        // sorted by t, t from 0 to 1
  std::vector<double> breaks_;         // C0 joins of the function space, 0 and 1 included
  std::array<std::vector<Trim>, 2> trims_;
  std::array<Curve, 4> fitted_;        // base 1, rail 1, base 2, rail 2
  bool have_fit_ = false;
  std::array<double, 2> max_error_{0.0, 0.0};
  double worst_ = 0.0;
};

}  // namespace

RailPair offset_rails(const Surface& face1, const Surface& face2, std::array<double, 2> outward,
                      const geom::IntersectionCurve& curve, std::array<double, 2> distance, const RailOptions& options) {
  if (face1.dim() < 3 || face2.dim() < 3)
    throw Error("rails: faces with " + std::to_string(face1.dim()) + " and " + std::to_string(face2.dim()) +
                " coordinates; expected at least 3 (xyz)");
  for (std::size_t i = 0; i < 2; ++i) {
    if (!(distance[i] > 0) || !std::isfinite(distance[i]))
      throw Error("rails: distance " + num(distance[i]) + " on face " + std::to_string(i + 1) +
                  "; expected a positive distance");
    if (!(outward[i] == 1.0 || outward[i] == -1.0))
      throw Error("rails: outward sign " + num(outward[i]) + " for face " + std::to_string(i + 1) +
                  "; expected +1 or -1");
  }
  if (!(options.tolerance > 0) || !std::isfinite(options.tolerance))
    throw Error("rails: tolerance " + num(options.tolerance) + "; expected a positive value");
  if (curve.points.size() < 2)
    throw Error("rails: the intersection curve has " + std::to_string(curve.points.size()) +
                " point(s); expected at least 2");
  return RailBuilder(face1, face2, outward, curve, distance, options).build();
}

}  // namespace trivox::fillet
