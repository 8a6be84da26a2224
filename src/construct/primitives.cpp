#include "trivox/construct/primitives.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/fit.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::construct {

using spline::KnotVector;

namespace {

constexpr double pi = 3.141592653589793;
/// Square (cube) half-width relative to the radius: the rulings from the square's corners to the
/// circle are then 0.29 r long against 0.5 r at the sides (disk), 0.22 r against 0.55 r (ball),
/// so det J varies by a modest factor across a cell.
constexpr double disk_core = 0.5;
constexpr double ball_core = 0.45;

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

// ---------------------------------------------------------------------------------------------
// Vectors

Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// ---------------------------------------------------------------------------------------------
// Parameter checks: "<type> <parameter> <value>; expected ..."

void need_finite(const char* type, const char* what, const Vec3& v) {
  for (double x : v)
    if (!std::isfinite(x))
      throw Error(std::string(type) + " " + what + " (" + num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]) +
                  ") is not finite; expected three finite numbers");
}
void need_positive(const char* type, const char* what, double v) {
  if (!(v > 0.0) || !std::isfinite(v))
    throw Error(std::string(type) + " " + what + " " + num(v) + "; expected a positive finite number");
}
Vec3 unit_axis(const char* type, const Vec3& axis) {
  need_finite(type, "axis", axis);
  const double l = norm(axis);
  if (!(l > 0.0) || !std::isfinite(l))
    throw Error(std::string(type) + " axis (" + num(axis[0]) + ", " + num(axis[1]) + ", " + num(axis[2]) +
                ") has zero length; expected a non-zero direction");
  return scale(axis, 1.0 / l);
}

/// (e1, e2) with (e1, e2, n) right-handed: e1 the coordinate axis least aligned with n, made
/// orthogonal to it (ties: x before y before z), so that the z axis gives e1 = x, e2 = y.
std::array<Vec3, 2> frame(const Vec3& n) {
  int best = 0;
  for (int c = 1; c < 3; ++c)
    if (std::abs(n[static_cast<std::size_t>(c)]) < std::abs(n[static_cast<std::size_t>(best)])) best = c;
  Vec3 h{0, 0, 0};
  h[static_cast<std::size_t>(best)] = 1.0;
  Vec3 e1 = sub(h, scale(n, dot(h, n)));
  e1 = scale(e1, 1.0 / norm(e1));
  return {e1, cross(n, e1)};
}

// ---------------------------------------------------------------------------------------------
// The polynomial circle and sphere pieces

/// Greville parameters of a uniform cubic space mapped to [-1, 1], made exactly odd
/// (s[n-1-i] = -s[i], the middle 0) so that mirrored parts hold bit-identical points.
std::vector<double> odd_greville(const KnotVector& kv) {
  const std::vector<double> g = kv.greville();
  const int n = static_cast<int>(g.size());
  std::vector<double> s(g.size());
  for (int i = 0; i < n; ++i) {
    const int m = n - 1 - i;
    if (i < m) s[static_cast<std::size_t>(i)] = 2.0 * g[static_cast<std::size_t>(i)] - 1.0;
    else if (i == m) s[static_cast<std::size_t>(i)] = 0.0;
    else s[static_cast<std::size_t>(i)] = -s[static_cast<std::size_t>(m)];
  }
  s.front() = -1.0, s.back() = 1.0;
  return s;
}

/// The unit quarter circle from -45 to +45 degrees, angle pi/4 s for s in [-1, 1] (uniform in
/// angle: the smallest interpolation error per knot): a planar cubic on uniform knots,
/// interpolating at the Greville abscissae, the knot count doubled until | |C| - 1 | <= tol on
/// 32 samples per span.
struct Arc {
  KnotVector knots;
  std::vector<double> s;       ///< odd Greville parameters in [-1, 1]
  std::vector<double> points;  ///< n x 2 control points, mirror-symmetric about the x axis
  double error = 0.0;
};

