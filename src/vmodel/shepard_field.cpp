#include "trivox/vmodel/shepard_field.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::vmodel {

std::array<double, 2> shepard_weights(double d1, double d2, int q) noexcept {
  if (!(d1 > 0) && !(d2 > 0)) return {0.5, 0.5};  // on C: both distances vanish
  // alpha_near = 1 / (1 + (d_near / d_far)^q): d^-q never formed, so no overflow on S^_i.
  const bool first = d1 <= d2;
  const double r = first ? d1 / d2 : d2 / d1;
  double t = 1.0;
  for (int k = 0; k < q; ++k) t *= r;
  const double near = 1.0 / (1.0 + t), far = t / (1.0 + t);  // each to full relative precision
  return first ? std::array<double, 2>{near, far} : std::array<double, 2>{far, near};
}

namespace {

const spline::Surface& checked_source(const std::array<spline::Surface, 2>& s, std::size_t i, int power) {
  if (s[0].dim() != s[1].dim())
    throw Error("Shepard blend: S^_1 has " + std::to_string(s[0].dim()) + " coordinates and S^_2 " +
                std::to_string(s[1].dim()) + "; expected the same (xyz and the same properties)");
  if (s[i].dim() < 3)
    throw Error("Shepard blend: S^_" + std::to_string(i + 1) + " has " + std::to_string(s[i].dim()) +
                " coordinates; expected at least 3 (xyz)");
  if (power < 1 || power > 16)
    throw Error("Shepard blend: power " + std::to_string(power) + "; expected an integer q in 1..16");
  return s[i];
}

double box_diagonal(const spline::Surface& s) {
  const auto b = s.control_box();
  double d = 0.0;
  for (std::size_t k = 0; k < 3; ++k) d += (b[1][k] - b[0][k]) * (b[1][k] - b[0][k]);
  return std::sqrt(d);
}

}  // namespace

ShepardField::ShepardField(const std::array<spline::Surface, 2>& sources, int power)
    : dist_{geom::SurfaceDistance(checked_source(sources, 0, power)), geom::SurfaceDistance(checked_source(sources, 1, power))},
      m_(sources[0].dim() - 3),
      q_(power) {
  slack_ = 1e-9 * std::max(box_diagonal(sources[0]), box_diagonal(sources[1]));
}

ShepardValue ShepardField::eval(const std::array<double, 3>& p, double* props, ShepardWalk* walk) const {
  const int dim = 3 + m_;
  constexpr int stack_dim = 32;
  double sval[2][stack_dim];
  std::vector<double> hval;
  double* val[2] = {sval[0], sval[1]};
  if (dim > stack_dim) {
    hval.resize(2 * static_cast<std::size_t>(dim));
    val[0] = hval.data();
    val[1] = hval.data() + dim;
  }
  ShepardValue out;
  const double step = walk && walk->valid ? std::hypot(p[0] - walk->p[0], p[1] - walk->p[1], p[2] - walk->p[2]) : 0.0;
  for (std::size_t i = 0; i < 2; ++i) {
    geom::ClosestPoint c;
    bool done = false;
    if (walk && walk->valid) {
      c = dist_[i].closest(p, walk->uv[i], val[i]);
      // The distance is 1-Lipschitz: a warm answer farther than the previous distance plus the
      // step is certainly not the global minimum.
      done = c.converged && c.distance <= walk->d[i] + step + slack_;
      if (done) ++walk->warm;
    }
    if (!done) {
      c = dist_[i].closest(p);
      dist_[i].surface().eval(c.uv, val[i]);
      if (walk) ++walk->cold;
    }
    out.distance[i] = c.distance;
    out.uv[i] = c.uv;
  }
  out.alpha = shepard_weights(out.distance[0], out.distance[1], q_);
  for (int h = 0; h < m_; ++h) props[h] = out.alpha[0] * val[0][3 + h] + out.alpha[1] * val[1][3 + h];
  if (walk) {
    walk->valid = true;
    walk->p = p;
    walk->uv = out.uv;
    walk->d = out.distance;
  }
  return out;
}

// ---- encoding ----

}  // namespace trivox::vmodel
