#include "trivox/geom/kernel.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include <Eigen/Dense>

#include "trivox/error.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::geom {

namespace {

using spline::Curve;
using spline::Surface;
using spline::Trivariate;
using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string point_text(const std::vector<double>& p, int coords) {
  std::string s = "(";
  for (int h = 0; h < coords; ++h) s += (h ? ", " : "") + num(p[static_cast<std::size_t>(h)]);
  return s + ")";
}

/// The spline equal to 1 on s's domain, in s's function space (partition of unity), so that a
/// product with it lands in the same space as a product with s.
template <int P>
spline::TensorSpline<P> ones_like(const spline::TensorSpline<P>& s) {
  return spline::TensorSpline<P>(s.knot_vectors(), 1, std::vector<double>(static_cast<std::size_t>(s.size()), 1.0));
}

/// Coordinates of several splines that share one function space, side by side in one spline.
template <int P>
spline::TensorSpline<P> side_by_side(std::vector<spline::TensorSpline<P>> parts) {
  for (std::size_t i = 1; i < parts.size(); ++i)
    if (parts[i].knot_vectors() != parts[0].knot_vectors()) {
      auto [x, y] = spline::make_compatible(parts[0], parts[i]);
      for (std::size_t j = 0; j < i; ++j) parts[j] = spline::make_compatible(parts[j], x).first;
      parts[i] = std::move(y);
    }
  int dim = 0;
  for (const auto& p : parts) dim += p.dim();
  const int n = parts[0].size();
  std::vector<double> pts(static_cast<std::size_t>(n * dim));
  for (int r = 0; r < n; ++r) {
    int h = 0;
    for (const auto& p : parts)
      for (double v : p.point(r)) pts[static_cast<std::size_t>(r * dim + h++)] = v;
  }
  return spline::TensorSpline<P>(parts[0].knot_vectors(), dim, std::move(pts));
}

/// Integral of basis function i of a knot vector: (t_{i+k} - t_i) / k.
double basis_integral(const spline::KnotVector& kv, int i) {
  return (kv[i + kv.order()] - kv[i]) / kv.order();
}

/// Refinement of every direction: 2^r - 1 new knots per span (r halvings).
template <int P>
spline::TensorSpline<P> halve(spline::TensorSpline<P> s, int refinements) {
  if (refinements <= 0) return s;
  const int per_span = (1 << std::min(refinements, 10)) - 1;
  for (int d = 0; d < P; ++d) s = spline::refine_uniform(s, d, per_span);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Planar: half-planes a x + b y + c >= 0 (a, b normalised), clipping a convex polygon.

struct HalfPlane {
  double a, b, c;
};

double side(const HalfPlane& h, const Vec2& p) { return h.a * p.x() + h.b * p.y() + h.c; }

/// Sutherland-Hodgman against one half-plane; `eps` is the distance counted as on the line.
std::vector<Vec2> clip(const std::vector<Vec2>& poly, const HalfPlane& h, double eps) {
  std::vector<Vec2> out;
  const std::size_t n = poly.size();
  out.reserve(n + 1);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % n];
    const double dp = side(h, p), dq = side(h, q);
    if (dp >= -eps) out.push_back(p);
    if ((dp > eps && dq < -eps) || (dp < -eps && dq > eps)) out.push_back(p + (dp / (dp - dq)) * (q - p));
  }
  // Drop repeated vertices (a vertex on the line may have been pushed next to its own cut).
  std::vector<Vec2> clean;
  for (const Vec2& p : out)
    if (clean.empty() || (p - clean.back()).norm() > eps) clean.push_back(p);
  while (clean.size() > 1 && (clean.front() - clean.back()).norm() <= eps) clean.pop_back();
  return clean;
}

/// f_K(t) = C'(t) x (K - C(t)) as a spline in R^3 whose coefficients are (a_i, b_i, c_i):
/// f_K = a K_x + b K_y + c with a = -C'_y, b = C'_x, c = C'_y C_x - C'_x C_y.
Curve tangent_constraint(const Curve& c) {
  const Curve x = spline::coordinates(c, 0, 1), y = spline::coordinates(c, 1, 1);
  const Curve dx = spline::derivative(x, 0), dy = spline::derivative(y, 0);
  const Curve one = ones_like(x);
  Curve a = spline::product(dy, one, spline::ProductKind::scalar);
  for (double& v : a.points()) v = -v;
  Curve b = spline::product(dx, one, spline::ProductKind::scalar);
  Curve cc = spline::add(spline::product(dy, x, spline::ProductKind::scalar),
                         spline::product(dx, y, spline::ProductKind::scalar), -1.0);
  return side_by_side<1>({std::move(a), std::move(b), std::move(cc)});
}

