/// @file src/slice/mat3.hpp
/// @brief (private to src/slice) Three-vectors and 3 x 3 matrices: dot product and norm of
/// three doubles, the inverse of a matrix given by its columns (as rows), and a matrix (rows)
/// times a vector. Inline: Newton, the sampler's anchors and its warm starts call them per
/// iteration or per voxel.
#pragma once
#include <array>
#include <cmath>
#include <cstddef>

#include "trivox/slice/locator.hpp"

namespace trivox::slice::detail {

/// Dot product and Euclidean norm of three doubles.
inline double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm3(const double* a) { return std::sqrt(dot3(a, a)); }

/// The inverse of J (given by columns), as rows; false when singular.
inline bool invert(const std::array<Vec3, 3>& J, std::array<Vec3, 3>& inv) {
  auto cross = [](const Vec3& a, const Vec3& b) {
    return Vec3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  const Vec3 c0 = cross(J[1], J[2]), c1 = cross(J[2], J[0]), c2 = cross(J[0], J[1]);
  const double det = J[0][0] * c0[0] + J[0][1] * c0[1] + J[0][2] * c0[2];
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return false;
  for (std::size_t k = 0; k < 3; ++k) {
    inv[0][k] = c0[k] / det;
    inv[1][k] = c1[k] / det;
    inv[2][k] = c2[k] / det;
  }
  return true;
}

/// rows times v.
inline Vec3 mul(const std::array<Vec3, 3>& rows, const Vec3& v) {
  return {rows[0][0] * v[0] + rows[0][1] * v[1] + rows[0][2] * v[2], rows[1][0] * v[0] + rows[1][1] * v[1] + rows[1][2] * v[2],
          rows[2][0] * v[0] + rows[2][1] * v[1] + rows[2][2] * v[2]};
}

}  // namespace trivox::slice::detail
