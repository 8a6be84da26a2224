#include "trivox/fillet/ruled_fillet.hpp"

#include <string>
#include <vector>

#include "property_blend.hpp"
#include "trivox/construct/constructors.hpp"
#include "fillet_util.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet {

using spline::Surface;
using spline::Trivariate;

std::array<Trivariate, 2> ruled_fillet(const Surface& sub1, const Surface& sub2, const Surface& blend) {
  auto [s1, s2, b] = detail::fillet_common_space(sub1, sub2, blend, "ruled fillet");
  // S^_1(u, 1) and S^_2(u, 0) are both C (from each surface, equal to the rails' tolerance):
  // one curve, so the halves glue exactly.
  detail::join_at_c(s1, s2);
  auto [b1, b2] = spline::split(b, 1, 0.5);
  std::array<Trivariate, 2> halves{construct::ruled(s1, spline::reparametrize(b1, 1, 0.0, 1.0)),
                                   construct::ruled(s2, spline::reparametrize(b2, 1, 0.0, 1.0))};
  if (detail::jacobian_at(halves[0], {0.5, 0.5, 0.5}) < 0.0)
    for (auto& h : halves) h = spline::reverse(h, 0);
  return halves;
}

}  // namespace trivox::fillet
