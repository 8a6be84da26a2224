/// @file src/fillet/property_blend.hpp
/// @brief Internal: the inputs of a volumetric fillet (S^_1, S^_2, S_b) checked and brought into
/// one function space, S_b given the property function g_b of Masalha et al. 2021, Sec. 7.1, and
/// the two copies of C (S^_1(u, 1), S^_2(u, 0)) joined into one curve. Shared by the ruled fillet
/// (Alg. 2) and the volumetric-Boolean-sum fillet (Alg. 3).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet::detail {

/// sub1, sub2 and blend (padded to R^k when in R^3) in one function space per direction, each
/// normalized to [0, 1]^2. When blend is in R^3 and k > 3, its properties become
/// g_b = sum ((1 - a_r) p1_{m,r} + a_r p2_{m,r}) B_{m,r}, a_r = r / (n_v - 1) (Sec. 7.1), so
/// g_b = g_1 on rail 1 (r = 0) and g_2 on rail 2 (r = n_v - 1).
/// @param what  the operation, prefixing the error messages ("ruled fillet")
/// @throws Error (bad_input) for sub-regions of different dimensions or fewer than 3
///         coordinates, rational inputs, or a blend in neither R^3 nor R^k
inline std::array<spline::Surface, 3> fillet_common_space(const spline::Surface& sub1,
                                                          const spline::Surface& sub2,
                                                          const spline::Surface& blend, const char* what) {
  using spline::Surface;
  const std::string op(what);
  const int k = sub1.dim();
  if (sub2.dim() != k)
    throw Error(op + ": the sub-regions have " + std::to_string(k) + " and " + std::to_string(sub2.dim()) +
                " coordinates; expected the same (xyz and the same properties)");
  if (k < 3) throw Error(op + ": sub-regions need at least 3 coordinates (xyz)");
  if (blend.dim() != 3 && blend.dim() != k)
    throw Error(op + ": the blending surface has " + std::to_string(blend.dim()) + " coordinates; expected 3 or " +
                std::to_string(k));
  if (sub1.rational() || sub2.rational() || blend.rational())
    throw Error(op + ": rational surfaces; expected polynomial ones");
  const bool blend_properties = blend.dim() == 3 && k > 3;
  Surface padded = blend;
  if (blend.dim() != k) {
    std::vector<double> pts;
    pts.reserve(static_cast<std::size_t>(blend.size() * k));
    for (int i = 0; i < blend.size(); ++i) {
      const auto p = blend.point(i);
      pts.insert(pts.end(), p.begin(), p.end());
      pts.insert(pts.end(), static_cast<std::size_t>(k - blend.dim()), 0.0);
    }
    padded = Surface(blend.knot_vectors(), k, std::move(pts));
  }
  const Surface parts[3] = {sub1, sub2, padded};
  std::vector<Surface> c = construct::common_space<2>(parts);
  Surface &s1 = c[0], &s2 = c[1], &b = c[2];
  const int nu = b.count(0), nv = b.count(1);
  if (blend_properties) {
    // Masalha et al. 2021, Sec. 7.1: g_b = sum ((1 - a_r) p1_{m,r} + a_r p2_{m,r})
    // B_{m,r}, a_r = r / (n_v - 1).
    for (int r = 0; r < nv; ++r) {
      const double a = nv > 1 ? static_cast<double>(r) / (nv - 1) : 0.0;
      for (int m = 0; m < nu; ++m) {
        const int row = b.row({m, r});
        auto out = b.point(row);
        const auto p1 = s1.point(row), p2 = s2.point(row);
        for (std::size_t j = 3; j < static_cast<std::size_t>(k); ++j) out[j] = (1.0 - a) * p1[j] + a * p2[j];
      }
    }
  }
  return {std::move(s1), std::move(s2), std::move(b)};
}

/// Joins C: the xyz of S^_1's last row in v and S^_2's first row (both C, from each surface)
/// become their mean, bit-identical in both; properties are left to each surface.
/// @return the largest xyz distance between the two rows before the join
inline double join_at_c(spline::Surface& s1, spline::Surface& s2) {
  const int nu = s1.count(0), nv = s1.count(1);
  double gap = 0.0;
  for (int m = 0; m < nu; ++m) {
    auto p = s1.point(s1.row({m, nv - 1}));
    auto q = s2.point(s2.row({m, 0}));
    double d2 = 0.0;
    for (std::size_t j = 0; j < 3; ++j) {
      const double d = p[j] - q[j];
      d2 += d * d;
      p[j] = q[j] = 0.5 * (p[j] + q[j]);
    }
    gap = std::max(gap, std::sqrt(d2));
  }
  return gap;
}

}  // namespace trivox::fillet::detail
