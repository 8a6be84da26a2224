#include "trivox/geom/closest_point.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "trivox/error.hpp"

namespace trivox::geom {

namespace {

double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Parameters of `samples` per span of kv, ends included.
std::vector<double> sample_params(const spline::KnotVector& kv, int samples) {
  std::vector<double> t;
  const auto br = kv.breakpoints();
  for (std::size_t s = 0; s + 1 < br.size(); ++s) {
    const double a = br[s].value, b = br[s + 1].value;
    for (int k = 0; k < samples; ++k) t.push_back(a + (b - a) * k / samples);
  }
  t.push_back(kv.back());
  return t;
}

}  // namespace

SurfaceDistance::SurfaceDistance(spline::Surface surface, int samples_per_span) : surface_(std::move(surface)) {
  if (surface_.dim() < 3)
    throw Error("closest point on a surface with " + std::to_string(surface_.dim()) +
                " coordinates; expected at least 3 (xyz)");
  // Newton needs xyz only: a copy of the surface without its property coordinates halves the
  // work per evaluation for a surface that carries three properties.
  if (surface_.dim() == 3) {
    geo_ = surface_;
  } else {
    const int n = surface_.size(), k = surface_.dim();
    std::vector<double> xyz(static_cast<std::size_t>(3 * n));
    for (int r = 0; r < n; ++r)
      for (int d = 0; d < 3; ++d) xyz[static_cast<std::size_t>(3 * r + d)] = surface_.points()[static_cast<std::size_t>(k * r + d)];
    geo_ = spline::Surface(surface_.knot_vectors(), 3, std::move(xyz), surface_.weights());
  }
  samples_per_span = std::max(2, samples_per_span);
  const auto us = sample_params(surface_.knots(0), samples_per_span);
  const auto vs = sample_params(surface_.knots(1), samples_per_span);
  std::vector<double> x(static_cast<std::size_t>(surface_.dim()));
  for (double v : vs)
    for (double u : us) {
      surface_.eval({u, v}, x.data());
      uv_.push_back({u, v});
      xyz_.push_back({x[0], x[1], x[2]});
    }
}

ClosestPoint SurfaceDistance::closest(const std::array<double, 3>& p) const {
  // The three nearest samples start Newton; the best answer wins.
  std::array<std::size_t, 3> best{0, 0, 0};
  std::array<double, 3> best_d{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                               std::numeric_limits<double>::infinity()};
  for (std::size_t i = 0; i < xyz_.size(); ++i) {
    const double dx = xyz_[i][0] - p[0], dy = xyz_[i][1] - p[1], dz = xyz_[i][2] - p[2];
    const double d = dx * dx + dy * dy + dz * dz;
    if (d < best_d[2]) {
      std::size_t k = 2;
      while (k > 0 && d < best_d[k - 1]) {
        best_d[k] = best_d[k - 1];
        best[k] = best[k - 1];
        --k;
      }
      best_d[k] = d;
      best[k] = i;
    }
  }
  std::vector<double> buf(6 * 3), val(3);
  ClosestPoint out;
  out.distance = std::numeric_limits<double>::infinity();
  const std::size_t starts = std::min<std::size_t>(3, xyz_.size());
  for (std::size_t s = 0; s < starts; ++s) {
    std::array<double, 2> t = uv_[best[s]];
    double f = best_d[s];
    const bool conv = descend(p, t, f, buf.data(), val.data());
    if (std::sqrt(f) < out.distance) {
      geo_.eval(t, val.data());
      out.uv = t;
      out.point = {val[0], val[1], val[2]};
      out.distance = std::sqrt(f);
      out.converged = conv;
    }
  }
  return out;
}

ClosestPoint SurfaceDistance::closest(const std::array<double, 3>& p, const std::array<double, 2>& start,
                                      double* values) const {
  double buf[6 * 3], val[3];
  const auto du = geo_.domain(0), dv = geo_.domain(1);
  std::array<double, 2> t{std::clamp(start[0], du[0], du[1]), std::clamp(start[1], dv[0], dv[1])};
  geo_.eval(t, val);
  const double r[3] = {val[0] - p[0], val[1] - p[1], val[2] - p[2]};
  double f = dot3(r, r);
  ClosestPoint out;
  out.converged = descend(p, t, f, buf, val);
  out.uv = t;
  if (values) {
    surface_.eval(t, values);
    out.point = {values[0], values[1], values[2]};
  } else {
    geo_.eval(t, val);
    out.point = {val[0], val[1], val[2]};
  }
  out.distance = std::sqrt(f);
  return out;
}

bool SurfaceDistance::descend(const std::array<double, 3>& p, std::array<double, 2>& t, double& f, double* buf,
                              double* val) const {
  const auto du = geo_.domain(0), dv = geo_.domain(1);
  const double lo[2] = {du[0], dv[0]}, hi[2] = {du[1], dv[1]};
  constexpr int dim = 3;
  const auto f_at = [&](const std::array<double, 2>& x) {
    geo_.eval(x, val);
    const double r[3] = {val[0] - p[0], val[1] - p[1], val[2] - p[2]};
    return dot3(r, r);
  };
  double last = std::numeric_limits<double>::infinity();  // the previous step's size
  for (int it = 0; it < 40; ++it) {
    geo_.eval_derivatives(t, 2, buf);
    const double* S = buf;
    const double* Su = S + dim;
    const double* Sv = S + 2 * dim;
    const double* Suu = S + 3 * dim;
    const double* Suv = S + 4 * dim;
    const double* Svv = S + 5 * dim;
    const double r[3] = {S[0] - p[0], S[1] - p[1], S[2] - p[2]};
    const double g[2] = {dot3(r, Su), dot3(r, Sv)};
    double H[2][2] = {{dot3(Su, Su) + dot3(r, Suu), dot3(Su, Sv) + dot3(r, Suv)}, {0.0, dot3(Sv, Sv) + dot3(r, Svv)}};
    H[1][0] = H[0][1];
    if (!(H[0][0] > 0 && H[0][0] * H[1][1] - H[0][1] * H[0][1] > 0)) {  // Gauss-Newton away from convexity
      H[0][0] = dot3(Su, Su);
      H[1][1] = dot3(Sv, Sv);
      H[0][1] = H[1][0] = dot3(Su, Sv);
    }
    // Coordinates at a bound whose descent direction leaves the domain are frozen.
    bool frozen[2] = {false, false};
    for (int d = 0; d < 2; ++d)
      frozen[d] = (t[static_cast<std::size_t>(d)] <= lo[d] && g[d] > 0) || (t[static_cast<std::size_t>(d)] >= hi[d] && g[d] < 0);
    double step[2] = {0.0, 0.0};
    if (!frozen[0] && !frozen[1]) {
      const double det = H[0][0] * H[1][1] - H[0][1] * H[1][0];
      if (std::abs(det) > 0) {
        step[0] = -(H[1][1] * g[0] - H[0][1] * g[1]) / det;
        step[1] = -(H[0][0] * g[1] - H[1][0] * g[0]) / det;
      }
    } else {
      for (int d = 0; d < 2; ++d)
        if (!frozen[d] && H[d][d] > 0) step[d] = -g[d] / H[d][d];
    }
    // Near the minimum |S - p|^2 is flat to rounding (it fixes (u, v) only to about the square
    // root of the machine epsilon), so small Newton steps, which the gradient decides to full
    // precision, are taken without asking f to decrease: warm and cold starts then agree to
    // rounding, not to 1e-8.
    const bool small = std::abs(step[0]) / (hi[0] - lo[0]) + std::abs(step[1]) / (hi[1] - lo[1]) < 1e-7;
    double lambda = 1.0;
    std::array<double, 2> next{};
    double fn = f;
    for (int h = 0; h < 30; ++h, lambda *= 0.5) {
      for (std::size_t d = 0; d < 2; ++d) next[d] = std::clamp(t[d] + lambda * step[d], lo[d], hi[d]);
      fn = f_at(next);
      if (fn <= f || (small && h == 0)) break;
    }
    const double moved = std::abs(next[0] - t[0]) / (hi[0] - lo[0]) + std::abs(next[1] - t[1]) / (hi[1] - lo[1]);
    if (!(fn <= f) && !small) return true;  // no descent: t is stationary to working precision
    t = next;
    f = fn;
    // Converged: a step below 1e-15 of the domain; or below 1e-12 without shrinking any more,
    // the rounding floor of the gradient (on order-19 patches steps of 1e-14 wander).
    if (moved < 1e-15 || (moved < 1e-12 && moved > 0.25 * last)) return true;
    last = moved;
  }
  return false;
}

double distance(const std::vector<SurfaceDistance>& surfaces, const std::array<double, 3>& p) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& s : surfaces) d = std::min(d, s.closest(p).distance);
  return d;
}

}  // namespace trivox::geom
