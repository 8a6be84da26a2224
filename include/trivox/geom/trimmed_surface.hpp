/// @file trivox/geom/trimmed_surface.hpp
/// @brief Trimmed B-spline surfaces and their untrimming: tensor-product patches that cover the
/// trimmed surface exactly, with its area and property integrals.
///
/// A trimmed surface is a polynomial B-spline surface S(u, v) (coordinates 0..2 xyz, then any
/// properties) and closed trimming loops in its parameter rectangle, each a chain of planar
/// polynomial B-spline curves: outer loops counter-clockwise, holes clockwise inside them. The
/// trimmed domain D is the set of parameters of winding number 1.
///
/// Untrimming follows Massarwi & Elber 2016, Sec. 5.1: (1) tile D by quads with freeform sides
/// (the trimming curves among them) that lie in one Bezier piece of S each (the note closing
/// Sec. 5.1); (2) parametrise each quad by the Boolean sum of its four sides (the bilinearly
/// blended Coons patch, Cohen et al. 2001); (3) compose S with each quad map, q(s, t) ->
/// S(q(s, t)), giving tensor-product Bezier patches that tile S restricted to D.
///
/// The tiling is a slab (trapezoidal) decomposition whose sides are the monotone pieces of the
/// trimming curves (quads with freeform sides, Massarwi & Elber 2016, Sec. 5.1). Every trimming
/// curve is cut at its vertical tangents (roots of u'), at its crossings with the knot lines of
/// S in v and at its ends; the consecutive Bezier pieces between two such cuts (a marched
/// intersection curve has one per marched point) form one u-monotone side. The events are the
/// sides' ends and the knot lines of S in u: the slabs are cut at those vertical lines only, not
/// at every Bezier piece's end, so no slab is narrower than the distance between two real events
/// of the loops. Between two consecutive events every side spans the whole slab, and sides and
/// horizontal knot lines of S (domain edges included) do not cross inside it, so they are ordered
/// from bottom to top; a region between two neighbours whose winding number is 1 is a quad of D
/// whose left and right sides are vertical segments, possibly of zero length (a triangle-like
/// quad where the loop turns or has a corner).
///
/// Quad maps keep each curve's own (polynomial) parameter; no curve is refitted. With straight
/// sides the Boolean sum is the ruled map (1 - t) c_bottom(s) + t c_top(s). It is used with
/// vertical rulings only, which stay inside the slab region and never cross: q(s, t) =
/// (U(s), (1 - t) v_bottom(s) + t v_top(s)), where U is the bottom and top sides' common
/// u-polynomial. That holds when a side is a knot line or a straight edge (a line, parametrised
/// by the other side's u(s)) or when both curves have the same u-polynomials. Otherwise the
/// quad is split by a straight separator v = alpha + beta u through the midpoints of its left
/// and right sides, checked to lie between the two curves (signs of Bernstein coefficients, subdivided where needed); each half is then a ruled map between a
/// curve and the separator parametrised by that curve's u(s). Where no such separator exists
/// the slab is halved (up to `UntrimOptions::max_splits` times). Every quad map is polynomial
/// with a non-negative Jacobian determinant u_s (v_top - v_bottom): the patches keep the
/// orientation of S, and their interiors do not overlap.
///
/// Composition is exact up to rounding: q's coordinates are rescaled to the Bezier piece's
/// [0, 1]^2 and S's de Casteljau algorithm is run on bivariate Bernstein polynomials (products
/// of Bernstein forms), so the patch of a surface of degrees (p, q) over a quad map whose u has
/// degrees (a_s, a_t) and v (b_s, b_t) has degrees (p a_s + q b_s, p a_t + q b_t): for a
/// bicubic surface and cubic curves, (18, 3). A side of several Bezier pieces gives one patch of
/// as many knot spans in s (each the exact composition over its piece, joined with knots of
/// multiplicity equal to the degree), its knots at the pieces' shares of the curve's parameter.
///
/// Cost: O(E x I log I) for E events and I curve pieces and knot lines per slab, plus per patch
/// the composition, O(p q (deg_s deg_t) k) for k coordinates. Counts and orders are capped
/// (UntrimOptions) and refused beyond their limits.
#pragma once
#include <cstdint>
#include <vector>

#include "trivox/limits.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::geom {

/// A closed chain of planar curves (2 coordinates, u and v) in a surface's parameter space:
/// piece i ends where piece i + 1 starts, the last where the first starts.
struct TrimLoop {
  std::vector<spline::Curve> pieces;
};