// ---------------------------------------------------------------------------------------------
// Spatial: half-spaces n . x <= d (n normalised), clipping a convex polyhedron held as faces.

struct HalfSpace {
  Vec3 n;
  double d;
};

using Polygon3 = std::vector<Vec3>;

Vec3 perpendicular(const Vec3& n) {
  const Vec3 t = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return n.cross(t).normalized();
}

void push_unique(std::vector<Vec3>& pts, const Vec3& p, double eps) {
  for (const Vec3& q : pts)
    if ((p - q).norm() <= eps) return;
  pts.push_back(p);
}

/// Clips a convex polyhedron (faces counter-clockwise seen from outside) by n . x <= d and closes
/// the cut with a new face.
std::vector<Polygon3> clip(const std::vector<Polygon3>& faces, const HalfSpace& h, double eps) {
  bool cuts = false;
  for (const auto& f : faces)
    for (const Vec3& p : f) cuts = cuts || h.n.dot(p) - h.d > eps;
  if (!cuts) return faces;
  std::vector<Polygon3> out;
  std::vector<Vec3> cap;
  for (const auto& f : faces) {
    Polygon3 g;
    const std::size_t n = f.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3& p = f[i];
      const Vec3& q = f[(i + 1) % n];
      const double sp = h.n.dot(p) - h.d, sq = h.n.dot(q) - h.d;
      if (sp <= eps) g.push_back(p);
      if (std::abs(sp) <= eps) push_unique(cap, p, eps);
      if ((sp < -eps && sq > eps) || (sp > eps && sq < -eps)) {
        const Vec3 x = p + (sp / (sp - sq)) * (q - p);
        g.push_back(x);
        push_unique(cap, x, eps);
      }
    }
    Polygon3 clean;
    for (const Vec3& p : g)
      if (clean.empty() || (p - clean.back()).norm() > eps) clean.push_back(p);
    while (clean.size() > 1 && (clean.front() - clean.back()).norm() <= eps) clean.pop_back();
    if (clean.size() >= 3) out.push_back(std::move(clean));
  }
  if (cap.size() >= 3) {
    Vec3 c = Vec3::Zero();
    for (const Vec3& p : cap) c += p;
    c /= static_cast<double>(cap.size());
    const Vec3 e1 = perpendicular(h.n), e2 = h.n.cross(e1);
    std::vector<std::pair<double, Vec3>> sorted;
    for (const Vec3& p : cap) sorted.emplace_back(std::atan2((p - c).dot(e2), (p - c).dot(e1)), p);
    std::sort(sorted.begin(), sorted.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    Polygon3 g;
    for (const auto& [angle, p] : sorted) g.push_back(p);
    out.push_back(std::move(g));
  }
  return out;
}

/// g_K(s,t) = n . (K - S) with n = S_s x S_t, as a spline in R^4 with coefficients (n_i, d_i):
/// g_K = n . K - d, d = n . S.
Surface normal_constraint(const Surface& s) {
  const Surface x = spline::coordinates(s, 0, 3);
  const Surface n = spline::product(spline::derivative(x, 0), spline::derivative(x, 1), spline::ProductKind::cross);
  Surface nn = spline::product(ones_like(x), n, spline::ProductKind::scalar_vector);
  Surface d = spline::product(x, n, spline::ProductKind::dot);
  return side_by_side<2>({std::move(nn), std::move(d)});
}

/// Shoelace area and centroid of a clipped polygon into k (left empty for zero area).
void finish(const std::vector<Vec2>& poly, PlanarKernel& k) {
  k.vertices.clear();
  k.area = 0.0;
  if (poly.size() < 3) return;
  double a2 = 0.0;
  Vec2 c = Vec2::Zero();
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % poly.size()];
    const double w = p.x() * q.y() - q.x() * p.y();
    a2 += w;
    c += w * (p + q);
  }
  if (!(a2 > 0.0)) return;
  k.area = 0.5 * a2;
  c /= 3.0 * a2;
  k.centroid = {c.x(), c.y()};
  for (const Vec2& p : poly) k.vertices.push_back({p.x(), p.y()});
}

