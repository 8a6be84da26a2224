/// @file src/fillet/corner_seam.cpp
/// @brief A convex corner's gap across a seam (Masalha et al. 2021, Sec. 6.1, Fig. 12 (d): p
/// and q on two faces of the smooth body joined G1): where B_d, the sphere of radius d about the
/// corner o on the arriving piece's face, crosses that face's boundaries through o. fillet_across
/// keeps the crossing nearest the other face as the seam point s and splits the bridge there.
///
/// Cost: per boundary iso-curve through o one derivative evaluation and a regula falsi (Illinois)
/// of up to 200 surface evaluations.
#include <cmath>

#include "corner_util.hpp"
#include "fillet_util.hpp"

namespace trivox::fillet::detail {

using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using spline::Trivariate;

std::vector<std::array<double, 2>> seam_crossings(const Surface& s, const std::array<double, 2>& o_uv, const Vec& o,
                                                  const Vec& into, double d) {
  std::vector<std::array<double, 2>> found;
  const std::array<std::array<double, 2>, 2> dom{s.domain(0), s.domain(1)};
  const std::size_t k = static_cast<std::size_t>(s.dim());
  for (std::size_t fix = 0; fix < 2; ++fix)
    for (const double edge : dom[fix]) {
      if (std::abs(o_uv[fix] - edge) > 1e-9 * (dom[fix][1] - dom[fix][0])) continue;
      const std::size_t fr = 1 - fix;
      const auto uv_at = [&](double t) {
        std::array<double, 2> uv{};
        uv[fix] = edge;
        uv[fr] = t;
        return uv;
      };
      const auto e = s.eval_derivatives({uv_at(o_uv[fr])[0], uv_at(o_uv[fr])[1]}, 1);
      const double run = dot(xyz(e.data() + (fr == 0 ? k : 2 * k)), into);
      if (!(std::abs(run) > 0.0)) continue;
      const double end = run > 0.0 ? dom[fr][1] : dom[fr][0];
      const auto g = [&](double t) { return norm(sub(point_at(s, uv_at(t)), o)) - d; };
      double a = o_uv[fr], b = end, ga = g(a), gb = g(b);
      if (!(gb >= 0.0)) continue;  // the boundary ends inside the sphere
      for (int it = 0; it < 200 && std::abs(b - a) > 1e-15 * (1.0 + std::abs(a)) && ga != 0.0 && gb != 0.0; ++it) {
        double m = a - ga * (b - a) / (gb - ga);  // Illinois
        if (!(m > std::min(a, b) && m < std::max(a, b))) m = 0.5 * (a + b);
        const double gm = g(m);
        if (gm == 0.0) a = b = m;
        else if ((gm < 0.0) == (ga < 0.0)) a = m, ga = gm, gb *= 0.5;
        else b = m, gb = gm, ga *= 0.5;
      }
      const double t = std::abs(ga) <= std::abs(gb) ? a : b;
      if (dot(sub(point_at(s, uv_at(t)), o), into) > 0.0) found.push_back(uv_at(t));
    }
  return found;
}

}  // namespace trivox::fillet::detail