Arc unit_arc(double tol) {
  for (int segments = 2;; segments *= 2) {
    Arc a{KnotVector::uniform(4, segments), {}, {}, 0.0};
    a.s = odd_greville(a.knots);
    const int n = a.knots.size();
    std::vector<double> values(2 * static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const double angle = 0.25 * pi * a.s[static_cast<std::size_t>(i)];
      values[2 * static_cast<std::size_t>(i)] = std::cos(angle);
      values[2 * static_cast<std::size_t>(i) + 1] = std::sin(angle);
    }
    spline::Curve c = spline::interpolate_curve(a.knots.greville(), 2, values, a.knots);
    a.points.assign(c.points().begin(), c.points().end());
    // Mirror symmetry y -> -y, exact; the ends on the diagonals y = -x and y = x.
    for (int i = 0; i < n; ++i) {
      const int m = n - 1 - i;
      double* p = a.points.data() + 2 * i;
      if (i == m) p[1] = 0.0;
      if (i == 0) p[1] = -p[0];
      if (i > m) p[0] = a.points[2 * static_cast<std::size_t>(m)], p[1] = -a.points[2 * static_cast<std::size_t>(m) + 1];
    }
    c = spline::Curve({a.knots}, 2, a.points);
    a.error = 0.0;
    const int samples = 32 * segments;
    for (int k = 0; k <= samples; ++k) {
      double p[2];
      c.eval({static_cast<double>(k) / samples}, p);
      a.error = std::max(a.error, std::abs(std::hypot(p[0], p[1]) - 1.0));
    }
    if (a.error <= tol || segments >= 1024) return a;
  }
}

/// The sixth of the unit sphere over the cube face x = 1 in the equiangular cube map: the
/// direction (1, tan(pi/4 s), tan(pi/4 t)), s, t in [-1, 1], normalised (angles uniform in s and
/// t, so the knots are used evenly): a bicubic on uniform knots through the Greville grid, D4-symmetric (the
/// mirrors y -> -y, z -> -z and the swap y <-> z hold exactly on the control net), so that the
/// six caps made from it by rotations share their edges bit for bit.
struct Cap {
  KnotVector knots;
  std::vector<double> s;
  std::vector<double> points;  ///< n x n x 3, u (y) fastest
  double error = 0.0;
};

Cap unit_cap(double tol) {
  for (int segments = 2;; segments *= 2) {
    Cap c{KnotVector::uniform(4, segments), {}, {}, 0.0};
    c.s = odd_greville(c.knots);
    const int n = c.knots.size();
    std::vector<double> values(3 * static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double y = std::tan(0.25 * pi * c.s[static_cast<std::size_t>(i)]),
                     z = std::tan(0.25 * pi * c.s[static_cast<std::size_t>(j)]);
        const double l = std::sqrt(1.0 + y * y + z * z);
        double* v = values.data() + 3 * static_cast<std::size_t>(i + n * j);
        v[0] = 1.0 / l, v[1] = y / l, v[2] = z / l;
      }
    const std::vector<double> g = c.knots.greville();
    const spline::Surface fit = spline::fit_surface_grid(g, g, 3, values, {c.knots, c.knots});
    const std::vector<double> raw(fit.points().begin(), fit.points().end());
    auto at = [&](int i, int j) { return raw.data() + 3 * static_cast<std::size_t>(i + n * j); };
    c.points.resize(raw.size());
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int a = std::min(i, n - 1 - i), b = std::min(j, n - 1 - j);
        // The canonical entry (a <= b), with its exact relations: edge a = 0 on the plane
        // y = -x, the diagonal y = z, the middle row y = 0 (and column z = 0).
        const int lo = std::min(a, b), hi = std::max(a, b);
        double q[3] = {at(lo, hi)[0], at(lo, hi)[1], at(lo, hi)[2]};
        if (lo == 0) q[1] = -q[0];
        if (hi == 0) q[2] = q[1];
        if (lo == hi) q[2] = q[1];
        if (2 * lo == n - 1) q[1] = 0.0;
        if (2 * hi == n - 1) q[2] = 0.0;
        if (a > b) std::swap(q[1], q[2]);
        if (i != a) q[1] = -q[1];
        if (j != b) q[2] = -q[2];
        double* p = c.points.data() + 3 * static_cast<std::size_t>(i + n * j);
        p[0] = q[0], p[1] = q[1], p[2] = q[2];
      }
    const spline::Surface cap({c.knots, c.knots}, 3, c.points);
    c.error = 0.0;
    const int samples = 16 * segments;
    for (int kj = 0; kj <= samples; ++kj)
      for (int ki = 0; ki <= samples; ++ki) {
        double p[3];
        cap.eval({static_cast<double>(ki) / samples, static_cast<double>(kj) / samples}, p);
        c.error = std::max(c.error, std::abs(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1.0));
      }
    if (c.error <= tol || segments >= 256) return c;
  }
}

// ---------------------------------------------------------------------------------------------
// The 5-cell disk

/// One part of the unit disk pattern: a planar net (x, y per control point) in (u, v).
struct Patch2 {
  std::array<KnotVector, 2> knots;
  std::vector<double> xy;
};

