#include "trivox/slice/boundary_faces.hpp"

#include <cmath>
#include <memory>
#include <utility>

#include "trivox/error.hpp"
#include "trivox/geom/face_trim.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/slice/locator.hpp"

namespace trivox::slice {

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
  src.emplace_back(c.name, c.volume);
  is_within.push_back(true);
  for (const auto& w : c.within) src.push_back(w), is_within.push_back(true);
  for (const auto& list : c.without)
    for (const auto& w : list) src.push_back(w), is_within.push_back(false);
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
  std::vector<BoundaryFace> out;
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t f = 0; f < 6; ++f) {
      const spline::Surface& F = faces[k][f];
      std::vector<spline::Curve> cuts;
      for (std::size_t j = 0; j < n; ++j) {
        if (j == k) continue;
        for (std::size_t g = 0; g < 6; ++g)
          for (auto& ic : geom::intersect_surfaces(F, faces[j][g], io))
            if (ic.points.size() >= 2 && ic.uv1.dim() == 2) cuts.push_back(std::move(ic.uv1));
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
