/// @file trivox/fillet/compose.hpp
/// @brief Functional composition of a surface with a curve or a surface in its parameter space,
/// and the fillet sub-regions S^_i of the primary surfaces built with it.
///
/// Masalha, Cirillo & Elber 2021, Sec. 1.5, Eqs. 2-3: the part of S_i between the
/// intersection curve and the rail is S^_i(u, v) = S_i(Rld(c_a(u), c_b(u))(v)), the image of the
/// ruled surface between the two curves in S_i's parameter space. When that ruled surface stays
/// inside one polynomial piece of S_i, the composition is a tensor-product spline: for a piece of
/// degrees (p, q) and a map r of degrees (m_u, m_v), S(r) has degree (p + q) m per direction and
/// keeps the continuity of r at r's knots. It is computed here exactly (up to rounding) by
/// collocation in that space at its Greville points: S(r) lies in the space, so the interpolant
/// is the composition itself. Where the region crosses knot lines of S_i (B-spline surfaces "in
/// general position", Sec. 1.5 and 4.3) the composition is no spline of this kind and the
/// sub-region is instead fitted by least squares with its two boundary curves pinned (Sec. 4.3).
///
/// Cost: exact: one surface evaluation per control point of the result (about (p+q+1) x
/// (p+q) m per span of r); fit: a few thousand evaluations per round and one banded
/// least-squares solve (spline/fit.hpp), rounds doubling the knots until within tolerance.
#pragma once
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet {

/// C(t) = s(c(t)): a curve in s's parameter space mapped onto s (all of s's coordinates).
/// Exact when c stays within one polynomial piece of s.
/// @throws Error (bad_input) for a rational s or c, c not in R^2, or c leaving s's domain or
///         crossing one of s's interior knot lines (check with crosses_knot_lines)
spline::Curve compose(const spline::Surface& s, const spline::Curve& c);

/// S(u, v) = s(r(u, v)), r a polynomial surface in R^2 inside s's parameter domain; exact when r
/// stays within one polynomial piece of s. Same errors as the curve version.
spline::Surface compose(const spline::Surface& s, const spline::Surface& r);

/// True when the control box of c or r (which contains its image) reaches strictly across an
/// interior knot line of s: the composition is then no tensor-product spline.
bool crosses_knot_lines(const spline::Surface& s, const spline::Curve& c);
bool crosses_knot_lines(const spline::Surface& s, const spline::Surface& r);

enum class SubregionMethod {
  compose,    ///< exact composition; refused where the region crosses knot lines of s
  fit,        ///< least-squares fit with pinned boundaries (Masalha et al. 2021, Sec. 4.3)
  automatic,  ///< compose where possible, else fit; fillet_faces tries `matched` first
  /// fillet_faces: B-spline faces whose knot lines C crosses, as matched Bezier pairs composed
  /// exactly (Masalha et al. 2021, Alg. 4-5, fillet/matched.hpp); subregion() treats it as compose
  matched,
};

/// "compose", "fit", "auto", "matched".
const char* subregion_method_name(SubregionMethod m) noexcept;
/// The method called `name`, or false.
bool subregion_method_from_name(const char* name, SubregionMethod& out) noexcept;

struct SubregionOptions {
  SubregionMethod method = SubregionMethod::automatic;
  /// Fit: largest distance (coordinates 0..2, model units) between the fitted sub-region and
  /// s(Rld) at check points between the data, > 0. Properties are fitted in the same space.
  double tolerance = 1e-6;
  int max_rounds = 8;  ///< fit: knot doublings before giving up (Error failed)
};

/// What subregion() did.
struct SubregionReport {
  bool composed = false;   ///< exact composition (else fitted)
  double fit_error = 0.0;  ///< fit: largest xyz distance found at the check points
};

/// S^(u, v) = s((1 - v) from(u) + v to(u)) (Masalha et al. 2021 Eqs. 2-3), u along the curves, v
/// from `from` (v = 0) to `to` (v = 1). The curves are in s's parameter space and in one function
/// space (same order and knots). A fit keeps its two boundaries exactly on s(from) and s(to) as
/// fitted curves: S^(u, 0) and S^(u, 1) are themselves least-squares curves of those images.
/// @throws Error (bad_input) for curves outside s's domain or in different spaces, or for
///         SubregionMethod::compose on a region that crosses knot lines (the message says so and
///         names "fit"); Error (failed) when the fit does not reach the tolerance
spline::Surface subregion(const spline::Surface& s, const spline::Curve& from, const spline::Curve& to,
                          const SubregionOptions& options = {}, SubregionReport* report = nullptr);

}  // namespace trivox::fillet