/// The quarter turns (x, y) -> (-y, x) applied q times: exact in floating point.
void quarter_turns(double& x, double& y, int q) {
  for (int k = 0; k < q; ++k) {
    const double t = x;
    x = -y, y = t;
  }
}

/// core, then the outer parts at quarter turns q = 0 (+x), 1 (+y), 2 (-x), 3 (-y) (Massarwi & Elber
/// 2016 Fig. 9 (a)): the square [-0.5, 0.5]^2 in the arc's space in both directions, and each outer
/// part ruled (u) from the square's side to the arc, v counter-clockwise.
std::array<Patch2, 5> disk_pattern(const Arc& arc) {
  const int n = arc.knots.size();
  std::array<Patch2, 5> parts;
  parts[0].knots = {arc.knots, arc.knots};
  parts[0].xy.resize(2 * static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double* p = parts[0].xy.data() + 2 * static_cast<std::size_t>(i + n * j);
      p[0] = disk_core * arc.s[static_cast<std::size_t>(i)], p[1] = disk_core * arc.s[static_cast<std::size_t>(j)];
    }
  for (int q = 0; q < 4; ++q) {
    Patch2& part = parts[static_cast<std::size_t>(q) + 1];
    part.knots = {KnotVector::bezier(2), arc.knots};
    part.xy.resize(4 * static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) {
      double in[2] = {disk_core, disk_core * arc.s[static_cast<std::size_t>(j)]};
      double out[2] = {arc.points[2 * static_cast<std::size_t>(j)], arc.points[2 * static_cast<std::size_t>(j) + 1]};
      quarter_turns(in[0], in[1], q);
      quarter_turns(out[0], out[1], q);
      double* p = part.xy.data() + 4 * static_cast<std::size_t>(j);
      p[0] = in[0], p[1] = in[1], p[2] = out[0], p[3] = out[1];
    }
  }
  return parts;
}

/// The pattern part placed in space: X = origin + r (x ex + y ey).
spline::Surface place(const Patch2& part, const Vec3& origin, double r, const Vec3& ex, const Vec3& ey) {
  const std::size_t n = part.xy.size() / 2;
  std::vector<double> pts(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = r * part.xy[2 * i], y = r * part.xy[2 * i + 1];
    for (std::size_t c = 0; c < 3; ++c) pts[3 * i + c] = origin[c] + x * ex[c] + y * ey[c];
  }
  return spline::Surface(part.knots, 3, std::move(pts));
}

std::string cell_name(const std::string& name, const char* part) { return name + "." + part; }

// ---------------------------------------------------------------------------------------------
// The primitives

void check(const Box& b) {
  need_finite("box", "min", b.min);
  need_finite("box", "max", b.max);
  for (int c = 0; c < 3; ++c)
    if (!(b.min[static_cast<std::size_t>(c)] < b.max[static_cast<std::size_t>(c)]))
      throw Error(std::string("box min ") + "xyz"[c] + " = " + num(b.min[static_cast<std::size_t>(c)]) + " >= max " +
                  "xyz"[c] + " = " + num(b.max[static_cast<std::size_t>(c)]) + "; expected min < max in x, y and z");
}
void check(const Cylinder& c) {
  need_finite("cylinder", "base", c.base);
  unit_axis("cylinder", c.axis);
  need_positive("cylinder", "radius", c.radius);
  need_positive("cylinder", "height", c.height);
}
void check(const Cone& c) {
  need_finite("cone", "base", c.base);
  unit_axis("cone", c.axis);
  need_positive("cone", "radius", c.radius);
  if (c.top_radius == 0.0)
    throw Error("cone top_radius 0: a cone with an apex is singular there (Massarwi & Elber 2016, Sec. 3.2.3); expected a "
                "positive top_radius (a frustum; use a small one for a nearly sharp cone)");
  need_positive("cone", "top_radius", c.top_radius);
  need_positive("cone", "height", c.height);
}
void check(const Torus& t) {
  need_finite("torus", "center", t.center);
  unit_axis("torus", t.axis);
  need_positive("torus", "major", t.major);
  need_positive("torus", "minor", t.minor);
  if (!(t.major > t.minor))
    throw Error("torus major " + num(t.major) + " <= minor " + num(t.minor) +
                ": the tube would reach the axis; expected major > minor");
}
void check(const Sphere& s) {
  need_finite("sphere", "center", s.center);
  need_positive("sphere", "radius", s.radius);
}

