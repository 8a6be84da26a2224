/// @file trivox/construct/primitives.hpp
/// @brief The non-singular primitives of Massarwi & Elber 2016, Sec. 3.2.3, Fig. 9:
/// a box, and a cylinder, cone, torus and sphere made of several polynomial cells, none of which
/// has a vanishing Jacobian; and the property fields that colour them.
///
/// A tensor-product trivariate cylinder or sphere is singular on its axis or at its poles
/// (Massarwi & Elber 2016, Fig. 8). The primitives avoid that by splitting the solid into cells
/// glued C0 along shared faces (Sec. 3.2.3):
///
///  - a *5-cell disk*: a central square of half-width 0.5 r and four cells ruled between the
///    square's sides and quarter circles (Fig. 9 (a)-(c)); the cylinder extrudes it along the
///    axis, the cone rules the bottom disk to the top disk, the torus revolves it about the axis
///    (construct::extrude, ruled, revolve of Sec. 3.2.2);
///  - the *7-cell ball*: an inner cube of half-width 0.45 r and six cells ruled between each cube
///    face and the sixth of the sphere above it (Fig. 9 (d)).
///
/// The circle and the sphere are not polynomial: each quarter circle is the cubic interpolant
/// of the circle, uniform in angle, and each sixth of the sphere the bicubic interpolant of the
/// equiangular cube map (the direction (1, tan(pi/4 s), tan(pi/4 t)) over the cube face), on
/// uniform knots doubled until the largest distance from the exact circle (sphere), sampled
/// densely, is below half of `relative_tolerance * r`. The square's side (the cube face) is
/// linear in the same parameters, and each ruling joins the points of equal parameter.
/// Every cell of a primitive is then polynomial (no weights), right-handed (det J > 0), and the
/// cells that share a face hold it in the same function space with bit-identical control points
/// (the parts are exact images of one another under quarter turns and mirror symmetries), so
/// vmodel::build_topology glues them and a property field is continuous across them.
///
/// Part names and parameter directions (cells are named `<name>.<part>`, in this order):
///
///  - box: `box` (one trilinear cell); u, v, w along x, y, z.
///  - cylinder and cone: `core`, `x0`, `x1`, `y0`, `y1`. The cross-section frame is (e1, e2, n):
///    n = axis / |axis|; e1 = the coordinate axis least aligned with n (x before y before z on a
///    tie) made orthogonal to n; e2 = n x e1. For axis (0,0,1) that is e1 = x, e2 = y. `core` is
///    the square, u along e1, v along e2; `x1` lies on the +e1 side, `x0` on -e1, `y1` on +e2,
///    `y0` on -e2; in each of them u runs radially outward (u0 glued to the core, u1 on the
///    curved boundary) and v counter-clockwise about n (v0, v1 glued to the neighbours). In all
///    five, w runs along n from the base (w0) to the top (w1).
///  - torus: `core`, `bottom`, `top`, `inner`, `outer`: the 5-cell disk of radius `minor` in the
///    half-plane through e1 (frame as above, about `axis`), its local x along n and y along e1
///    (so `bottom` is the -n side, `top` +n, `inner` faces the axis and `outer` away from it);
///    u, v as for the cylinder's parts in that (n, e1) frame, w the revolution about n, a full
///    turn from the half-plane through e1 (w0) back to it (w1). A full ring is closed onto
///    itself, so each cell's w0 and w1 faces coincide (vmodel keeps them as two boundary
///    V-surfaces: a cell is never glued to itself).
///  - sphere: `core`, `x0`, `x1`, `y0`, `y1`, `z0`, `z1`: the cube (u, v, w along x, y, z) and
///    the six caps, `x1` on +x ... `z0` on -z; in each cap w runs radially outward (w0 glued to
///    the cube, w1 on the sphere) and (u, v) across the cap, right-handed about the outward
///    normal: for `x1`, u along +y and v along +z; the other caps are the images of `x1` under
///    the rotations (x,y,z) -> (-x,-y,z) [x0], (-y,x,z) [y1], (y,-x,z) [y0], (-z,y,x) [z1],
///    (z,y,-x) [z0].
///
/// Cost: the arcs and caps cost O(segments^2) small solves; a primitive of the default tolerance
/// is 5-7 cells of at most a few thousand control points, built in milliseconds.
#pragma once
#include <array>
#include <string>
#include <variant>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::construct {

using Vec3 = std::array<double, 3>;

/// An axis-aligned box [min, max] (min < max in every coordinate).
struct Box {
  Vec3 min{0, 0, 0}, max{1, 1, 1};
};
/// A solid cylinder: the disk of `radius` about `base`, perpendicular to `axis` (any non-zero
/// length), swept `height` along the unit axis.
struct Cylinder {
  Vec3 base{0, 0, 0}, axis{0, 0, 1};
  double radius = 1, height = 1;
};
/// A solid frustum of a cone: `radius` at `base`, `top_radius` at base + height * unit axis.
/// top_radius must be positive: an apex is a singular point (every cell touching it would have
/// a vanishing Jacobian there), so a full cone is refused; use a small top radius instead.
struct Cone {
  Vec3 base{0, 0, 0}, axis{0, 0, 1};
  double radius = 1, top_radius = 0.5, height = 1;
};
/// A solid torus: the disk of radius `minor` whose centre runs on the circle of radius `major`
/// about `center`, perpendicular to `axis`. major > minor (else the tube reaches the axis).
struct Torus {
  Vec3 center{0, 0, 0}, axis{0, 0, 1};
  double major = 2, minor = 1;
};
/// A solid ball.
struct Sphere {
  Vec3 center{0, 0, 0};
  double radius = 1;
};

