#include "trivox/fillet/ruled_fillet.hpp"

#include <string>
#include <vector>

#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet {

using spline::Surface;
using spline::Trivariate;

namespace {

/// s with coordinates padded by zeros up to dim.
Surface padded(const Surface& s, int dim) {
  std::vector<double> pts;
  pts.reserve(static_cast<std::size_t>(s.size() * dim));
  for (int i = 0; i < s.size(); ++i) {
    const auto p = s.point(i);
    pts.insert(pts.end(), p.begin(), p.end());
    pts.insert(pts.end(), static_cast<std::size_t>(dim - s.dim()), 0.0);
  }
  return Surface(s.knot_vectors(), dim, std::move(pts));
}

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
  const int k = sub1.dim();
  if (sub2.dim() != k)
    throw Error("ruled fillet: the sub-regions have " + std::to_string(k) + " and " + std::to_string(sub2.dim()) +
                " coordinates; expected the same (xyz and the same properties)");
  if (k < 3) throw Error("ruled fillet: sub-regions need at least 3 coordinates (xyz)");
  if (blend.dim() != 3 && blend.dim() != k)
    throw Error("ruled fillet: the blending surface has " + std::to_string(blend.dim()) +
                " coordinates; expected 3 or " + std::to_string(k));
  if (sub1.rational() || sub2.rational() || blend.rational())
    throw Error("ruled fillet: rational surfaces; expected polynomial ones");
  const bool blend_properties = blend.dim() == 3 && k > 3;
  const Surface parts[3] = {sub1, sub2, blend.dim() == k ? blend : padded(blend, k)};
  std::vector<Surface> c = construct::common_space<2>(parts);
  Surface &s1 = c[0], &s2 = c[1], &b = c[2];
  const int nu = b.count(0), nv = b.count(1);
  if (blend_properties) {
    // Seed 000 Sec. 7.1: g_b = sum ((1 - a_r) p1_{m,r} + a_r p2_{m,r}) B_{m,r}, a_r = r / (n_v - 1).
    for (int r = 0; r < nv; ++r) {
      const double a = nv > 1 ? static_cast<double>(r) / (nv - 1) : 0.0;
      for (int m = 0; m < nu; ++m) {
        const int row = b.row({m, r});
        auto out = b.point(row);
        const auto p1 = s1.point(row), p2 = s2.point(row);
        for (int j = 3; j < k; ++j)
          out[static_cast<std::size_t>(j)] = (1.0 - a) * p1[static_cast<std::size_t>(j)] + a * p2[static_cast<std::size_t>(j)];
      }
    }
  }
  // S^_1(u, 1) and S^_2(u, 0) are both C (from each surface, equal to the rails' tolerance):
  // one curve, so the halves glue exactly.
  for (int m = 0; m < nu; ++m) {
    auto p = s1.point(s1.row({m, nv - 1}));
    auto q = s2.point(s2.row({m, 0}));
    for (int j = 0; j < 3; ++j) {
      const double mid = 0.5 * (p[static_cast<std::size_t>(j)] + q[static_cast<std::size_t>(j)]);
      p[static_cast<std::size_t>(j)] = q[static_cast<std::size_t>(j)] = mid;
    }
  }
  auto [b1, b2] = spline::split(b, 1, 0.5);
  std::array<Trivariate, 2> halves{construct::ruled(s1, spline::reparametrize(b1, 1, 0.0, 1.0)),
                                   construct::ruled(s2, spline::reparametrize(b2, 1, 0.0, 1.0))};
  if (det_at_centre(halves[0]) < 0.0)
    for (auto& h : halves) h = spline::reverse(h, 0);
  return halves;
}

}  // namespace trivox::fillet