std::vector<PrimitiveCell> build(const std::string& name, const Box& b, double) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        pts.push_back(i ? b.max[0] : b.min[0]);
        pts.push_back(j ? b.max[1] : b.min[1]);
        pts.push_back(k ? b.max[2] : b.min[2]);
      }
  const KnotVector lin = KnotVector::bezier(2);
  return {{name, spline::Trivariate({lin, lin, lin}, 3, std::move(pts))}};
}

constexpr const char* disk_names[5] = {"core", "x1", "y1", "x0", "y0"};
/// Output order core, x0, x1, y0, y1 from the pattern order core, +x, +y, -x, -y.
constexpr int disk_order[5] = {0, 3, 1, 4, 2};

std::vector<PrimitiveCell> build(const std::string& name, const Cylinder& c, double tol) {
  const Vec3 n = unit_axis("cylinder", c.axis);
  const auto [e1, e2] = frame(n);
  const auto parts = disk_pattern(unit_arc(tol));
  const Vec3 h = scale(n, c.height);
  std::vector<PrimitiveCell> out;
  for (int k : disk_order) {
    const spline::Surface s = place(parts[static_cast<std::size_t>(k)], c.base, c.radius, e1, e2);
    out.push_back({cell_name(name, disk_names[k]), extrude(s, h)});
  }
  return out;
}

std::vector<PrimitiveCell> build(const std::string& name, const Cone& c, double tol) {
  const Vec3 n = unit_axis("cone", c.axis);
  const auto [e1, e2] = frame(n);
  const auto parts = disk_pattern(unit_arc(tol));
  const Vec3 top = add(c.base, scale(n, c.height));
  std::vector<PrimitiveCell> out;
  for (int k : disk_order) {
    const auto& p = parts[static_cast<std::size_t>(k)];
    out.push_back({cell_name(name, disk_names[k]),
                   ruled(place(p, c.base, c.radius, e1, e2), place(p, top, c.top_radius, e1, e2))});
  }
  return out;
}

std::vector<PrimitiveCell> build(const std::string& name, const Torus& t, double tol) {
  const Vec3 n = unit_axis("torus", t.axis);
  const auto [e1, e2] = frame(n);
  (void)e2;
  const auto parts = disk_pattern(unit_arc(tol));
  // The cross-section's x along n, y along e1: x x y = n x e1 = e2, the direction the
  // revolution (right-handed about n) starts in, so the cells are right-handed.
  const Vec3 centre = add(t.center, scale(e1, t.major));
  Revolution rev;
  rev.origin = t.center;
  rev.axis = n;
  rev.angle = 2 * pi;
  rev.relative_tolerance = tol * t.minor / (t.major + t.minor);
  constexpr const char* names[5] = {"core", "top", "outer", "bottom", "inner"};
  constexpr int order[5] = {0, 3, 1, 4, 2};  // core, bottom, top, inner, outer
  std::vector<PrimitiveCell> out;
  for (int k : order)
    out.push_back({cell_name(name, names[k]), revolve(place(parts[static_cast<std::size_t>(k)], centre, t.minor, n, e1), rev)});
  return out;
}

/// The rotations taking the +x cap to the others (columns: where x, y, z go), all det +1.
struct Rotation {
  const char* name;
  int m[3][3];
};
constexpr Rotation cap_rotations[6] = {
    {"x0", {{-1, 0, 0}, {0, -1, 0}, {0, 0, 1}}},  // (x,y,z) -> (-x,-y,z)
    {"x1", {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}},
    {"y0", {{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}}},   // (y,-x,z)
    {"y1", {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}},   // (-y,x,z)
    {"z0", {{0, 0, 1}, {0, 1, 0}, {-1, 0, 0}}},   // (z,y,-x)
    {"z1", {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}},   // (-z,y,x)
};

/// Exact: every entry is 0 or +-1, so each output is one input, possibly negated.
Vec3 rotate(const Rotation& r, const double* p) {
  Vec3 out{};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (r.m[a][b] != 0) out[static_cast<std::size_t>(a)] = r.m[a][b] > 0 ? p[b] : -p[b];
  return out;
}

spline::Surface place3(const std::array<KnotVector, 2>& knots, const std::vector<double>& unit, const Rotation& r,
                       const Vec3& centre, double radius) {
  std::vector<double> pts(unit.size());
  for (std::size_t i = 0; i < unit.size() / 3; ++i) {
    const Vec3 q = rotate(r, unit.data() + 3 * i);
    for (std::size_t c = 0; c < 3; ++c) pts[3 * i + c] = centre[c] + radius * q[c];
  }
  return spline::Surface(knots, 3, std::move(pts));
}

