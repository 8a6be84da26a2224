#include "trivox/vmodel/boolean.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "trivox/error.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/vmodel/topology.hpp"

namespace trivox::vmodel {

namespace {

using Box = std::array<std::array<double, 3>, 2>;

/// A conservative xyz box of a cell's region: its trivariate's box, narrowed to every within
/// cell's box (the region lies in all of them).
Box region_box(const VCell& c) {
  const auto b = spline::bounding_box(c.volume, 3);
  Box box{{{b[0][0], b[0][1], b[0][2]}, {b[1][0], b[1][1], b[1][2]}}};
  for (const auto& w : c.within) {
    const Box wb = region_box(w);
    for (std::size_t d = 0; d < 3; ++d) {
      box[0][d] = std::max(box[0][d], wb[0][d]);
      box[1][d] = std::min(box[1][d], wb[1][d]);
    }
  }
  return box;
}

bool overlap(const Box& a, const Box& b) {
  for (std::size_t d = 0; d < 3; ++d)
    if (a[0][d] > b[1][d] || b[0][d] > a[1][d] || a[0][d] > a[1][d] || b[0][d] > b[1][d]) return false;
  return true;
}

void check_compatible(const VModel& a, const VModel& b, BooleanOp op) {
  const std::string what = std::string(boolean_op_name(op)) + " of two models";
  if (a.cells.empty() || b.cells.empty())
    throw Error(what + ": the " + (a.cells.empty() ? "first" : "second") +
                " model has no cells; expected volumetric cells in both");
  if (a.properties != b.properties) {
    auto list = [](const std::vector<std::string>& p) {
      std::string s = "[";
      for (std::size_t i = 0; i < p.size(); ++i) s += (i ? ", " : "") + p[i];
      return s + "]";
    };
    throw Error(what + ": properties " + list(a.properties) + " and " + list(b.properties) +
                "; expected the same property names in the same order");
  }
  if (a.units != b.units)
    throw Error(what + ": units " + a.units + " and " + b.units + "; expected the same units");
}

/// a - (the cells of b that may meet a), or a itself when none can.
VCell minus(const VCell& a, const std::vector<VCell>& b, const std::vector<Box>& b_boxes) {
  const Box ab = region_box(a);
  std::vector<VCell> near;
  for (std::size_t j = 0; j < b.size(); ++j)
    if (overlap(ab, b_boxes[j])) near.push_back(b[j]);
  VCell out = a;
  if (!near.empty()) out.without.push_back(std::move(near));
  return out;
}

/// The faces of m's cells glued to no other cell, as xyz surfaces.
std::vector<spline::Surface> boundary_of(const VModel& m) {
  const Topology topo = build_topology(m);
  std::vector<spline::Surface> out;
  for (const auto& h : topo.half_v_surfaces)
    if (h.twin < 0)
      out.push_back(spline::coordinates(spline::boundary_face(m.cells[static_cast<std::size_t>(h.cell)].volume, h.face), 0, 3));
  return out;
}

/// Where the faces of `others` (those whose boxes meet home's) cut home's six faces: curves in
/// each face's parameters (Massarwi & Elber 2016, Sec. 4: the trimming curves of
/// the boundary V-surfaces).
std::vector<FaceTrim> cut_faces(const VCell& home, const std::vector<VCell>& others, const std::vector<Box>& boxes,
                                double tolerance) {
  const Box hb = region_box(home);
  std::vector<FaceTrim> out;
  for (auto f : spline::all_faces) {
    const spline::Surface S = spline::coordinates(spline::boundary_face(home.volume, f), 0, 3);
    FaceTrim t;
    t.face = f;
    for (std::size_t j = 0; j < others.size(); ++j) {
      if (!overlap(hb, boxes[j])) continue;
      for (auto g : spline::all_faces) {
        const spline::Surface G = spline::coordinates(spline::boundary_face(others[j].volume, g), 0, 3);
        for (auto& c : geom::intersect_surfaces(S, G, {.tolerance = tolerance}))
          if (c.points.size() >= 2) t.curves.push_back(std::move(c.uv1));
      }
    }
    if (!t.curves.empty()) out.push_back(std::move(t));
  }
  return out;
}

double model_size(const VModel& a, const VModel& b) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (const auto* m : {&a, &b})
    for (const auto& c : m->cells) {
      const Box bx = region_box(c);
      for (std::size_t d = 0; d < 3; ++d) lo[d] = std::min(lo[d], bx[0][d]), hi[d] = std::max(hi[d], bx[1][d]);
    }
  return std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

class Names {
public:
  std::string unique(const std::string& name) {
    std::string n = name;
    for (int k = 2; !used_.insert(n).second; ++k) n = name + "." + std::to_string(k);
    return n;
  }

private:
  std::set<std::string> used_;
};

}  // namespace

const char* boolean_op_name(BooleanOp op) noexcept {
  switch (op) {
    case BooleanOp::union_op: return "union";
    case BooleanOp::intersection: return "intersection";
    case BooleanOp::subtraction: return "subtraction";
  }
  return "union";
}

VModel boolean(const VModel& a, const VModel& b, BooleanOp op, const BooleanOptions& options) {
  check_compatible(a, b, op);
  if (options.blend == BlendRule::distance && !(options.power > 0 && std::isfinite(options.power)))
    throw Error(std::string(boolean_op_name(op)) + ": distance blend power " + std::to_string(options.power) +
                "; expected a positive power");
  const bool distance = options.blend == BlendRule::distance && op != BooleanOp::subtraction;
  const std::vector<spline::Surface> a_boundary = distance ? boundary_of(a) : std::vector<spline::Surface>{};
  const std::vector<spline::Surface> b_boundary = distance ? boundary_of(b) : std::vector<spline::Surface>{};
  std::vector<Box> a_boxes, b_boxes;
  for (const auto& c : a.cells) a_boxes.push_back(region_box(c));
  for (const auto& c : b.cells) b_boxes.push_back(region_box(c));
  VModel out;
  out.units = a.units;
  out.properties = a.properties;
  out.surfaces = a.surfaces;
  out.surfaces.insert(out.surfaces.end(), b.surfaces.begin(), b.surfaces.end());
  Names names;
  // Trimming curves of each input cell's faces by the other input (computed once per cell).
  std::vector<std::vector<FaceTrim>> a_cuts(a.cells.size()), b_cuts(b.cells.size());
  if (options.trim_curves) {
    const double tol = 1e-9 * std::max(1e-300, model_size(a, b));
    for (std::size_t i = 0; i < a.cells.size(); ++i) a_cuts[i] = cut_faces(a.cells[i], b.cells, b_boxes, tol);
    if (op == BooleanOp::union_op)
      for (std::size_t j = 0; j < b.cells.size(); ++j) b_cuts[j] = cut_faces(b.cells[j], a.cells, a_boxes, tol);
  }
  const auto add_cuts = [](VCell& c, const std::vector<FaceTrim>& cuts) {
    for (const auto& t : cuts) {
      auto it = std::find_if(c.trim_curves.begin(), c.trim_curves.end(), [&](const FaceTrim& x) { return x.face == t.face; });
      if (it == c.trim_curves.end()) c.trim_curves.push_back(t);
      else it->curves.insert(it->curves.end(), t.curves.begin(), t.curves.end());
    }
  };
  // Alg. 1: every pair of cells whose boxes meet; the first input's trivariate carries the
  // geometry, the second rides along in `within`.
  if (op != BooleanOp::subtraction)
    for (std::size_t i = 0; i < a.cells.size(); ++i)
      for (std::size_t j = 0; j < b.cells.size(); ++j) {
        if (!overlap(a_boxes[i], b_boxes[j])) continue;
        VCell c = a.cells[i];
        c.name = names.unique(a.cells[i].name + options.join + b.cells[j].name);
        if (distance) {
          // One boundary per blended value: a's own (kept when a was blended so before), then b's.
          const auto& ai = a.cells[i];
          if (!(ai.blend == BlendRule::distance && ai.boundaries.size() == 1 + ai.within.size()))
            c.boundaries.assign(1 + ai.within.size(), a_boundary);
          c.boundaries.push_back(b_boundary);
          c.blend_power = options.power;
        }
        c.within.push_back(b.cells[j]);
        c.blend = options.blend;
        add_cuts(c, a_cuts[i]);
        out.cells.push_back(std::move(c));
      }
  // Alg. 2: A - B (and, for the union, B - A), each cell minus the whole other model.
  if (op != BooleanOp::intersection)
    for (std::size_t i = 0; i < a.cells.size(); ++i) {
      VCell d = minus(a.cells[i], b.cells, b_boxes);
      d.name = names.unique(a.cells[i].name);
      add_cuts(d, a_cuts[i]);
      out.cells.push_back(std::move(d));
    }
  if (op == BooleanOp::union_op)
    for (std::size_t j = 0; j < b.cells.size(); ++j) {
      VCell d = minus(b.cells[j], a.cells, a_boxes);
      d.name = names.unique(b.cells[j].name);
      add_cuts(d, b_cuts[j]);
      out.cells.push_back(std::move(d));
    }
  return out;
}

}  // namespace trivox::vmodel
