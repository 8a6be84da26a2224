#include "trivox/geom/planar_crossing.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::geom {

namespace {

struct Vertex {
  double t, x, y;
};

/// Polyline of a Bezier piece within `tol` of it: its control polygon, once within tol of the
/// chord, bounds the piece's distance from the chord (convex hull property).
void flatten_piece(const spline::Curve& b, double tol, int depth, std::vector<Vertex>& out) {
  const int n = b.size();
  const auto p0 = b.point(0), p1 = b.point(n - 1);
  const double cx = p1[0] - p0[0], cy = p1[1] - p0[1];
  const double len = std::hypot(cx, cy);
  double dev = 0.0;
  for (int i = 1; i + 1 < n; ++i) {
    const auto q = b.point(i);
    const double dx = q[0] - p0[0], dy = q[1] - p0[1];
    dev = std::max(dev, len > 0 ? std::abs(cx * dy - cy * dx) / len : std::hypot(dx, dy));
  }
  if (dev <= tol || depth >= 40) {
    out.push_back({b.domain(0)[1], p1[0], p1[1]});
    return;
  }
  const auto dom = b.domain(0);
  auto [l, r] = spline::split(b, 0, 0.5 * (dom[0] + dom[1]));
  flatten_piece(l, tol, depth + 1, out);
  flatten_piece(r, tol, depth + 1, out);
}

std::vector<Vertex> flatten(const spline::Curve& c, double tol) {
  std::vector<Vertex> out;
  const auto pieces = spline::bezier_pieces(c);
  const auto p = pieces.front().point(0);
  out.push_back({c.domain(0)[0], p[0], p[1]});
  for (const auto& b : pieces) flatten_piece(b, tol, 0, out);
  return out;
}

double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

/// Where segments a0-a1 and b0-b1 cross or touch: parameters (s, u) in [0, 1].
bool segments_meet(const Vertex& a0, const Vertex& a1, const Vertex& b0, const Vertex& b1, double& s, double& u) {
  const double rx = a1.x - a0.x, ry = a1.y - a0.y, qx = b1.x - b0.x, qy = b1.y - b0.y;
  const double den = cross(rx, ry, qx, qy);
  const double wx = b0.x - a0.x, wy = b0.y - a0.y;
  if (den == 0.0) {
    if (cross(wx, wy, rx, ry) != 0.0) return false;  // parallel, apart
    const double rr = rx * rx + ry * ry;
    if (rr == 0.0) return false;
    const double t0 = (wx * rx + wy * ry) / rr, t1 = ((b1.x - a0.x) * rx + (b1.y - a0.y) * ry) / rr;
    if (std::max(t0, t1) < 0.0 || std::min(t0, t1) > 1.0) return false;  // collinear, disjoint
    s = std::clamp(std::max(0.0, std::min(t0, t1)), 0.0, 1.0);
    u = t1 != t0 ? std::clamp((s - t0) / (t1 - t0), 0.0, 1.0) : 0.0;
    return true;
  }
  s = cross(wx, wy, qx, qy) / den;
  u = cross(wx, wy, rx, ry) / den;
  return s >= 0.0 && s <= 1.0 && u >= 0.0 && u <= 1.0;
}

}  // namespace

std::optional<PlanarCrossing> first_crossing(std::span<const spline::Curve> curves, double tolerance) {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance))
    throw Error("crossing tolerance " + std::to_string(tolerance) + "; expected a positive length");
  std::vector<std::vector<Vertex>> lines;
  for (std::size_t i = 0; i < curves.size(); ++i) {
    if (curves[i].dim() < 2)
      throw Error("curve " + std::to_string(i) + " has " + std::to_string(curves[i].dim()) +
                  " coordinate(s); expected planar curves (x, y first)");
    lines.push_back(flatten(curves[i], tolerance));
  }
  // Endpoints shared by two curve ends (boundary corners, or a closed curve's seam).
  const double near = 10.0 * tolerance;
  std::vector<std::array<double, 2>> corners;
  for (std::size_t a = 0; a < lines.size(); ++a)
    for (const Vertex* e : {&lines[a].front(), &lines[a].back()})
      for (std::size_t b = 0; b < lines.size(); ++b)
        for (const Vertex* f : {&lines[b].front(), &lines[b].back()})
          if (e != f && std::hypot(e->x - f->x, e->y - f->y) <= near) corners.push_back({e->x, e->y});
  const auto at_corner = [&](double x, double y) {
    for (const auto& c : corners)
      if (std::hypot(x - c[0], y - c[1]) <= near) return true;
    return false;
  };
  for (std::size_t a = 0; a < lines.size(); ++a)
    for (std::size_t b = a; b < lines.size(); ++b) {
      const auto& A = lines[a];
      const auto& B = lines[b];
      for (std::size_t i = 0; i + 1 < A.size(); ++i)
        for (std::size_t j = (a == b ? i + 2 : 0); j + 1 < B.size(); ++j) {
          double s, u;
          if (!segments_meet(A[i], A[i + 1], B[j], B[j + 1], s, u)) continue;
          const double x = A[i].x + s * (A[i + 1].x - A[i].x), y = A[i].y + s * (A[i + 1].y - A[i].y);
          if (at_corner(x, y)) continue;
          PlanarCrossing c;
          c.curve_a = static_cast<int>(a);
          c.curve_b = static_cast<int>(b);
          c.t_a = A[i].t + s * (A[i + 1].t - A[i].t);
          c.t_b = B[j].t + u * (B[j + 1].t - B[j].t);
          c.point = {x, y};
          return c;
        }
    }
  return std::nullopt;
}

}  // namespace trivox::geom
