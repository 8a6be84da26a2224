#include "trivox/slice/boundary_faces.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>

#include "trivox/error.hpp"
#include "trivox/geom/face_trim.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/slice/locator.hpp"

namespace trivox::slice {

namespace {

/// A cutting curve all of whose control points lie within tol of its first (in the face's
/// parameters): a point at geom::trim_face's tolerance, which it would refuse as a closed curve
/// enclosing no area. Such short branches come where two faces meet at their rectangles'
/// edges (cells of one primitive touching along an edge, traced piecewise): they bound nothing.
bool point_like(const spline::Curve& c, double tol) {
  const auto p = c.points();
  for (std::size_t i = 2; i < p.size(); i += 2)
    if (std::hypot(p[i] - p[0], p[i + 1] - p[1]) > tol) return false;
  return true;
}

/// A cutting curve whose control points (hence the curve) lie within tol of one side of the
/// rectangle [du] x [dv]: geom::trim_face sets such curves aside (the rectangle's side is already
/// an edge), so they are left out before it, where they would only count towards its limit on
/// polyline segments. They come where a face meets the faces of the cells glued to its cell (of
/// one primitive) along its edges: a torus cell's edges are whole circles, traced in pieces.
bool along_side(const spline::Curve& c, std::array<double, 2> du, std::array<double, 2> dv, double tol) {
  const auto p = c.points();
  double lo[2] = {p[0], p[1]}, hi[2] = {p[0], p[1]};
  for (std::size_t i = 0; i < p.size(); i += 2)
    for (std::size_t k = 0; k < 2; ++k) lo[k] = std::min(lo[k], p[i + k]), hi[k] = std::max(hi[k], p[i + k]);
  return hi[1] - dv[0] <= tol || du[1] - lo[0] <= tol || dv[1] - lo[1] <= tol || hi[0] - du[0] <= tol;
}

}  // namespace

int face_orientation(spline::Face face) noexcept {
  switch (face) {
    case spline::Face::u1:
    case spline::Face::v0:
    case spline::Face::w1:
      return 1;
    default:
      return -1;
  }
}

std::vector<BoundaryFace> boundary_faces(const vmodel::VModel& model, int cell, const BoundaryFaceOptions& options) {
  if (cell < 0 || cell >= static_cast<int>(model.cells.size()))
    throw Error("boundary_faces: cell " + std::to_string(cell) + " out of range; the model has " +
                std::to_string(model.cells.size()) + " cells");
  const vmodel::VCell& c = model.cells[static_cast<std::size_t>(cell)];
  // Sources: index 0 the cell's own trivariate (plain), then the direct conditions.
  std::vector<vmodel::VCell> src;
  std::vector<bool> is_within;
  // The solid each source belongs to: the cells of one `without` list are one solid, whose
  // cells' faces touch and coincide along their shared faces by construction.
  std::vector<int> solid;
  src.emplace_back(c.name, c.volume);
  is_within.push_back(true);
  solid.push_back(0);
  for (const auto& w : c.within) src.push_back(w), is_within.push_back(true), solid.push_back(static_cast<int>(solid.size()));
  int next_solid = static_cast<int>(solid.size());
  for (const auto& list : c.without) {
    for (const auto& w : list) src.push_back(w), is_within.push_back(false), solid.push_back(next_solid);
    ++next_solid;
  }
  const std::size_t n = src.size();
  std::vector<vmodel::VModel> models(n);
  std::vector<std::unique_ptr<Locator>> locs;
  for (std::size_t k = 0; k < n; ++k) {
    models[k].properties = model.properties;
    models[k].cells.push_back(src[k]);
  }
  for (std::size_t k = 0; k < n; ++k) locs.push_back(std::make_unique<Locator>(models[k]));
  // Inside the piece, not deciding source `skip` (whose face the point lies on).
  auto admitted = [&](std::size_t skip, const double* x) {
    const Vec3 p{x[0], x[1], x[2]};
    for (std::size_t k = 0; k < n; ++k) {
      if (k == skip) continue;
      const bool in = locs[k]->locate(p).inside;
      if (in != static_cast<bool>(is_within[k])) return false;
    }
    return true;
  };
  std::vector<std::array<spline::Surface, 6>> faces(n);
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t f = 0; f < 6; ++f) faces[k][f] = spline::boundary_face(src[k].volume, spline::all_faces[f]);