using Primitive = std::variant<Box, Cylinder, Cone, Torus, Sphere>;

/// "box", "cylinder", "cone", "torus", "sphere".
const char* primitive_type(const Primitive& p) noexcept;

/// One cell of a primitive: its full name `<name>.<part>` (the box: `<name>` alone) and its
/// trivariate, xyz only (dim 3) until a field is applied.
struct PrimitiveCell {
  std::string name;
  spline::Trivariate volume;
};

struct PrimitiveOptions {
  /// Largest distance of the boundary from the exact circle or sphere, relative to
  /// characteristic_radius(). In [1e-8, 0.01] (finer would need thousands of spans). The default keeps the
  /// boundary within 2e-4 r (5 times inside the 1e-3 r the primitives promise) with 2-4 cubic
  /// spans per quarter circle; every halving of it costs about 1.2 times more spans per direction.
  double relative_tolerance = 2e-4;
};

/// The cells of primitive `p`, named `<name>.<part>` as in the file comment.
/// @throws trivox::Error (bad_input) naming the parameter and what was expected, for a zero or
///         negative radius or height, a zero axis, min >= max, major <= minor, top_radius <= 0,
///         a non-finite value or a tolerance out of range
std::vector<PrimitiveCell> build_primitive(const std::string& name, const Primitive& p,
                                           const PrimitiveOptions& options = {});

/// Checks p's parameters as build_primitive does (the same messages), without building.
void check_primitive(const Primitive& p);

/// The exact volume of the solid: (max - min) products, pi r^2 h, the frustum
/// pi h (r^2 + r r_t + r_t^2) / 3, 2 pi^2 R r^2, 4/3 pi r^3.
double exact_volume(const Primitive& p);

/// The distance from x to the exact boundary surface of the solid (for tests and reports).
double boundary_distance(const Primitive& p, const Vec3& x);

/// The radius the primitive's tolerance is relative to: the sphere's and cylinder's radius,
/// the cone's larger radius, the torus's minor radius (box: half its smallest side).
double characteristic_radius(const Primitive& p);

// ---------------------------------------------------------------------------------------------
// Property fields

/// The same values everywhere (one per property).
struct ConstantField {
  std::vector<double> values;
};
/// Values interpolated linearly along the segment from -> to: v0 at the plane through `from`
/// perpendicular to (to - from), v1 at the plane through `to`, and *clamped* beyond them (v0
/// before `from`, v1 past `to`), so that colours and material fractions stay in range.
struct LinearField {
  Vec3 from{0, 0, 0}, to{1, 0, 0};
  std::vector<double> v0, v1;
};
/// Values linear in the distance d from `center`: v_centre at d = 0, v_radius at d = radius,
/// clamped (v_radius) beyond.
struct RadialField {
  Vec3 center{0, 0, 0};
  double radius = 1;
  std::vector<double> v_centre, v_radius;
};

using Field = std::variant<ConstantField, LinearField, RadialField>;

/// The exact field at point x (one value per property).
std::vector<double> field_value(const Field& f, const Vec3& x);

/// Number of properties the field carries.
int field_size(const Field& f) noexcept;

struct FieldOptions {
  /// Largest error at any point of the cells, relative to the field's range (per property,
  /// |v1 - v0|), that refinement aims for: 1/512, a quarter of an 8-bit grey level.
  double relative_tolerance = 1.0 / 512.0;
  /// Uniform refinements (every knot span halved in every direction) tried at most.
  int max_refinements = 2;
  /// No refinement that would give the cells more control points than this in total (each
  /// multiplies them by about 8; the slicer and validity checks pay for every one).
  long max_control_points = 60000;
};

/// How well the properties follow the exact field.
struct FieldReport {
  /// True when the spline field equals the exact field everywhere (constant fields; linear
  /// fields whose clamping planes do not cut the cells: an affine function of xyz set on the
  /// control points is reproduced exactly, since the cell map is a polynomial spline and the
  /// B-spline basis is a partition of unity).
  bool exact = false;
  /// Largest error seen on a dense sample of every cell, relative to the range (0 when exact).
  double max_error = 0.0;
  int refinements = 0;     ///< uniform refinements applied to reach the tolerance
  bool converged = true;   ///< max_error <= relative_tolerance (or exact)
};

/// Appends the field's values to every control point of `cells` (coordinates 3.., after xyz;
/// the cells must have dim 3 and come from one primitive, so their shared faces share function
/// spaces). Exact fields are set on the control points. Others (a radial field, or a linear one
/// clamped inside the cells) are interpolated at the Greville abscissae of each cell: the order
/// of every direction is first raised to at least 4, then all cells are refined uniformly (the
/// same knots on both sides of every shared face, so the field stays continuous) until the
/// sampled error is below options.relative_tolerance or max_refinements (or the control-point
/// budget) is reached. Near a kink
/// of the exact field (the centre of a radial field, a clamping plane or sphere inside a cell)
/// a polynomial cannot follow it: the error there is about the slope times a knot span, and is
/// what max_error reports.
/// @throws trivox::Error (bad_input) for a field with inconsistent value counts, a zero-length
///         linear segment, a radius <= 0 or non-finite values
FieldReport apply_field(std::vector<PrimitiveCell>& cells, const Field& f, const FieldOptions& options = {});

/// Checks the field's parameters as apply_field does.
/// @param properties  the number of properties it must carry
void check_field(const Field& f, int properties);

}  // namespace trivox::construct
