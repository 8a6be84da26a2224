// Surfaces shared by the surface-intersection tests: a bilinear plane patch and the unit sphere
// as a revolved half circle (rational, exact to 1e-11).
#pragma once
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include "trivox/construct/constructors.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::test {

/// The parallelogram o + s e1 + t e2, s, t in [0, 1].
inline spline::Surface plane_patch(std::array<double, 3> o, std::array<double, 3> e1, std::array<double, 3> e2) {
  std::vector<double> pts;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i)
      for (std::size_t d = 0; d < 3; ++d) pts.push_back(o[d] + i * e1[d] + j * e2[d]);
  return spline::Surface({spline::KnotVector::bezier(2), spline::KnotVector::bezier(2)}, 3, pts);
}

/// Half circle from the north to the south pole in the xz-plane, revolved about z.
inline spline::Surface unit_sphere() {
  const auto arc = construct::circle_arc(M_PI, 1e-11);
  std::vector<double> pts;
  for (int i = 0; i < arc.size(); ++i) pts.insert(pts.end(), {arc.point(i)[1], 0.0, arc.point(i)[0]});
  construct::Revolution r;
  r.relative_tolerance = 1e-11;
  return construct::revolve(spline::Curve(arc.knot_vectors(), 3, pts), r);
}

}  // namespace trivox::test