/// A polynomial B-spline surface restricted to the parameters inside its trimming loops.
class TrimmedSurface {
public:
  /// @param surface    a polynomial (non-rational) B-spline surface with at least 3 coordinates
  /// @param loops      closed trimming loops in its parameter rectangle; outer loops
  ///                   counter-clockwise, holes clockwise; none: the whole rectangle
  /// @param tolerance  relative to the parameter rectangle's larger side (> 0, < 1e-3): the
  ///                   largest gap between consecutive pieces of a loop and the largest
  ///                   excursion outside the rectangle accepted; untrim merges events closer
  ///                   than this
  /// @param limits     orders and control points of the surface and of every curve
  /// @throws trivox::Error (bad_input) for a rational surface or curve, a curve that is not
  ///         planar, an empty loop, a loop that is not closed, a piece leaving the parameter
  ///         rectangle, loops crossing one another or themselves (checked on polylines within
  ///         1e-6 of the rectangle's size of the curves, trivox/geom/planar_crossing.hpp), a
  ///         loop enclosing no area, no counter-clockwise loop, or orders and counts over the
  ///         limits; messages name the loop and piece ("trimming loop 1, piece 2: ...")
  TrimmedSurface(spline::Surface surface, std::vector<TrimLoop> loops, double tolerance = 1e-10,
                 const Limits& limits = default_limits());

  const spline::Surface& surface() const noexcept { return surface_; }
  const std::vector<TrimLoop>& loops() const noexcept { return loops_; }
  /// The absolute tolerance in parameter units (the relative one times the larger side).
  double tolerance() const noexcept { return tolerance_; }
  /// Signed area of each loop in the parameter plane (positive: counter-clockwise), by Green's
  /// theorem with Gauss points exact for the polynomial integrand.
  const std::vector<double>& loop_areas() const noexcept { return loop_areas_; }

private:
  spline::Surface surface_;
  std::vector<TrimLoop> loops_;
  double tolerance_ = 0.0;
  std::vector<double> loop_areas_;
};

struct UntrimOptions {
  /// Refuse (trivox::Error, bad_input) before building more patches, or Bezier pieces (knot
  /// spans in s) of patches in all, than this.
  std::int64_t max_patches = 100'000;
  /// How often a slab may be halved to fit a separator between two curves; beyond it untrim
  /// fails (trivox::Error, failed: the curves touch or nearly so).
  int max_splits = 30;
  /// max_order bounds the patches' orders (refused beyond it, naming the orders).
  Limits limits = default_limits();
};

/// What untrim did.
struct UntrimReport {
  std::int64_t patches = 0;
  /// Largest |patch(s, t) - S(q(s, t))| over all coordinates at 5 x 5 points per patch.
  double max_composition_error = 0.0;
  /// True when every patch is the exact composition (up to rounding); always, since the
  /// inputs are polynomial and no curve is refitted.
  bool exact = true;
  int max_order_s = 0, max_order_t = 0;  ///< largest patch orders
  /// Bezier pieces (knot spans in s) over all patches, and the most in one patch.
  std::int64_t spans = 0;
  int max_spans = 0;
};

/// The untrimmed patches: patches[i] = S(domains[i](s, t)) on [0, 1]^2.
struct Untrimmed {
  /// Patches on [0, 1]^2 with the surface's coordinates: Bezier in t; in s one Bezier piece per
  /// piece of the quad's curved side (C0 knots), a Bezier patch where that side has one piece.
  std::vector<spline::Surface> patches;
  /// The quad maps q_i: [0, 1]^2 -> parameter plane (2 coordinates, with the patch's knots in s),
  /// s from left to right, t from bottom to top; their images tile the trimmed domain.
  std::vector<spline::Surface> domains;
  UntrimReport report;
};

/// Untrims `trimmed` (see the file comment).
/// @throws trivox::Error (bad_input) for overlapping loops or holes outside outer loops
///         (winding numbers other than 0 and 1, naming the loops), and for orders or counts
///         over the options' limits; (failed) when two curves cannot be separated
Untrimmed untrim(const TrimmedSurface& trimmed, const UntrimOptions& options = {});

/// The area of a polynomial surface's xyz image: int |S_u x S_v| du dv over every Bezier
/// element with (order + extra_points) Gauss points per direction (the integrand is a square
/// root, so not exact; converging fast where the surface is regular).
double surface_area(const spline::Surface& s, int extra_points = 8);

/// The integral of coordinate `coord` (3.. for properties) over the surface's area,
/// int f |S_u x S_v| du dv, with the same rule as surface_area.
double integrate_coordinate(const spline::Surface& s, int coord, int extra_points = 8);

/// The area of the trimmed surface: the sum of its untrimmed patches' areas.
double area(const Untrimmed& untrimmed);
double area(const TrimmedSurface& trimmed, const UntrimOptions& options = {});

/// The integral of coordinate `coord` over the trimmed surface (sum over the patches).
double integrate_coordinate(const Untrimmed& untrimmed, int coord);

}  // namespace trivox::geom
