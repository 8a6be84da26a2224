/// @file trivox/spline/extract.hpp
/// @brief Lower-dimensional pieces of a spline: iso-curves and iso-surfaces, the six boundary
/// faces of a trivariate, and bounding boxes.
///
/// An iso-parametric piece at t in direction d contracts the control net along d with the basis
/// values at t (exact; rational splines in homogeneous coordinates). Cost: O(size * order_d).
#pragma once
#include <array>
#include <string_view>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::spline {

/// The spline with direction `dir` fixed at t: a surface of a trivariate, a curve of a surface,
/// keeping the other directions in their order.
/// @throws Error when t is outside the domain of dir
template <int P>
TensorSpline<P - 1> iso(const TensorSpline<P>& s, int dir, double t);

/// The iso-curve of a trivariate along direction `dir` through the fixed values of the two
/// other parameters (`fixed` holds the three parameters; the entry of dir is ignored).
Curve iso_curve(const Trivariate& s, int dir, const std::array<double, 3>& fixed);

/// The six faces of a trivariate, named as in the model format.
enum class Face { u0, u1, v0, v1, w0, w1 };
inline constexpr std::array<Face, 6> all_faces{Face::u0, Face::u1, Face::v0, Face::v1, Face::w0, Face::w1};
std::string_view face_name(Face f);
/// @throws Error when `name` is not one of u0 u1 v0 v1 w0 w1
Face face_from_name(std::string_view name);

/// The boundary face of a trivariate: direction (u for u0/u1, ...) at its domain's minimum (0) or
/// maximum (1); the surface's parameters are the two other directions in order.
Surface boundary_face(const Trivariate& s, Face f);

/// Axis-aligned box {min, max} of the first `coords` coordinates (all when -1), from the control
/// points of the Bezier pieces: tighter than the control net, still conservative.
template <int P>
std::array<std::vector<double>, 2> bounding_box(const TensorSpline<P>& s, int coords = -1);

}  // namespace trivox::spline
