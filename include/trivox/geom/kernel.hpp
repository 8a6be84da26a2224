/// @file trivox/geom/kernel.hpp
/// @brief Conservative kernels of closed loops of planar curves and of closed sets of surfaces:
/// a convex polygon (polyhedron) of points that see the whole boundary.
///
/// Hong & Elber 2022 (cited in Fadila et al. 2023, Secs. 2 and 5.1): a point K is in the kernel of
/// a closed boundary iff it lies on the inner side of every tangent line (plane). For a
/// counter-clockwise loop of curves C that is f_K(t) = C'(t) x (K - C(t)) >= 0 for all t; for
/// surfaces with outward normals n = S_u x S_v it is g_K(u,v) = n(u,v) . (K - S(u,v)) <= 0. Both
/// f_K and g_K are splines (derivative and product splines, spline/calculus.hpp) whose coefficients
/// are affine in K, so requiring every coefficient to have the right sign is a sufficient condition
/// (convex hull property): a finite set of half-planes (half-spaces) whose intersection lies inside
/// the true kernel. Refining f_K (g_K) replaces each coefficient by convex combinations of its
/// neighbours, so the conservative kernel only grows with `KernelOptions::refinements` and tends
/// to the true kernel. The half-planes (half-spaces) are intersected by clipping a box around the
/// input (its control points), one constraint after the other.
///
/// Orientation is found, not assumed: the signed area (1/2 sum of integral C x C') or signed
/// volume (1/3 sum of integral S . n) of the boundary is computed exactly from the same
/// coefficients, and the constraints are flipped when it is negative.
///
/// Cost: per curve of order p, one product spline of order 2p (O(p) coefficients per span, times
/// 2^refinements); per surface of orders (p, q), coefficients of orders about (3p-2, 3q-2) per
/// span. Clipping is O(constraints * vertices) in 2-D and O(constraints * polyhedron size) in 3-D.
#pragma once
#include <array>
#include <span>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::geom {

struct KernelOptions {
  /// Each step halves every knot span of f_K (g_K) before its coefficients become constraints:
  /// a tighter (never smaller) kernel for 2^refinements times as many constraints.
  int refinements = 2;
  /// How far a curve's end may be from the next curve's start (model units; planar loops).
  double join_tolerance = 1e-9;
};

/// A convex polygon inside the kernel of a closed planar loop.
struct PlanarKernel {
  /// Counter-clockwise vertices; empty when no kernel point was found.
  std::vector<std::array<double, 2>> vertices;
  double area = 0.0;
  /// The interior kernel point of Fadila et al. 2023, Alg. 1 (line 9): the polygon's centroid.
  std::array<double, 2> centroid{0.0, 0.0};
  /// +1 when the loop runs counter-clockwise, -1 clockwise (from its signed area).
  int orientation = 0;
  int constraints = 0;  ///< half-planes used (after dropping degenerate coefficients)

  bool empty() const noexcept { return vertices.size() < 3 || !(area > 0.0); }
};

/// A convex polyhedron inside the kernel of a closed set of surfaces.
struct SpatialKernel {
  /// The polyhedron's vertices (no particular order); empty when no kernel point was found.
  std::vector<std::array<double, 3>> vertices;
  /// Its faces, each a list of indices into `vertices`, counter-clockwise seen from outside.
  std::vector<std::vector<int>> faces;
  double volume = 0.0;
  std::array<double, 3> centroid{0.0, 0.0, 0.0};  ///< interior kernel point (Fadila et al. 2023, Alg. 1)
  /// +1 when the given normals point outward, -1 when they point inward (from the signed volume).
  int orientation = 0;
  int constraints = 0;  ///< half-spaces used

  bool empty() const noexcept { return vertices.size() < 4 || !(volume > 0.0); }
};

/// The conservative kernel of a closed loop of polynomial curves (coordinates 0 and 1 are x and
/// y; further coordinates are ignored), given in traversal order: curve i's end must be curve
/// i+1's start (the last joins the first), within `options.join_tolerance`. Either orientation.
/// @throws trivox::Error (bad_input) for fewer than one curve, a rational curve, fewer than 2
///         coordinates, a gap in the loop (naming the two curves and the distance) or a loop of
///         zero signed area
PlanarKernel planar_kernel(std::span<const spline::Curve> loop, const KernelOptions& options = {});

/// The four boundary curves of a planar surface as one loop: S(u, v0), S(u1, v), S(u, v1)
/// reversed, S(u0, v) reversed (counter-clockwise when det J > 0).
std::vector<spline::Curve> boundary_loop(const spline::Surface& s);

/// planar_kernel(boundary_loop(s)): the kernel of a planar surface's boundary (Fadila et al. 2023,
/// Sec. 5.1 uses the boundary of the regular construction S_0 as the kernel's input).
PlanarKernel planar_kernel(const spline::Surface& s, const KernelOptions& options = {});

/// The conservative kernel of a closed set of polynomial surfaces (coordinates 0..2 are xyz)
/// whose normals S_s x S_t all point outward or all inward. Degenerate faces (zero normal, such
/// as a face collapsed to an edge) contribute no constraint.
/// @throws trivox::Error (bad_input) for no surfaces, a rational surface, fewer than 3
///         coordinates or a set of zero signed volume
SpatialKernel spatial_kernel(std::span<const spline::Surface> faces, const KernelOptions& options = {});

/// The six boundary faces of a trivariate, each oriented (reversed in its first parameter where
/// needed) so that its normal points outward when det J > 0; inward otherwise. Faces in the
/// order u0 u1 v0 v1 w0 w1 (spline::Face).
std::vector<spline::Surface> oriented_boundary(const spline::Trivariate& t);

/// spatial_kernel(oriented_boundary(t)): the kernel of a trivariate's boundary.
SpatialKernel spatial_kernel(const spline::Trivariate& t, const KernelOptions& options = {});

/// The part of a kernel polygon where further affine constraints hold: {a, b, c} keeps the
/// points with a x + b y + c >= 0. Constraints with (a, b) = 0 keep everything when c >= 0 and
/// nothing otherwise. The result's `constraints` counts k's and the ones given; `orientation` is
/// k's. Used to pick the kernel point of Fadila et al. 2023, Alg. 1 more carefully (Sec. 7), where
/// det J's coefficients, affine in that point, give the constraints
/// (construct/kernel_construct.hpp).
PlanarKernel restrict_kernel(const PlanarKernel& k, std::span<const std::array<double, 3>> constraints);

/// The same for a kernel polyhedron: {a, b, c, d} keeps a x + b y + c z + d >= 0.
SpatialKernel restrict_kernel(const SpatialKernel& k, std::span<const std::array<double, 4>> constraints);

}  // namespace trivox::geom