/// Volume, centroid, vertices and faces of a clipped polyhedron into k (left empty for zero
/// volume); vertices within 10 eps are merged.
void finish(const std::vector<Polygon3>& poly, double eps, SpatialKernel& k) {
  k.vertices.clear();
  k.faces.clear();
  k.volume = 0.0;
  if (poly.size() < 4) return;
  // Volume and centroid: tetrahedra from a point inside to each face's fan triangles.
  Vec3 ref = Vec3::Zero();
  int count = 0;
  for (const auto& f : poly)
    for (const Vec3& p : f) ref += p, ++count;
  ref /= count;
  double vol6 = 0.0;
  Vec3 c = Vec3::Zero();
  for (const auto& f : poly)
    for (std::size_t i = 1; i + 1 < f.size(); ++i) {
      const double v = (f[0] - ref).dot((f[i] - ref).cross(f[i + 1] - ref));
      vol6 += v;
      c += v * (ref + f[0] + f[i] + f[i + 1]) / 4.0;
    }
  if (!(vol6 > 0.0)) return;
  k.volume = vol6 / 6.0;
  c /= vol6;
  k.centroid = {c.x(), c.y(), c.z()};
  for (const auto& f : poly) {
    std::vector<int> ids;
    for (const Vec3& p : f) {
      int id = -1;
      for (std::size_t j = 0; j < k.vertices.size() && id < 0; ++j)
        if ((Vec3(k.vertices[j][0], k.vertices[j][1], k.vertices[j][2]) - p).norm() <= 10 * eps) id = static_cast<int>(j);
      if (id < 0) {
        id = static_cast<int>(k.vertices.size());
        k.vertices.push_back({p.x(), p.y(), p.z()});
      }
      ids.push_back(id);
    }
    k.faces.push_back(std::move(ids));
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------

PlanarKernel planar_kernel(std::span<const Curve> loop, const KernelOptions& options) {
  if (loop.empty()) throw Error("kernel of an empty loop; expected at least one curve");
  const std::size_t n = loop.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (loop[i].rational())
      throw Error("kernel loop: curve " + std::to_string(i) + " is rational; expected polynomial curves");
    if (loop[i].dim() < 2)
      throw Error("kernel loop: curve " + std::to_string(i) + " has " + std::to_string(loop[i].dim()) +
                  " coordinates; expected at least 2 (x, y)");
    if (loop[i].knots(0).order() < 2)
      throw Error("kernel loop: curve " + std::to_string(i) + " is piecewise constant; expected order >= 2");
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    const auto end = loop[i].eval({loop[i].domain(0)[1]});
    const auto start = loop[j].eval({loop[j].domain(0)[0]});
    const double gap = std::hypot(end[0] - start[0], end[1] - start[1]);
    if (!(gap <= options.join_tolerance))
      throw Error("kernel loop: curve " + std::to_string(i) + " ends at " + point_text(end, 2) + " but curve " +
                  std::to_string(j) + " starts at " + point_text(start, 2) + ", " + num(gap) +
                  " apart; expected each curve to end where the next starts (within " + num(options.join_tolerance) + ")");
  }

  // Constraint splines, the loop's bounding box and its signed area (1/2 sum of integral C x C').
  std::vector<Curve> constraints;
  double area2 = 0.0;
  Vec2 lo = Vec2::Constant(HUGE_VAL), hi = Vec2::Constant(-HUGE_VAL);
  for (const Curve& c : loop) {
    Curve f = tangent_constraint(c);
    for (int i = 0; i < f.size(); ++i) area2 += f.point(i)[2] * basis_integral(f.knots(0), i);
    constraints.push_back(halve(std::move(f), options.refinements));
    for (int i = 0; i < c.size(); ++i) {
      const Vec2 p(c.point(i)[0], c.point(i)[1]);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  const double size = (hi - lo).norm();
  if (!(std::abs(0.5 * area2) > 1e-14 * size * size))
    throw Error("kernel loop: signed area " + num(0.5 * area2) +
                "; expected a closed loop enclosing a region (non-zero area)");

  PlanarKernel k;
  k.orientation = area2 > 0 ? 1 : -1;
  const double sign = k.orientation;
  double largest = 0.0;
  for (const Curve& f : constraints)
    for (int i = 0; i < f.size(); ++i) largest = std::max(largest, std::hypot(f.point(i)[0], f.point(i)[1]));
  const double eps = 1e-12 * size;
  std::vector<HalfPlane> planes;
  for (const Curve& f : constraints)
    for (int i = 0; i < f.size(); ++i) {
      const auto p = f.point(i);
      const double a = sign * p[0], b = sign * p[1], c = sign * p[2];
      const double len = std::hypot(a, b);
      if (len <= 1e-10 * largest) {
        // A vanishing tangent coefficient: the constraint is c >= 0, about K not at all.
        if (c < -eps * largest) return k;
        continue;
      }
      planes.push_back({a / len, b / len, c / len});
    }
  k.constraints = static_cast<int>(planes.size());

  const Vec2 margin = Vec2::Constant(0.01 * size + 1e-300);
  std::vector<Vec2> poly{Vec2(lo.x() - margin.x(), lo.y() - margin.y()), Vec2(hi.x() + margin.x(), lo.y() - margin.y()),
                         Vec2(hi.x() + margin.x(), hi.y() + margin.y()), Vec2(lo.x() - margin.x(), hi.y() + margin.y())};
  for (const HalfPlane& h : planes) {
    poly = clip(poly, h, eps);
    if (poly.size() < 3) return k;
  }
  finish(poly, k);
  return k;
}

std::vector<Curve> boundary_loop(const Surface& s) {
  const auto du = s.domain(0), dv = s.domain(1);
  return {spline::iso(s, 1, dv[0]), spline::iso(s, 0, du[1]), spline::reverse(spline::iso(s, 1, dv[1]), 0),
          spline::reverse(spline::iso(s, 0, du[0]), 0)};
}

PlanarKernel planar_kernel(const Surface& s, const KernelOptions& options) {
  const auto loop = boundary_loop(s);
  KernelOptions o = options;
  // The loop comes from one surface: its corners coincide up to the rounding of the iso-curves.
  double size = 0.0;
  const auto box = s.control_box();
  for (int h = 0; h < std::min(2, s.dim()); ++h) size = std::max(size, box[1][static_cast<std::size_t>(h)] - box[0][static_cast<std::size_t>(h)]);
  o.join_tolerance = std::max(o.join_tolerance, 1e-12 * size);
  return planar_kernel(loop, o);
}

SpatialKernel spatial_kernel(std::span<const Surface> faces, const KernelOptions& options) {
  if (faces.empty()) throw Error("kernel of an empty set of surfaces; expected a closed set of faces");
  for (std::size_t i = 0; i < faces.size(); ++i) {
    if (faces[i].rational())
      throw Error("kernel faces: surface " + std::to_string(i) + " is rational; expected polynomial surfaces");
    if (faces[i].dim() < 3)
      throw Error("kernel faces: surface " + std::to_string(i) + " has " + std::to_string(faces[i].dim()) +
                  " coordinates; expected at least 3 (x, y, z)");
    for (int d = 0; d < 2; ++d)
      if (faces[i].knots(d).order() < 2)
        throw Error("kernel faces: surface " + std::to_string(i) + " is piecewise constant in direction " +
                    std::to_string(d) + "; expected order >= 2");
  }
  std::vector<Surface> constraints;
  double volume3 = 0.0;
  Vec3 lo = Vec3::Constant(HUGE_VAL), hi = Vec3::Constant(-HUGE_VAL);
  for (const Surface& s : faces) {
    Surface g = normal_constraint(s);
    for (int i = 0; i < g.size(); ++i) {
      const auto ij = g.multi_index(i);
      volume3 += g.point(i)[3] * basis_integral(g.knots(0), ij[0]) * basis_integral(g.knots(1), ij[1]);
    }
    constraints.push_back(halve(std::move(g), options.refinements));
    for (int i = 0; i < s.size(); ++i) {
      const Vec3 p(s.point(i)[0], s.point(i)[1], s.point(i)[2]);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  const double size = (hi - lo).norm();
  if (!(std::abs(volume3 / 3.0) > 1e-14 * size * size * size))
    throw Error("kernel faces: signed volume " + num(volume3 / 3.0) +
                "; expected a closed set of surfaces enclosing a region (non-zero volume)");

  SpatialKernel k;
  k.orientation = volume3 > 0 ? 1 : -1;
  const double sign = k.orientation;
  double largest = 0.0;
  for (const Surface& g : constraints)
    for (int i = 0; i < g.size(); ++i) {
      const auto p = g.point(i);
      largest = std::max(largest, Vec3(p[0], p[1], p[2]).norm());
    }
  const double eps = 1e-12 * size;
  std::vector<HalfSpace> spaces;
  for (const Surface& g : constraints)
    for (int i = 0; i < g.size(); ++i) {
      const auto p = g.point(i);
      const Vec3 n = sign * Vec3(p[0], p[1], p[2]);
      const double d = sign * p[3];
      const double len = n.norm();
      if (len <= 1e-10 * largest) {
        // A degenerate face (or corner) coefficient: 0 <= d, about K not at all.
        if (d < -eps * largest) return k;
        continue;
      }
      spaces.push_back({n / len, d / len});
    }
  k.constraints = static_cast<int>(spaces.size());

  // The box around the control points, as six faces counter-clockwise seen from outside.
  const Vec3 a = lo - Vec3::Constant(0.01 * size), b = hi + Vec3::Constant(0.01 * size);
  auto corner = [&](int i) { return Vec3(i & 1 ? b.x() : a.x(), i & 2 ? b.y() : a.y(), i & 4 ? b.z() : a.z()); };
  std::vector<Polygon3> poly{
      {corner(0), corner(4), corner(6), corner(2)},  // x min
      {corner(1), corner(3), corner(7), corner(5)},  // x max
      {corner(0), corner(1), corner(5), corner(4)},  // y min
      {corner(2), corner(6), corner(7), corner(3)},  // y max
      {corner(0), corner(2), corner(3), corner(1)},  // z min
      {corner(4), corner(5), corner(7), corner(6)},  // z max
  };
  for (const HalfSpace& h : spaces) {
    poly = clip(poly, h, eps);
    if (poly.size() < 4) return k;
  }
  finish(poly, eps, k);
  return k;
}

std::vector<Surface> oriented_boundary(const Trivariate& t) {
  // With det J > 0, S_s x S_t of the faces (parameters in increasing order) points outward on
  // u1, v0 and w1 and inward on u0, v1 and w0: reversing the first parameter of those flips it.
  std::vector<Surface> faces;
  for (spline::Face f : spline::all_faces) {
    Surface s = spline::boundary_face(t, f);
    if (f == spline::Face::u0 || f == spline::Face::v1 || f == spline::Face::w0) s = spline::reverse(s, 0);
    faces.push_back(std::move(s));
  }
  return faces;
}

SpatialKernel spatial_kernel(const Trivariate& t, const KernelOptions& options) {
  const auto faces = oriented_boundary(t);
  return spatial_kernel(faces, options);
}

PlanarKernel restrict_kernel(const PlanarKernel& k, std::span<const std::array<double, 3>> constraints) {
  PlanarKernel r;
  r.orientation = k.orientation;
  r.constraints = k.constraints + static_cast<int>(constraints.size());
  if (k.empty()) return r;
  std::vector<Vec2> poly;
  Vec2 lo = Vec2::Constant(HUGE_VAL), hi = Vec2::Constant(-HUGE_VAL);
  for (const auto& v : k.vertices) {
    poly.emplace_back(v[0], v[1]);
    lo = lo.cwiseMin(poly.back());
    hi = hi.cwiseMax(poly.back());
  }
  const double eps = 1e-12 * (hi - lo).norm();
  for (const auto& h : constraints) {
    const double len = std::hypot(h[0], h[1]);
    if (!(len > 0.0)) {
      if (h[2] < 0.0) return r;
      continue;
    }
    poly = clip(poly, HalfPlane{h[0] / len, h[1] / len, h[2] / len}, eps);
    if (poly.size() < 3) return r;
  }
  finish(poly, r);
  return r;
}

SpatialKernel restrict_kernel(const SpatialKernel& k, std::span<const std::array<double, 4>> constraints) {
  SpatialKernel r;
  r.orientation = k.orientation;
  r.constraints = k.constraints + static_cast<int>(constraints.size());
  if (k.empty()) return r;
  std::vector<Polygon3> poly;
  Vec3 lo = Vec3::Constant(HUGE_VAL), hi = Vec3::Constant(-HUGE_VAL);
  for (const auto& f : k.faces) {
    Polygon3 g;
    for (int id : f) {
      const auto& v = k.vertices[static_cast<std::size_t>(id)];
      g.emplace_back(v[0], v[1], v[2]);
      lo = lo.cwiseMin(g.back());
      hi = hi.cwiseMax(g.back());
    }
    poly.push_back(std::move(g));
  }
  const double eps = 1e-12 * (hi - lo).norm();
  for (const auto& h : constraints) {
    const Vec3 n(h[0], h[1], h[2]);
    const double len = n.norm();
    if (!(len > 0.0)) {
      if (h[3] < 0.0) return r;
      continue;
    }
    // a . x + d >= 0  <=>  (-a) . x <= d
    poly = clip(poly, HalfSpace{-n / len, h[3] / len}, eps);
    if (poly.size() < 4) return r;
  }
  finish(poly, eps, r);
  return r;
}

}  // namespace trivox::geom