  // The side each source's faces bound: its Jacobian's sign, reversed outside a `without` cell.
  std::vector<int> side(n);
  for (std::size_t k = 0; k < n; ++k)
    side[k] = (geom::signed_volume(src[k].volume) < 0 ? -1 : 1) * (is_within[k] ? 1 : -1);
  geom::IntersectionOptions io;
  io.tolerance = options.intersection_tolerance;
  auto face_of = [&](std::size_t k, std::size_t f) {
    return (k == 0 ? std::string("own face ") : "face ") + std::string(spline::face_name(spline::all_faces[f])) +
           (k == 0 ? std::string() : " of condition " + std::to_string(k - 1) + " '" + src[k].name + "'");
  };
  std::vector<geom::IntersectionContact> contacts;
  std::vector<BoundaryFace> out;
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t f = 0; f < 6; ++f) {
      const spline::Surface& F = faces[k][f];
      const double uv_tol =
          options.tolerance * std::max(F.domain(0)[1] - F.domain(0)[0], F.domain(1)[1] - F.domain(1)[0]);
      std::vector<spline::Curve> cuts;
      for (std::size_t j = 0; j < n; ++j) {
        if (j == k) continue;
        for (std::size_t g = 0; g < 6; ++g) {
          // Faces of different solids that touch along a curve or coincide over a region are not
          // cut there, so the piece's boundary would be wrong (or non-manifold): refused, naming
          // both faces. Faces of one solid (the cells of a primitive) meet so by construction.
          contacts.clear();
          for (auto& ic : geom::intersect_surfaces(F, faces[j][g], io, solid[j] != solid[k] ? &contacts : nullptr))
            if (ic.points.size() >= 2 && ic.uv1.dim() == 2 && !point_like(ic.uv1, uv_tol) &&
                !along_side(ic.uv1, F.domain(0), F.domain(1), uv_tol))
              cuts.push_back(std::move(ic.uv1));
          for (const auto& t : contacts) {
            if (t.kind == geom::IntersectionContact::Kind::point) continue;
            char at[96];
            std::snprintf(at, sizeof at, "(%.9g, %.9g, %.9g)", t.at.xyz[0], t.at.xyz[1], t.at.xyz[2]);
            throw Error("boundary_faces: cell " + std::to_string(cell) + " (" + c.name + "): " + face_of(k, f) + " and " +
                            face_of(j, g) +
                            (t.kind == geom::IntersectionContact::Kind::curve ? " touch tangentially along a curve through "
                                                                              : " coincide over a region around ") +
                            at + "; expected faces that cross or miss (such a contact is not cut: the piece would be " +
                            (t.kind == geom::IntersectionContact::Kind::curve ? "non-manifold there)" : "wrong there)"),
                        ErrorKind::failed);
          }
        }
      }
      geom::FaceTrimOptions fo;
      fo.tolerance = options.tolerance;
      fo.face_name = "cell " + std::to_string(cell) + " (" + c.name + "), " +
                     (k == 0 ? std::string("own") : "condition " + std::to_string(k - 1) + " (" + src[k].name + ")") +
                     " face " + std::string(spline::face_name(spline::all_faces[f]));
      for (auto& ts : geom::trim_face(F, cuts, [&](const double* x) { return admitted(k, x); }, fo)) {
        geom::Untrimmed patches = geom::untrim(ts);
        const double a = geom::area(patches);
        out.push_back({.cell = cell,
                       .source = static_cast<int>(k) - 1,
                       .source_name = src[k].name,
                       .face = spline::all_faces[f],
                       .surface = std::move(ts),
                       .area = a,
                       .orientation = face_orientation(spline::all_faces[f]) * side[k],
                       .patches = std::move(patches),
                       .glued = false,
                       .glued_to = -1});
      }
    }
  return out;
}

double boundary_area(const std::vector<BoundaryFace>& faces) {
  double a = 0;
  for (const auto& f : faces) a += f.area;
  return a;
}

}  // namespace trivox::slice
