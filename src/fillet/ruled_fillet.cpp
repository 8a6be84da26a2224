#include "trivox/fillet/ruled_fillet.hpp"

#include <string>
#include <vector>

#include "property_blend.hpp"
#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet {

using spline::Surface;
using spline::Trivariate;

namespace {

double det_at_centre(const Trivariate& t) {
  const auto d = t.eval_derivatives({0.5, 0.5, 0.5}, 1);
  const std::size_t k = static_cast<std::size_t>(t.dim());
  const double* a = d.data() + k;
  const double* b = d.data() + 2 * k;
  const double* c = d.data() + 3 * k;
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
}

}  // namespace

std::array<Trivariate, 2> ruled_fillet(const Surface& sub1, const Surface& sub2, const Surface& blend) {
  auto [s1, s2, b] = detail::fillet_common_space(sub1, sub2, blend, "ruled fillet");
  // S^_1(u, 1) and S^_2(u, 0) are both C (from each surface, equal to the rails' tolerance):
  // one curve, so the halves glue exactly.
  detail::join_at_c(s1, s2);
  auto [b1, b2] = spline::split(b, 1, 0.5);
  std::array<Trivariate, 2> halves{construct::ruled(s1, spline::reparametrize(b1, 1, 0.0, 1.0)),
                                   construct::ruled(s2, spline::reparametrize(b2, 1, 0.0, 1.0))};
  if (det_at_centre(halves[0]) < 0.0)
    for (auto& h : halves) h = spline::reverse(h, 0);
  return halves;
}

}  // namespace trivox::fillet