std::vector<PrimitiveCell> build(const std::string& name, const Sphere& s, double tol) {
  const Cap cap = unit_cap(tol);
  const int n = cap.knots.size();
  const std::size_t nn = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  // The cube face x = ball_core in the cap's space (a linear function's control points are its
  // values at the Greville abscissae).
  std::vector<double> face(3 * nn);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double* p = face.data() + 3 * static_cast<std::size_t>(i + n * j);
      p[0] = ball_core, p[1] = ball_core * cap.s[static_cast<std::size_t>(i)], p[2] = ball_core * cap.s[static_cast<std::size_t>(j)];
    }
  std::vector<PrimitiveCell> out;
  std::vector<double> core(3 * nn * static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        double* p = core.data() + 3 * (static_cast<std::size_t>(i + n * j) + nn * static_cast<std::size_t>(k));
        const double q[3] = {ball_core * cap.s[static_cast<std::size_t>(i)], ball_core * cap.s[static_cast<std::size_t>(j)],
                             ball_core * cap.s[static_cast<std::size_t>(k)]};
        for (std::size_t c = 0; c < 3; ++c) p[c] = s.center[c] + s.radius * q[c];
      }
  out.push_back({cell_name(name, "core"), spline::Trivariate({cap.knots, cap.knots, cap.knots}, 3, std::move(core))});
  const std::array<KnotVector, 2> kk{cap.knots, cap.knots};
  for (const Rotation& r : cap_rotations)
    out.push_back({cell_name(name, r.name),
                   ruled(place3(kk, face, r, s.center, s.radius), place3(kk, cap.points, r, s.center, s.radius))});
  return out;
}

}  // namespace

const char* primitive_type(const Primitive& p) noexcept {
  constexpr const char* names[] = {"box", "cylinder", "cone", "torus", "sphere"};
  return names[p.index()];
}

void check_primitive(const Primitive& p) {
  std::visit([](const auto& q) { check(q); }, p);
}

std::vector<PrimitiveCell> build_primitive(const std::string& name, const Primitive& p, const PrimitiveOptions& options) {
  if (!(options.relative_tolerance >= 1e-8 && options.relative_tolerance <= 0.01))
    throw Error("primitive tolerance " + num(options.relative_tolerance) + "; expected a value in [1e-8, 0.01]");
  check_primitive(p);
  // The arcs are built to half the tolerance: the cubic interpolant's radial error is sampled
  // (32 points per span), and the margin covers what falls between the samples.
  const double tol = 0.5 * options.relative_tolerance;
  return std::visit([&](const auto& q) { return build(name, q, tol); }, p);
}

double exact_volume(const Primitive& p) {
  struct V {
    double operator()(const Box& b) const { return (b.max[0] - b.min[0]) * (b.max[1] - b.min[1]) * (b.max[2] - b.min[2]); }
    double operator()(const Cylinder& c) const { return pi * c.radius * c.radius * c.height; }
    double operator()(const Cone& c) const {
      return pi * c.height * (c.radius * c.radius + c.radius * c.top_radius + c.top_radius * c.top_radius) / 3.0;
    }
    double operator()(const Torus& t) const { return 2.0 * pi * pi * t.major * t.minor * t.minor; }
    double operator()(const Sphere& s) const { return 4.0 / 3.0 * pi * s.radius * s.radius * s.radius; }
  };
  return std::visit(V{}, p);
}

double characteristic_radius(const Primitive& p) {
  struct R {
    double operator()(const Box& b) const {
      return 0.5 * std::min({b.max[0] - b.min[0], b.max[1] - b.min[1], b.max[2] - b.min[2]});
    }
    double operator()(const Cylinder& c) const { return c.radius; }
    double operator()(const Cone& c) const { return std::max(c.radius, c.top_radius); }
    double operator()(const Torus& t) const { return t.minor; }
    double operator()(const Sphere& s) const { return s.radius; }
  };
  return std::visit(R{}, p);
}

