// Building a scene (scene.hpp): primitives and their fields, constructors, Booleans and fillets
// applied in the file's order, with the quality report of each step.
#include "trivox/scene/scene.hpp"

#include <algorithm>
#include <chrono>
#include <map>

#include "../io/json_io.hpp"
#include "scene_construct.hpp"

#include "trivox/error.hpp"
#include "trivox/fillet/shepard.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/slice/trim.hpp"
#include "trivox/vmodel/boolean.hpp"

namespace trivox::scene {

namespace {

using namespace io::json_io;

template <class Objects>
const vmodel::VCell& find_cell(const Source& src, const Objects& objects, const std::string& name, const std::string& ptr) {
  for (const auto& o : objects) {
    for (const auto& c : o.cells)
      if (c.name == name) return c;
    if (o.name == name && o.cells.size() == 1) return o.cells.front();
    if (o.name == name)
      src.fail(ptr, quote(name) + " has " + std::to_string(o.cells.size()) +
                        " cells; expected one cell: name it (" + quote(o.cells.front().name) + ", ...)");
  }
  src.fail(ptr, "no cell named " + quote(name) + "; expected the name of a model cell (a primitive's cells are "
                "<name>.<part>)");
}

/// Masalha et al. 2021, Sec. 6 / 6.1: the fillet over several faces (fillet/corners.hpp): its
/// pieces' cells <name>.<k>a, <name>.<k>b in chain order, the bridges' <name>.c<j>a, <name>.c<j>b.
template <class Objects>
std::vector<vmodel::VCell> apply_fillet_across(const Source& src, const SceneOperation& op, const Objects& objects,
                                               SceneBuild& out) {
  std::array<std::vector<fillet::SideFace>, 2> sides;
  for (std::size_t i = 0; i < 2; ++i)
    for (const auto& sf : op.sides[i]) {
      const std::string ptr = sf.pointer + "/cell";
      const vmodel::VCell& c = find_cell(src, objects, sf.cell, ptr);
      if (!c.plain())
        src.fail(ptr, quote(sf.cell) + " is a trimmed piece of a Boolean; expected a plain cell (fillets of "
                      "trimmed cells are later work)");
      if (c.volume.rational()) src.fail(ptr, quote(sf.cell) + " is rational; expected a polynomial cell");
      sides[i].push_back({&c.volume, sf.face, sf.cell + "/" + std::string(spline::face_name(sf.face))});
    }
  fillet::MultiFillet mf;
  try {
    mf = fillet::fillet_across(sides[0], sides[1], op.fillet, op.corners);
  } catch (const Error& e) {
    throw e.within(src.at(op.pointer));
  }
  std::vector<vmodel::VCell> cells;
  std::size_t k = 0;
  for (const auto& piece : mf.pieces) {
    FilletBuild rep;
    rep.name = op.name;
    rep.pointer = op.pointer;
    rep.cells = {op.sides[0][piece.face[0]].cell, op.sides[1][piece.face[1]].cell};
    rep.faces = {op.sides[0][piece.face[0]].face, op.sides[1][piece.face[1]].face};
    for (const auto& f : piece.fillets) {
      const auto& q = f.quality;
      const std::string base = op.name + "." + std::to_string(++k);
      if (q.jacobian() == "changes sign")
        throw Error(src.at(op.pointer) + ": fillet " + base + " between " + sides[0][piece.face[0]].name + " and " +
                        sides[1][piece.face[1]].name + ": det J changes sign inside (from " + format_double(q.det_min) +
                        " to " + format_double(q.det_max) + "); expected a io::valid fillet: try other distances or tau",
                    ErrorKind::failed);
      rep.cell_names.push_back({base + "a", base + "b"});
      rep.quality.push_back(q);
      for (std::size_t c = 0; c < 2; ++c) cells.push_back(f.vcell(c, rep.cell_names.back()[c]));
    }
    out.fillets.push_back(std::move(rep));
  }
  const auto piece_name = [&](const fillet::FilletPiece& p) {
    return sides[0][p.face[0]].name + " x " + sides[1][p.face[1]].name;
  };
  for (std::size_t j = 0; j < mf.corners.size(); ++j) {
    const auto& cf = mf.corners[j];
    const fillet::Junction& jn = mf.junctions[cf.junction];
    CornerBuild rep;
    rep.name = op.name;
    rep.pointer = op.pointer;
    const std::string base = op.name + ".c" + std::to_string(j + 1);
    rep.cell_names = {base + "a", base + "b"};
    rep.pieces = {piece_name(mf.pieces[jn.piece[0]]), piece_name(mf.pieces[jn.piece[1]])};
    const std::size_t g = static_cast<std::size_t>(jn.gap_side);
    // A bridge split at a seam (part 1: from the seam to q) lies on the leaving piece's faces.
    const fillet::FilletPiece& on = mf.pieces[jn.piece[cf.part == 1 ? 1 : 0]];
    rep.faces = {sides[g][on.face[g]].name, sides[1 - g][on.face[1 - g]].name};
    rep.part = cf.part;
    rep.junction = jn;
    rep.quality = cf.quality;
    if (cf.quality.jacobian() == "changes sign")
      throw Error(src.at(op.pointer) + ": the bridging fillet " + base + " at the corner (" + format_double(jn.o[0]) +
                      ", " + format_double(jn.o[1]) + ", " + format_double(jn.o[2]) + "): det J changes sign inside (from " +
                      format_double(cf.quality.det_min) + " to " + format_double(cf.quality.det_max) +
                      "); expected a io::valid fillet: try other distances or tau",
                  ErrorKind::failed);
    for (std::size_t c = 0; c < 2; ++c) cells.emplace_back(rep.cell_names[c], cf.cells[c]);
    out.corners.push_back(std::move(rep));
  }
  for (const auto& jn : mf.junctions) {
    if (jn.kind != fillet::JunctionKind::stitch) continue;
    StitchBuild rep;
    rep.name = op.name;
    rep.pointer = op.pointer;
    rep.pieces = {piece_name(mf.pieces[jn.piece[0]]), piece_name(mf.pieces[jn.piece[1]])};
    const std::size_t g = static_cast<std::size_t>(jn.gap_side);
    rep.faces = {sides[g][mf.pieces[jn.piece[0]].face[g]].name, sides[1 - g][mf.pieces[jn.piece[0]].face[1 - g]].name};
    rep.junction = jn;
    out.stitches.push_back(std::move(rep));
  }
  return cells;
}

/// Masalha et al. 2021, Alg. 2 (or Sec. 3.2 / Alg. 3 with "construction": "vbs", Sec. 5 / Alg. 6
/// with "vrep") between two cells: the faces (given, or the one intersecting pair), the fillets,
/// their cells named <name>.<k>a and <name>.<k>b (vbs: <name>.<k>.1, .2, .3; vrep: the
/// trimmed cell <name>.<k>).
template <class Objects>
std::vector<vmodel::VCell> apply_fillet(const Source& src, const SceneOperation& op,
                                        const Objects& objects, SceneBuild& out) {
  if (op.across) return apply_fillet_across(src, op, objects, out);
  std::array<const vmodel::VCell*, 2> cell{};
  for (std::size_t i = 0; i < 2; ++i) {
    const std::string ptr = op.pointer + "/between/" + std::to_string(i);
    cell[i] = &find_cell(src, objects, op.between[i], ptr);
    if (!cell[i]->plain())
      src.fail(ptr, quote(op.between[i]) + " is a trimmed piece of a Boolean; expected a plain cell (fillets of "
                    "trimmed cells are later work)");
    if (cell[i]->volume.rational())
      src.fail(ptr, quote(op.between[i]) + " is rational; expected a polynomial cell");
  }
  if (op.bridge) {
    // Flends Sec. III: one cell from face to face (the reader made sure both faces are named).
    BridgeBuild rep;
    rep.name = op.name;
    rep.pointer = op.pointer;
    rep.cells = op.between;
    rep.faces = {*op.faces[0], *op.faces[1]};
    rep.cell_name = op.name + ".1";
    const auto start = std::chrono::steady_clock::now();
    spline::Trivariate t;
    try {
      t = fillet::bridge(cell[0]->volume, rep.faces[0], cell[1]->volume, rep.faces[1], {.dip = op.fillet.blend.dip},
                         &rep.quality);
    } catch (const Error& e) {
      throw e.within(src.at(op.pointer));
    }
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::vector<vmodel::VCell> cells;
    cells.emplace_back(rep.cell_name, std::move(t));
    out.bridges.push_back(std::move(rep));
    return cells;
  }
  std::array<spline::Face, 2> faces{};
  if (op.faces[0] && op.faces[1]) {
    faces = {*op.faces[0], *op.faces[1]};
  } else {
    // The pairs of faces that cross along a curve.
    geom::IntersectionOptions io;
    const auto b0 = spline::bounding_box(cell[0]->volume, 3), b1 = spline::bounding_box(cell[1]->volume, 3);
    double diag = 0.0;
    for (std::size_t j = 0; j < 3; ++j) {
      const double e = std::max(b0[1][j], b1[1][j]) - std::min(b0[0][j], b1[0][j]);
      diag += e * e;
    }
    io.tolerance = 1e-7 * std::sqrt(diag);
    std::vector<std::array<spline::Face, 2>> hits;
    for (spline::Face f0 : spline::all_faces) {
      if (op.faces[0] && f0 != *op.faces[0]) continue;
      const spline::Surface s0 = spline::boundary_face(cell[0]->volume, f0);
      for (spline::Face f1 : spline::all_faces) {
        if (op.faces[1] && f1 != *op.faces[1]) continue;
        const auto curves = geom::intersect_surfaces(s0, spline::boundary_face(cell[1]->volume, f1), io);
        const bool curve = std::any_of(curves.begin(), curves.end(), [](const auto& c) { return c.points.size() > 1; });
        if (curve) hits.push_back({f0, f1});
      }
    }
    const std::string names = quote(op.between[0]) + " and " + quote(op.between[1]);
    if (hits.empty())
      src.fail(op.pointer + "/between", "the faces of " + names + " do not intersect; expected cells whose "
                                        "boundaries cross along a curve");
    if (hits.size() > 1) {
      std::string list;
      for (const auto& h : hits)
        list += (list.empty() ? "" : ", ") + std::string(spline::face_name(h[0])) + "/" + std::string(spline::face_name(h[1]));
      src.fail(op.pointer + "/between", names + " intersect on several pairs of faces (" + list +
                                            "); expected one: choose the faces with {\"cell\", \"face\"} (fillets "
                                            "across several faces are later work)");
    }
    faces = hits.front();
  }
  std::vector<fillet::Fillet> fillets;
  try {
    fillets = fillet::fillet_faces(cell[0]->volume, faces[0], cell[1]->volume, faces[1], op.fillet);
  } catch (const Error& e) {
    throw e.within(src.at(op.pointer));
  }
  FilletBuild rep;
  rep.name = op.name;
  rep.pointer = op.pointer;
  rep.cells = op.between;
  rep.faces = faces;
  std::vector<vmodel::VCell> cells;
  for (std::size_t k = 0; k < fillets.size(); ++k) {
    const auto& q = fillets[k].quality;
    if (q.jacobian() == "changes sign")
      throw Error(src.at(op.pointer) + ": fillet " + std::to_string(k + 1) + " of " + quote(op.name) +
                      ": det J changes sign inside (from " + format_double(q.det_min) + " to " +
                      format_double(q.det_max) + "); expected a io::valid fillet: try other distances or tau",
                  ErrorKind::failed);
    const std::string base = op.name + "." + std::to_string(k + 1);
    // Ruled (Alg. 2): the halves <base>a, <base>b; VBS (Alg. 3): T_1, T_2, T_3 as <base>.1 .. .3;
    // V-rep (Alg. 6): the trimmed cell <base> (its trimming solid <base>.beyond.1, .2).
    std::vector<std::string> names;
    if (q.construction == fillet::Construction::vbs)
      names = {base + ".1", base + ".2", base + ".3"};
    else if (q.construction == fillet::Construction::vrep)
      names = {base};
    else
      names = {base + "a", base + "b"};
    rep.cell_names.push_back(names);
    rep.quality.push_back(q);
    if (!op.shepard) {
      for (std::size_t c = 0; c < names.size(); ++c) cells.push_back(fillets[k].vcell(c, names[c]));
      continue;
    }
    // Masalha et al. 2021, Sec. 7.2: both halves carry f, encoded, and S^_1, S^_2 (their faces w =
    // 0) for the exact per-voxel value.
    vmodel::ShepardData sd;
    sd.power = op.shepard_power;
    for (std::size_t h = 0; h < 2; ++h) sd.sources[h] = spline::boundary_face(fillets[k].cells[h], spline::Face::w0);
    const vmodel::ShepardField field(sd);
    for (std::size_t h = 0; h < 2; ++h) {
      auto enc = fillet::encode_shepard(fillets[k].cells[h], field, {.power = op.shepard_power});
      rep.shepard.push_back({enc.max_error, enc.rms_error, enc.check_error, enc.samples, enc.seconds});
      cells.emplace_back(base + (h == 0 ? "a" : "b"), std::move(enc.half));
    }
    // The sources as the encoded halves' faces w = 0 (the same surfaces, refined across C): the
    // encoded properties there are then the sources' g_i, control point for control point.
    for (std::size_t h = 0; h < 2; ++h)
      sd.sources[h] = spline::boundary_face(cells[cells.size() - 2 + h].volume, spline::Face::w0);
    for (std::size_t h = 0; h < 2; ++h) cells[cells.size() - 2 + h].shepard = sd;
  }
  out.fillets.push_back(std::move(rep));
  return cells;
}

/// The scene's Boolean and fillet operations, in order, on named objects: each scene cell (a
/// primitive's cells together) is an object; a Boolean replaces its operands by its result,
/// placed where `a` was; a fillet appends its cells as a new object. The primitives' reports keep
/// only the primitives no Boolean consumed.
void apply_operations(const Scene& scene, const Source& src, SceneBuild& out) {
  struct Object {
    std::string name;
    std::vector<vmodel::VCell> cells;
    int primitive = -1;  ///< index into out.primitives, -1 for a result or a trivariate cell
  };
  std::vector<Object> objects;
  std::size_t next = 0;
  for (const SceneCell& cell : scene.cells) {
    Object o;
    o.name = cell.name;
    int count = 1;
    for (std::size_t p = 0; p < out.primitives.size(); ++p)
      if (out.primitives[p].name == cell.name) {
        o.primitive = static_cast<int>(p);
        count = out.primitives[p].cell_count;
      }
    for (int k = 0; k < count; ++k) o.cells.push_back(std::move(out.model.cells[next++]));
    objects.push_back(std::move(o));
  }
  std::optional<std::map<std::string, spline::Surface>> surfaces;  // resolved at the first constructor
  const auto find_object = [&](const std::string& name) {
    return std::find_if(objects.begin(), objects.end(), [&](const Object& o) { return o.name == name; });
  };
  for (const SceneOperation& op : scene.operations) {
    if (detail::is_constructor(op.op)) {
      if (find_object(op.name) != objects.end())
        src.fail(op.pointer + "/name", quote(op.name) + " names another cell or result; expected a fresh name");
      if (!surfaces) surfaces = detail::resolve_surfaces(scene, src, out);
      objects.push_back({op.name, detail::apply_constructor(scene, src, op, *surfaces, out), -1});
      continue;
    }
    if (op.op == "fillet") {
      if (find_object(op.name) != objects.end())
        src.fail(op.pointer + "/name", quote(op.name) + " names another cell or result; expected a fresh name");
      Object result{op.name, apply_fillet(src, op, objects, out), -1};
      objects.push_back(std::move(result));
      continue;
    }
    const auto ia = find_object(op.a);
    if (ia == objects.end())
      src.fail(op.pointer + "/a", "no cell or result named " + quote(op.a) + "; expected the name of a scene cell or of an earlier operation's result");
    const auto ib = find_object(op.b);
    if (ib == objects.end())
      src.fail(op.pointer + "/b", "no cell or result named " + quote(op.b) + "; expected the name of a scene cell or of an earlier operation's result");
    if (ia == ib) src.fail(op.pointer + "/b", quote(op.b) + " is also \"a\"; expected two different operands");
    if (op.name != op.a && op.name != op.b && find_object(op.name) != objects.end())
      src.fail(op.pointer + "/name", quote(op.name) + " names another cell or result; expected a fresh name");
    vmodel::VModel A, B;
    A.units = B.units = scene.units;
    A.properties = B.properties = scene.properties;
    A.cells = ia->cells;
    B.cells = ib->cells;
    const vmodel::BooleanOp kind = op.op == "union" ? vmodel::BooleanOp::union_op
                                   : op.op == "intersection" ? vmodel::BooleanOp::intersection
                                                             : vmodel::BooleanOp::subtraction;
    vmodel::VModel r;
    try {
      r = slice::untrim(vmodel::boolean(A, B, kind, {.blend = op.blend, .power = op.power}));
    } catch (const Error& e) {
      throw e.within(src.at(op.pointer));
    }
    if (r.cells.empty())
      src.fail(op.pointer, "the " + op.op + " of " + quote(op.a) + " and " + quote(op.b) +
                               " is empty (their boxes do not meet); expected operands that overlap");
    Object result{op.name, std::move(r.cells), -1};
    const std::size_t at = static_cast<std::size_t>(ia - objects.begin());
    const std::size_t bt = static_cast<std::size_t>(ib - objects.begin());
    objects[at] = std::move(result);
    objects.erase(objects.begin() + static_cast<std::ptrdiff_t>(bt));
  }
  // The model: the remaining objects in order; reports for the untouched primitives.
  std::vector<PrimitiveBuild> kept;
  out.model.cells.clear();
  std::map<std::string, std::string> names;
  for (auto& o : objects) {
    if (o.primitive >= 0) {
      PrimitiveBuild rep = std::move(out.primitives[static_cast<std::size_t>(o.primitive)]);
      rep.first_cell = static_cast<int>(out.model.cells.size());
      kept.push_back(std::move(rep));
    }
    for (auto& c : o.cells) {
      if (!names.emplace(c.name, o.name).second)
        src.fail("/operations", "the result has two cells named " + quote(c.name) + "; expected distinct cell names "
                                "(rename a scene cell)");
      out.model.cells.push_back(std::move(c));
    }
  }
  out.primitives = std::move(kept);
}

}  // namespace

SceneBuild build_scene(const Scene& scene) {
  const Source src{scene.source};
  for (const SceneOperation& op : scene.operations) {
    const bool boolean = op.op == "union" || op.op == "intersection" || op.op == "subtraction";
    if (boolean || op.op == "fillet" || detail::is_constructor(op.op)) continue;
    src.fail(op.pointer + "/op",
             quote(op.op) + " is not supported yet in scenes (`trivox construct` runs it on its own); expected "
                 "union, intersection, subtraction, fillet, ruled, boolean_sum, half_boolean_sum, extrude, revolve or sweep");
  }
  SceneBuild out;
  out.model.units = scene.units;
  out.model.properties = scene.properties;
  out.model.surfaces = scene.surfaces;
  std::map<std::string, std::string> owner;  // model cell name -> scene pointer
  auto add = [&](std::string name, spline::Trivariate volume, const SceneCell& from) {
    const auto [it, fresh] = owner.emplace(name, from.pointer);
    if (!fresh)
      src.fail(from.pointer + "/name", "cell " + quote(name) + " (from " + quote(from.name) + ") is also a cell of " +
                                           it->second + "; expected unique cell names (a primitive's cells are "
                                           "named <name>.<part>)");
    out.model.cells.push_back({std::move(name), std::move(volume)});
  };
  for (const auto& s : scene.surfaces) owner.emplace(s.name, "/surfaces");
  for (const SceneCell& cell : scene.cells) {
    if (const auto* t = std::get_if<spline::Trivariate>(&cell.content)) {
      add(cell.name, *t, cell);
      continue;
    }
    const auto& p = std::get<ScenePrimitive>(cell.content);
    PrimitiveBuild report;
    report.name = cell.name;
    report.type = construct::primitive_type(p.primitive);
    report.first_cell = static_cast<int>(out.model.cells.size());
    report.exact_volume = construct::exact_volume(p.primitive);
    try {
      auto cells = construct::build_primitive(cell.name, p.primitive, p.options);
      for (const auto& c : cells) report.geometry.push_back(c.volume);
      if (p.field) {
        report.has_field = true;
        report.field = construct::apply_field(cells, *p.field);
      }
      report.cell_count = static_cast<int>(cells.size());
      for (auto& c : cells) add(std::move(c.name), std::move(c.volume), cell);
    } catch (const Error& e) {
      if (std::string_view(e.what()).starts_with(scene.source + ": ")) throw;
      throw e.within(src.at(cell.pointer));
    }
    out.primitives.push_back(std::move(report));
  }
  if (!scene.operations.empty()) apply_operations(scene, src, out);
  return out;
}

}  // namespace trivox::scene