namespace {

/// Distance from (rho, z) to the boundary of the planar trapezoid 0 <= z <= h, 0 <= rho <= r(z)
/// (r linear from r0 to r1): the cylinder's and cone's half meridian section.
double section_distance(double rho, double z, double h, double r0, double r1) {
  auto seg = [](double px, double py, double ax, double ay, double bx, double by) {
    const double dx = bx - ax, dy = by - ay;
    const double t = std::clamp(((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
    return std::hypot(px - ax - t * dx, py - ay - t * dy);
  };
  return std::min({seg(rho, z, 0, 0, r0, 0), seg(rho, z, r0, 0, r1, h), seg(rho, z, 0, h, r1, h)});
}

}  // namespace

double boundary_distance(const Primitive& p, const Vec3& x) {
  struct D {
    const Vec3& x;
    double operator()(const Box& b) const {
      // Inside: the nearest face; outside: the distance to the box.
      bool inside = true;
      double out2 = 0.0, in = INFINITY;
      for (std::size_t c = 0; c < 3; ++c) {
        const double lo = b.min[c] - x[c], hi = x[c] - b.max[c];
        if (lo > 0) inside = false, out2 += lo * lo;
        if (hi > 0) inside = false, out2 += hi * hi;
        in = std::min({in, -lo, -hi});
      }
      return inside ? in : std::sqrt(out2);
    }
    double operator()(const Cylinder& c) const { return axial(c.base, c.axis, c.height, c.radius, c.radius); }
    double operator()(const Cone& c) const { return axial(c.base, c.axis, c.height, c.radius, c.top_radius); }
    double axial(const Vec3& base, const Vec3& axis, double h, double r0, double r1) const {
      const Vec3 n = scale(axis, 1.0 / norm(axis));
      const Vec3 d = sub(x, base);
      const double z = dot(d, n);
      const double rho = norm(sub(d, scale(n, z)));
      return section_distance(rho, z, h, r0, r1);
    }
    double operator()(const Torus& t) const {
      const Vec3 n = scale(t.axis, 1.0 / norm(t.axis));
      const Vec3 d = sub(x, t.center);
      const double z = dot(d, n);
      const double rho = norm(sub(d, scale(n, z)));
      return std::abs(std::hypot(rho - t.major, z) - t.minor);
    }
    double operator()(const Sphere& s) const { return std::abs(norm(sub(x, s.center)) - s.radius); }
  };
  return std::visit(D{x}, p);
}

// ---------------------------------------------------------------------------------------------
// Fields

namespace {

/// A field's values for a point: for a number of properties m, the fraction t in [0, 1] between
/// the two value lists (constant: 0).
struct FieldShape {
  const std::vector<double>* a;
  const std::vector<double>* b;
};

FieldShape shape(const Field& f) {
  if (const auto* c = std::get_if<ConstantField>(&f)) return {&c->values, &c->values};
  if (const auto* l = std::get_if<LinearField>(&f)) return {&l->v0, &l->v1};
  const auto& r = std::get<RadialField>(f);
  return {&r.v_centre, &r.v_radius};
}

/// The unclamped parameter of x along the field (linear: projection on from -> to; radial:
/// distance / radius; constant: 0).
double field_param(const Field& f, const Vec3& x) {
  if (const auto* l = std::get_if<LinearField>(&f)) {
    const Vec3 d = sub(l->to, l->from);
    return dot(sub(x, l->from), d) / dot(d, d);
  }
  if (const auto* r = std::get_if<RadialField>(&f)) return norm(sub(x, r->center)) / r->radius;
  return 0.0;
}

void values_at(const FieldShape& s, double t, double* out) {
  for (std::size_t p = 0; p < s.a->size(); ++p) out[p] = (*s.a)[p] + t * ((*s.b)[p] - (*s.a)[p]);
}

/// Greville interpolation of `data` (one value list of m per Greville point of `cell`, u fastest)
/// in the cell's space: one 1-D collocation solve per direction, all lines at once.
std::vector<double> interpolate_greville(const spline::Trivariate& cell, std::vector<double> data, int m) {
  const auto n = cell.counts();
  for (int d = 0; d < 3; ++d) {
    const int nd = n[static_cast<std::size_t>(d)];
    const int lines = cell.size() / nd;
    // values[j * dim + c], j along d, c = (line, property).
    const int dim = lines * m;
    std::vector<double> values(static_cast<std::size_t>(nd) * static_cast<std::size_t>(dim));
    auto flat = [&](int along, int line) {
      // line enumerates the other two indices, lower direction fastest.
      std::array<int, 3> idx{};
      int q = line;
      for (int e = 0; e < 3; ++e) {
        if (e == d) continue;
        idx[static_cast<std::size_t>(e)] = q % n[static_cast<std::size_t>(e)];
        q /= n[static_cast<std::size_t>(e)];
      }
      idx[static_cast<std::size_t>(d)] = along;
      return cell.row(idx);
    };
    for (int line = 0; line < lines; ++line)
      for (int j = 0; j < nd; ++j)
        for (int p = 0; p < m; ++p)
          values[static_cast<std::size_t>(j) * dim + static_cast<std::size_t>(line) * m + p] =
              data[static_cast<std::size_t>(flat(j, line)) * m + p];
    const spline::Curve c = spline::interpolate_curve(cell.knots(d).greville(), dim, values, cell.knots(d));
    for (int line = 0; line < lines; ++line)
      for (int j = 0; j < nd; ++j)
        for (int p = 0; p < m; ++p)
          data[static_cast<std::size_t>(flat(j, line)) * m + p] =
              c.point(j)[static_cast<std::size_t>(line) * m + p];
  }
  return data;
}

/// The cell with properties appended: xyz of `cell` then `props` (m per control point).
spline::Trivariate with_properties(const spline::Trivariate& cell, const std::vector<double>& props, int m) {
  std::vector<double> pts(static_cast<std::size_t>(cell.size()) * static_cast<std::size_t>(3 + m));
  for (int r = 0; r < cell.size(); ++r) {
    double* p = pts.data() + static_cast<std::size_t>(r) * (3 + m);
    const auto x = cell.point(r);
    p[0] = x[0], p[1] = x[1], p[2] = x[2];
    for (int q = 0; q < m; ++q) p[3 + q] = props[static_cast<std::size_t>(r) * m + q];
  }
  return spline::Trivariate(cell.knot_vectors(), 3 + m, std::move(pts));
}

/// Sample parameters of a direction: 4 per knot span and the end, thinned to at most 49.
std::vector<double> sample_params(const KnotVector& kv) {
  std::vector<double> t;
  const auto br = kv.breakpoints();
  for (std::size_t i = 0; i + 1 < br.size(); ++i)
    for (int k = 0; k < 4; ++k) t.push_back(br[i].value + (br[i + 1].value - br[i].value) * k / 4.0);
  t.push_back(br.back().value);
  if (t.size() > 49) {
    std::vector<double> u(49);
    for (int i = 0; i < 49; ++i) u[static_cast<std::size_t>(i)] = kv.front() + (kv.back() - kv.front()) * i / 48.0;
    return u;
  }
  return t;
}

/// Largest |spline property - exact field| / range over a sample of the cell.
double field_error(const spline::Trivariate& cell, const Field& f, const FieldShape& s, const std::vector<double>& range) {
  const int m = static_cast<int>(range.size());
  const auto tu = sample_params(cell.knots(0)), tv = sample_params(cell.knots(1)), tw = sample_params(cell.knots(2));
  std::vector<double> p(static_cast<std::size_t>(cell.dim())), exact(static_cast<std::size_t>(m));
  double err = 0.0;
  for (double w : tw)
    for (double v : tv)
      for (double u : tu) {
        cell.eval({u, v, w}, p.data());
        values_at(s, std::clamp(field_param(f, {p[0], p[1], p[2]}), 0.0, 1.0), exact.data());
        for (int q = 0; q < m; ++q)
          if (range[static_cast<std::size_t>(q)] > 0)
            err = std::max(err, std::abs(p[3 + static_cast<std::size_t>(q)] - exact[static_cast<std::size_t>(q)]) /
                                    range[static_cast<std::size_t>(q)]);
      }
  return err;
}

}  // namespace

int field_size(const Field& f) noexcept { return static_cast<int>(shape(f).a->size()); }

void check_field(const Field& f, int properties) {
  const FieldShape s = shape(f);
  const char* kind = f.index() == 0 ? "constant" : f.index() == 1 ? "linear" : "radial";
  auto values = [&](const std::vector<double>& v, const char* what) {
    if (static_cast<int>(v.size()) != properties)
      throw Error(std::string(kind) + " field " + what + ": " + std::to_string(v.size()) + " values; expected " +
                  std::to_string(properties) + " (one per property)");
    for (double x : v)
      if (!std::isfinite(x)) throw Error(std::string(kind) + " field " + what + " holds " + num(x) + "; expected finite values");
  };
  if (f.index() == 0) values(*s.a, "values");
  if (const auto* l = std::get_if<LinearField>(&f)) {
    values(l->v0, "v0");
    values(l->v1, "v1");
    need_finite("linear field", "from", l->from);
    need_finite("linear field", "to", l->to);
    if (!(norm(sub(l->to, l->from)) > 0.0))
      throw Error("linear field from = to; expected two distinct points (the direction of the gradient)");
  }
  if (const auto* r = std::get_if<RadialField>(&f)) {
    values(r->v_centre, "v_centre");
    values(r->v_radius, "v_radius");
    need_finite("radial field", "center", r->center);
    need_positive("radial field", "radius", r->radius);
  }
}

FieldReport apply_field(std::vector<PrimitiveCell>& cells, const Field& f, const FieldOptions& options) {
  const int m = field_size(f);
  check_field(f, m);
  for (const auto& c : cells)
    if (c.volume.dim() != 3 || c.volume.rational())
      throw Error("cell " + c.name + ": " + std::to_string(c.volume.dim()) +
                  " coordinates; expected a polynomial cell of xyz only (3) before a field is applied");
  const FieldShape s = shape(f);
  FieldReport report;
  // Exact cases: the field is affine (or constant) over every control point, hence over the
  // cells' convex hulls; the unclamped affine function then agrees with the clamped one there.
  bool affine = f.index() == 0;
  if (f.index() == 1) {
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& c : cells)
      for (int r = 0; r < c.volume.size(); ++r) {
        const auto x = c.volume.point(r);
        const double t = field_param(f, {x[0], x[1], x[2]});
        lo = std::min(lo, t), hi = std::max(hi, t);
      }
    affine = (lo >= 0.0 && hi <= 1.0) || hi <= 0.0 || lo >= 1.0;
  }
  if (affine) {
    for (auto& c : cells) {
      std::vector<double> props(static_cast<std::size_t>(c.volume.size()) * m);
      for (int r = 0; r < c.volume.size(); ++r) {
        const auto x = c.volume.point(r);
        double t = field_param(f, {x[0], x[1], x[2]});
        if (f.index() == 1) t = std::clamp(t, 0.0, 1.0);
        values_at(s, t, props.data() + static_cast<std::size_t>(r) * m);
      }
      c.volume = with_properties(c.volume, props, m);
    }
    report.exact = true;
    return report;
  }
  std::vector<double> range(static_cast<std::size_t>(m));
  for (int q = 0; q < m; ++q) range[static_cast<std::size_t>(q)] = std::abs((*s.b)[static_cast<std::size_t>(q)] - (*s.a)[static_cast<std::size_t>(q)]);
  // Cubic at least in every direction, so that a smooth field converges at O(h^4).
  std::vector<spline::Trivariate> geometry;
  for (const auto& c : cells) {
    spline::Trivariate g = c.volume;
    for (int d = 0; d < 3; ++d)
      if (g.knots(d).order() < 4) g = spline::elevate(g, d, 4 - g.knots(d).order());
    geometry.push_back(std::move(g));
  }
  for (int round = 0;; ++round) {
    std::vector<spline::Trivariate> result;
    double err = 0.0;
    for (const auto& g : geometry) {
      const auto gu = g.knots(0).greville(), gv = g.knots(1).greville(), gw = g.knots(2).greville();
      std::vector<double> data(static_cast<std::size_t>(g.size()) * m);
      double x[3];
      for (int r = 0; r < g.size(); ++r) {
        const auto i = g.multi_index(r);
        g.eval({gu[static_cast<std::size_t>(i[0])], gv[static_cast<std::size_t>(i[1])], gw[static_cast<std::size_t>(i[2])]}, x);
        values_at(s, std::clamp(field_param(f, {x[0], x[1], x[2]}), 0.0, 1.0), data.data() + static_cast<std::size_t>(r) * m);
      }
      result.push_back(with_properties(g, interpolate_greville(g, std::move(data), m), m));
      err = std::max(err, field_error(result.back(), f, s, range));
    }
    report.max_error = err;
    report.refinements = round;
    report.converged = err <= options.relative_tolerance;
    long next = 0;
    for (const auto& g : geometry) {
      long n = 1;
      for (int d = 0; d < 3; ++d) n *= g.count(d) + static_cast<long>(g.knots(d).breakpoints().size()) - 1;
      next += n;
    }
    if (report.converged || round >= options.max_refinements || next > options.max_control_points) {
      for (std::size_t i = 0; i < cells.size(); ++i) cells[i].volume = std::move(result[i]);
      return report;
    }
    for (auto& g : geometry)
      for (int d = 0; d < 3; ++d) g = spline::refine_uniform(g, d, 1);
  }
}

std::vector<double> field_value(const Field& f, const Vec3& x) {
  const FieldShape s = shape(f);
  std::vector<double> out(s.a->size());
  values_at(s, std::clamp(field_param(f, x), 0.0, 1.0), out.data());
  return out;
}

}  // namespace trivox::construct
