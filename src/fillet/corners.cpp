/// @file src/fillet/corners.cpp
/// @brief fillet_across (Masalha et al. 2021, Sec. 6 and 6.1): the fillets between two bodies'
/// faces whose intersection curve C is only piecewise C1. One fillet per face pair and component
/// of C; the pieces chained where their ends meet; each junction classified (smooth, convex
/// corner, concave corner); the concave corners clipped and stitched (corner_stitch.cpp); the
/// convex ones bridged (corner_fillet.cpp, split at a seam by corner_seam.cpp) and glued to
/// their neighbours (corner_glue.cpp). trivox/fillet/corners.hpp gives the construction.
///
/// Cost: one surface intersection per pair of faces and one fillet_faces per crossing pair; the
/// chaining O(pieces^2); per concave corner two clips and a pinning, per convex corner one or two
/// bridges, each glued by pinning after trying the four pairs of end faces (13 x 13 samples
/// each).
#include "trivox/fillet/corners.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "corner_util.hpp"
#include "fillet_util.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/closest_point.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/spline/extract.hpp"

namespace trivox::fillet {

using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using spline::Trivariate;
using detail::Vec;
using namespace detail;

std::string detail::at(const Vec& p) { return std::string("(") + num(p[0]) + ", " + num(p[1]) + ", " + num(p[2]) + ")"; }

namespace {

Vec eval3(const Surface& s, const Curve& c, double t, Vec* tangent = nullptr) {
  const auto cd = c.eval_derivatives({t}, 1);
  const auto d = s.eval_derivatives({cd[0], cd[1]}, 1);
  const std::size_t k = static_cast<std::size_t>(s.dim());
  if (tangent) *tangent = axpy(scale(xyz(d.data() + k), cd[2]), cd[3], xyz(d.data() + 2 * k));
  return xyz(d.data());
}

std::string piece_name(const FilletPiece& p, const std::vector<SideFace>& s1, const std::vector<SideFace>& s2) {
  return s1[p.face[0]].name + " x " + s2[p.face[1]].name;
}

}  // namespace

MultiFillet fillet_across(const std::vector<SideFace>& side1, const std::vector<SideFace>& side2,
                          const FilletOptions& o, const CornerOptions& co) {
  if (side1.empty() || side2.empty()) throw Error("fillet across faces: a side without faces; expected at least one face each");
  const std::array<const std::vector<SideFace>*, 2> sides{&side1, &side2};
  double diag = 0.0;
  {
    std::array<double, 3> lo, hi;
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (const auto* side : sides)
      for (const SideFace& sf : *side) {
        if (sf.cell == nullptr) throw Error("fillet across faces: " + sf.name + " has no cell");
        const auto b = spline::bounding_box(*sf.cell, 3);
        for (std::size_t j = 0; j < 3; ++j) lo[j] = std::min(lo[j], b[0][j]), hi[j] = std::max(hi[j], b[1][j]);
      }
    diag = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  }
  FilletOptions fo = o;
  if (!(fo.tolerance > 0.0)) fo.tolerance = 1e-7 * diag;
  if (fo.construction != Construction::ruled)
    throw Error("fillet across faces: construction " + std::string(construction_name(fo.construction)) +
                "; expected \"ruled\" (Masalha et al. 2021, Sec. 6 here joins ruled fillets, Alg. 2)");
  const double tol = fo.tolerance;
  const double jt = co.join_tolerance > 0.0 ? co.join_tolerance
                                            : std::max(100.0 * tol, 1e-4 * std::min(fo.distance[0], fo.distance[1]));
  MultiFillet out;
  // Step 1: the pairs that cross along a curve, one fillet per component (Sec. 6).
  std::vector<FilletPiece> pieces;
  geom::IntersectionOptions io;
  io.tolerance = tol;
  for (std::size_t i = 0; i < side1.size(); ++i) {
    const Surface s1 = spline::boundary_face(*side1[i].cell, side1[i].face);
    for (std::size_t j = 0; j < side2.size(); ++j) {
      const Surface s2 = spline::boundary_face(*side2[j].cell, side2[j].face);
      const auto curves = geom::intersect_surfaces(s1, s2, io);
      if (std::none_of(curves.begin(), curves.end(), [](const auto& c) { return c.points.size() > 1; })) continue;
      std::vector<Fillet> fs;
      try {
        fs = fillet_faces(*side1[i].cell, side1[i].face, *side2[j].cell, side2[j].face, fo);
      } catch (const Error& e) {
        throw e.within("fillet between " + side1[i].name + " and " + side2[j].name);
      }
      // Group by component.
      for (auto& fl : fs) {
        if (pieces.empty() || pieces.back().face != std::array<std::size_t, 2>{i, j} ||
            pieces.back().fillets.front().component != fl.component) {
          FilletPiece p;
          p.face = {i, j};
          const RailPair& rp = fl.rails;
          p.closed = rp.closed;
          for (int e = 0; e < 2; ++e) {
            const double t = e;
            auto& end = p.ends[static_cast<std::size_t>(e)];
            end.o = eval3(s1, rp.rails[0].base, t, &end.tangent);
            const Surface* faces[2] = {&s1, &s2};
            for (std::size_t k = 0; k < 2; ++k) {
              const auto b = rp.rails[k].base.eval({t}), rr = rp.rails[k].rail.eval({t});
              end.o_uv[k] = {b[0], b[1]};
              end.rail_uv[k] = {rr[0], rr[1]};
              end.rail[k] = point_at(*faces[k], end.rail_uv[k]);
            }
          }
          pieces.push_back(std::move(p));
        }
        pieces.back().fillets.push_back(std::move(fl));
      }
    }
  }
  if (pieces.empty()) {
    std::string list1, list2;
    for (const auto& s : side1) list1 += (list1.empty() ? "" : ", ") + s.name;
    for (const auto& s : side2) list2 += (list2.empty() ? "" : ", ") + s.name;
    throw Error("fillet across faces: the faces " + list1 + " and " + list2 +
                " do not intersect; expected faces that cross along a curve");
  }
  // Chain the pieces at their ends.
  const std::size_t np = pieces.size();
  std::vector<std::array<long, 2>> mate(np, {-1, -1});  // mate[p][e] = 2 * piece + end
  for (std::size_t a = 0; a < np; ++a)
    for (int ea = 0; ea < 2; ++ea) {
      if (pieces[a].closed) continue;
      for (std::size_t b = a + 1; b < np; ++b)
        for (int eb = 0; eb < 2; ++eb) {
          if (pieces[b].closed) continue;
          if (norm(sub(pieces[a].ends[static_cast<std::size_t>(ea)].o, pieces[b].ends[static_cast<std::size_t>(eb)].o)) > jt)
            continue;
          for (const auto& [x, ex] : {std::pair{a, ea}, std::pair{b, eb}})
            if (mate[x][static_cast<std::size_t>(ex)] >= 0)
              throw Error("fillet across faces: three or more pieces of C meet at " +
                          at(pieces[x].ends[static_cast<std::size_t>(ex)].o) + " (" + piece_name(pieces[x], side1, side2) +
                          " among them); expected a curve C whose pieces meet in pairs (Masalha et al. 2021, Sec. 6)");
          mate[a][static_cast<std::size_t>(ea)] = static_cast<long>(2 * b + static_cast<std::size_t>(eb));
          mate[b][static_cast<std::size_t>(eb)] = static_cast<long>(2 * a + static_cast<std::size_t>(ea));
        }
    }
  // Walk: from the first piece with a free end (an open chain), else piece 0; each piece entered
  // at one end leaves at the other. Pieces in other chains follow in their own walks.
  std::vector<bool> used(np, false);
  std::vector<std::size_t> order;
  std::vector<Junction> junctions;
  int chains = 0;
  bool any_open = false;
  while (order.size() < np) {
    std::size_t startp = np;
    int enter = 0;
    for (std::size_t a = 0; a < np && startp == np; ++a)
      if (!used[a])
        for (int e = 0; e < 2; ++e)
          if (mate[a][static_cast<std::size_t>(e)] < 0 && !pieces[a].closed) {
            startp = a, enter = e;
            break;
          }
    if (startp == np)
      for (std::size_t a = 0; a < np; ++a)
        if (!used[a]) {
          startp = a;
          break;
        }
    ++chains;
    std::size_t cur = startp;
    int in_end = enter;
    while (true) {
      used[cur] = true;
      order.push_back(cur);
      const int out_end = 1 - in_end;
      if (pieces[cur].closed) break;
      const long m = mate[cur][static_cast<std::size_t>(out_end)];
      if (m < 0) {
        any_open = true;
        break;
      }
      const std::size_t nxt = static_cast<std::size_t>(m / 2);
      const int ne = static_cast<int>(m % 2);
      Junction jn;
      jn.piece = {cur, nxt};  // input indices; chain indices below
      jn.end = {out_end, ne};
      junctions.push_back(jn);
      if (used[nxt]) break;  // closed the loop
      cur = nxt;
      in_end = ne;
    }
  }
  out.closed = chains == 1 && !any_open && !pieces[order.front()].closed;
  // Re-index pieces in chain order.
  std::vector<std::size_t> pos(np);
  for (std::size_t k = 0; k < np; ++k) pos[order[k]] = k;
  for (std::size_t k = 0; k < np; ++k) out.pieces.push_back(std::move(pieces[order[k]]));
  // Classify the junctions (file comment).
  for (Junction& jn : junctions) {
    jn.piece = {pos[jn.piece[0]], pos[jn.piece[1]]};
    const FilletPiece& pa = out.pieces[jn.piece[0]];
    const FilletPiece& pb = out.pieces[jn.piece[1]];
    const auto& ea = pa.ends[static_cast<std::size_t>(jn.end[0])];
    const auto& eb = pb.ends[static_cast<std::size_t>(jn.end[1])];
    const Vec ta = unit(jn.end[0] == 1 ? ea.tangent : scale(ea.tangent, -1.0));
    const Vec tb = unit(jn.end[1] == 0 ? eb.tangent : scale(eb.tangent, -1.0));
    jn.o = scale(axpy(ea.o, 1.0, eb.o), 0.5);
    jn.angle = std::acos(std::clamp(dot(ta, tb), -1.0, 1.0));
    const std::string where = "fillet corner at " + at(jn.o) + " between " + piece_name(pa, side1, side2) + " and " +
                              piece_name(pb, side1, side2);
    std::array<bool, 2> meet{};
    for (std::size_t s = 0; s < 2; ++s) {
      jn.rail_gap[s] = norm(sub(ea.rail[s], eb.rail[s]));
      meet[s] = jn.rail_gap[s] <= jt;
    }
    if ((meet[0] && meet[1]) || jn.angle <= co.smooth_angle) {
      jn.kind = JunctionKind::smooth;
      continue;
    }
    if (!meet[0] && !meet[1])
      throw Error(where + ": the rails meet on neither body (gaps " + num(norm(sub(ea.rail[0], eb.rail[0]))) + " and " +
                  num(norm(sub(ea.rail[1], eb.rail[1]))) +
                  "); expected an edge of one body only, perpendicular to the other body's face there (Masalha et al. 2021 "
                  "Sec. 6.1; clipping rails at a slanted edge is not supported)");
    const int g = meet[0] ? 1 : 0;
    const std::size_t gs = static_cast<std::size_t>(g);
    jn.kind = JunctionKind::corner;
    jn.gap_side = g;
    jn.p = ea.rail[gs];
    jn.q = eb.rail[gs];
    jn.r = scale(axpy(ea.rail[1 - gs], 1.0, eb.rail[1 - gs]), 0.5);
    const Vec pq = sub(jn.q, jn.p);
    const double sa = dot(pq, ta), sb = dot(pq, tb);
    if (sa < 0.0 && sb < 0.0) {
      // Sec. 6: "concave discontinuities could be similarly handled ... with C1 discontinuities
      // on the fillet surface, along the trimmed location": clipped and stitched below.
      if (pa.face[gs] != pb.face[gs])
        throw Error(where + ": a concave corner whose rails cross on two faces (" + (*sides[gs])[pa.face[gs]].name +
                    " and " + (*sides[gs])[pb.face[gs]].name +
                    "); expected the corner inside one face of the smooth body (clipping across faces is not supported)");
      jn.kind = JunctionKind::stitch;
      continue;
    }
    if (!(sa > 0.0 && sb > 0.0))
      throw Error(where + ": the rails' ends p " + at(jn.p) + " and q " + at(jn.q) +
                  " are neither apart nor crossing; expected a convex corner");
    const double d = fo.distance[gs];
    if (std::abs(norm(sub(jn.p, jn.o)) - d) > jt || std::abs(norm(sub(jn.q, jn.o)) - d) > jt)
      throw Error(where + ": the rails end " + num(norm(sub(jn.p, jn.o))) + " and " + num(norm(sub(jn.q, jn.o))) +
                  " from the corner; expected " + num(d));
  }
  out.junctions = std::move(junctions);
  // Step 1b (Sec. 6, concave corners): clip the two pieces at the stitch plane and stitch them.
  for (Junction& jn : out.junctions) {
    if (jn.kind != JunctionKind::stitch) continue;
    const std::size_t gs = static_cast<std::size_t>(jn.gap_side);
    std::array<FilletPiece*, 2> pc{&out.pieces[jn.piece[0]], &out.pieces[jn.piece[1]]};
    const std::string where = "fillet corner at " + at(jn.o) + " between " + piece_name(*pc[0], side1, side2) + " and " +
                              piece_name(*pc[1], side1, side2);
    for (const FilletPiece* p : pc)
      if (p->fillets.size() != 1)
        throw Error(where + ": a concave corner next to a piece of " + std::to_string(p->fillets.size()) +
                    " fillets (matched pieces); expected one fillet per piece to clip (use \"method\": \"fit\")");
    // X: where the gap side's rails cross on the shared face, from the rails' ends at o.
    const SideFace& fg = (*sides[gs])[pc[0]->face[gs]];
    const Surface sg = spline::boundary_face(*fg.cell, fg.face);
    const Curve& ra = pc[0]->fillets[0].rails.rails[gs].rail;
    const Curve& rb = pc[1]->fillets[0].rails.rails[gs].rail;
    double s = jn.end[0], t = jn.end[1];
    if (!rails_cross(ra, rb, s, t))
      throw Error(where + ": a concave corner whose rails on " + fg.name +
                  " do not cross within both pieces; expected distances that keep the crossing inside them");
    const auto xa = ra.eval({s});
    jn.x = point_at(sg, {xa[0], xa[1]});
    jn.crossing = {s, t};
    const Vec nrm = unit(cross(sub(jn.x, jn.o), sub(jn.r, jn.o)));
    if (!(norm(nrm) > 0.0))
      throw Error(where + ": the rails' crossing " + at(jn.x) + ", o and r " + at(jn.r) +
                  " are collinear; expected a stitch plane through them");
    // Clip both pieces at Pi, keeping the side of each piece's far end.
    std::array<spline::Face, 2> ends{};
    for (std::size_t k = 0; k < 2; ++k) {
      Fillet& fl = pc[k]->fillets[0];
      const Trivariate& h0 = fl.cells.at(0);
      const auto du = h0.domain(0), dv = h0.domain(1), dw = h0.domain(2);
      const Vec c0 = xyz(h0.eval({du[0], dv[1], dw[0]})), c1 = xyz(h0.eval({du[1], dv[1], dw[0]}));  // C's ends
      ends[k] = norm(sub(c0, jn.o)) <= norm(sub(c1, jn.o)) ? spline::Face::u0 : spline::Face::u1;
      const Vec farc = ends[k] == spline::Face::u0 ? c1 : c0;
      const double side = dot(sub(farc, jn.o), nrm) > 0.0 ? 1.0 : -1.0;
      for (auto& h : fl.cells) h = clip_half(h, ends[k], jn.o, nrm, side, tol);
      auto& e = pc[k]->ends[static_cast<std::size_t>(jn.end[k])];
      e.rail[gs] = jn.x;
      e.rail_uv[gs] = {xa[0], xa[1]};
    }
    jn.stitch_ends = ends;
  }
  // The stitches, once every piece is clipped at both ends (a clip refits the whole piece): both
  // clipped ends lie in Pi; the second piece's end is pinned onto the first's.
  for (Junction& jn : out.junctions) {
    if (jn.kind != JunctionKind::stitch) continue;
    std::array<FilletPiece*, 2> pc{&out.pieces[jn.piece[0]], &out.pieces[jn.piece[1]]};
    const std::array<spline::Face, 2> ends = jn.stitch_ends;
    for (std::size_t c = 0; c < 2; ++c) {
      const auto g = face_gaps(spline::boundary_face(pc[1]->fillets[0].cells[c], ends[1]),
                               spline::boundary_face(pc[0]->fillets[0].cells[c], ends[0]));
      jn.glue_before = std::max(jn.glue_before, g[0]);
    }
    if (!(jn.glue_before <= jt))
      throw Error("fillet corner at " + at(jn.o) + " between " + piece_name(*pc[0], side1, side2) + " and " +
                  piece_name(*pc[1], side1, side2) + ": the clipped fillets' end sections in the stitch plane through o, the rails' crossing " +
                  at(jn.x) + " and r " + at(jn.r) + " lie " + num(jn.glue_before) +
                  " apart; expected a corner symmetric about that plane (one straight edge, perpendicular to the face, "
                  "equal angles; Masalha et al. 2021, Sec. 6)");
    {
      // The first piece's cells are refined into the common space as well (exactly): a copy,
      // so that its layers stay untouched.
      std::vector<Trivariate> first = pc[0]->fillets[0].cells;
      pin_end(pc[1]->fillets[0].cells, -1, ends[1], first, ends[0]);
    }
  }
  // The glue once every stitch is made (a piece may be stitched at both ends), and the pieces'
  // cells measured again.
  for (Junction& jn : out.junctions) {
    if (jn.kind != JunctionKind::stitch) continue;
    std::array<FilletPiece*, 2> pc{&out.pieces[jn.piece[0]], &out.pieces[jn.piece[1]]};
    jn.glue = 0.0;
    for (std::size_t c = 0; c < 2; ++c)
      jn.glue = std::max(jn.glue, face_gaps(spline::boundary_face(pc[1]->fillets[0].cells[c], jn.stitch_ends[1]),
                                            spline::boundary_face(pc[0]->fillets[0].cells[c], jn.stitch_ends[0]))[0]);
  }
  for (std::size_t k = 0; k < out.pieces.size(); ++k)
    if (std::any_of(out.junctions.begin(), out.junctions.end(), [&](const Junction& j) {
          return j.kind == JunctionKind::stitch && (j.piece[0] == k || j.piece[1] == k);
        }))
      remeasure(out.pieces[k].fillets[0]);
  if (!co.bridge) return out;
  // Step 2: the bridging fillets (Sec. 6.1).
  for (std::size_t jidx = 0; jidx < out.junctions.size(); ++jidx) {
    const Junction& jn = out.junctions[jidx];
    if (jn.kind != JunctionKind::corner) continue;
    const std::array<const FilletPiece*, 2> pn{&out.pieces[jn.piece[0]], &out.pieces[jn.piece[1]]};
    const std::array<const FilletPiece::End*, 2> en{&pn[0]->ends[static_cast<std::size_t>(jn.end[0])],
                                                    &pn[1]->ends[static_cast<std::size_t>(jn.end[1])]};
    const std::size_t gs = static_cast<std::size_t>(jn.gap_side), hs = 1 - gs;
    const std::string where = "fillet corner at " + at(jn.o) + " between " + piece_name(*pn[0], side1, side2) + " and " +
                              piece_name(*pn[1], side1, side2);
    const auto face_of = [&](std::size_t k, std::size_t side) -> const SideFace& { return (*sides[side])[pn[k]->face[side]]; };
    const auto surface_of = [&](std::size_t k, std::size_t side) {
      const SideFace& sf = face_of(k, side);
      return spline::boundary_face(*sf.cell, sf.face);
    };
    bool split = pn[0]->face[gs] != pn[1]->face[gs];
    // The gap on one face: one bridge from p to q. On two (G1-joined along a seam through o):
    // B_d is split at the seam point s, one bridge per face (p to s, s to q); where s is p or q
    // (the seam runs along one side of the gap), one bridge on the other face.
    std::array<Surface, 2> sg{surface_of(0, gs), surface_of(1, gs)};
    std::array<Surface, 2> sh{surface_of(0, hs), surface_of(1, hs)};
    std::array<std::array<double, 2>, 2> seam_uv{};
    // The single bridge's faces and parameters: the arriving piece's, unless s is p.
    std::size_t on = 0;
    std::array<std::array<double, 2>, 2> end_uv{en[0]->rail_uv[gs], en[1]->rail_uv[gs]};
    CornerQuality seam;
    if (split) {
      const SideFace &fa = face_of(0, gs), &fb = face_of(1, gs);
      const double d = 0.5 * (norm(sub(jn.p, jn.o)) + norm(sub(jn.q, jn.o)));
      const Vec into = unit(axpy(unit(sub(jn.p, jn.o)), 1.0, unit(sub(jn.q, jn.o))));  // towards the gap
      const geom::SurfaceDistance to_b(sg[1]);
      bool found = false;
      double best = std::numeric_limits<double>::infinity();
      for (const auto& uv : seam_crossings(sg[0], en[0]->o_uv[gs], jn.o, into, d)) {
        const auto cp = to_b.closest(point_at(sg[0], uv));
        if (cp.distance < best) best = cp.distance, seam_uv = {uv, cp.uv}, found = true;
      }
      if (!found)
        throw Error(where + ": the gap spans " + fa.name + " and " + fb.name + ", but B_d (radius " + num(d) +
                    ") does not reach a boundary of " + fa.name +
                    " through the corner; expected two faces joined along a seam through o");
      seam.seam_point = {point_at(sg[0], seam_uv[0]), point_at(sg[1], seam_uv[1])};
      seam.seam_gap = best;
      const Vec x = seam.seam_point[0];
      if (!(best <= jt))
        throw Error(where + ": B_d meets the boundary of " + fa.name + " at " + at(x) + ", " + num(best) + " from " +
                    fb.name + "; expected the two faces joined along a seam through the corner (join tolerance " +
                    num(jt) + ")");
      seam.seam_angle = std::acos(std::clamp(std::abs(dot(unit_normal(sg[0], seam_uv[0][0], seam_uv[0][1]), unit_normal(sg[1], seam_uv[1][0], seam_uv[1][1]))), 0.0, 1.0));
      if (!(seam.seam_angle <= co.smooth_angle))
        throw Error(where + ": " + fa.name + " and " + fb.name + " meet at " + at(x) + " at an angle of " +
                    num(seam.seam_angle) + " rad; expected a G1 seam (at most " + num(co.smooth_angle) + ")");
      const auto ang = [&](const Vec& a, const Vec& b) {
        return std::acos(std::clamp(dot(unit(sub(a, jn.o)), unit(sub(b, jn.o))), -1.0, 1.0));
      };
      if (!(std::abs(ang(jn.p, x) + ang(x, jn.q) - ang(jn.p, jn.q)) <= 1e-6))
        throw Error(where + ": the seam point " + at(x) + " of " + fa.name + " and " + fb.name +
                    " is not between p " + at(jn.p) + " and q " + at(jn.q) + "; expected the seam to cross the gap");
      if (norm(sub(x, jn.p)) <= jt) {  // B_d runs on the leaving piece's face from p
        split = false, on = 1;
        end_uv[0] = seam_uv[1];
      } else if (norm(sub(x, jn.q)) <= jt) {  // on the arriving piece's face to q
        split = false;
        end_uv[1] = seam_uv[0];
      }
    }
    const std::size_t nparts = split ? 2 : 1;
    std::array<CornerFillet, 2> parts;
    for (std::size_t k = 0; k < nparts; ++k) {
      CornerInput ci;
      const std::size_t f = split ? k : on;  // 0: the arriving piece's faces, 1: the leaving one's
      ci.face = &sg[f];
      ci.gap_side = jn.gap_side;
      ci.o_uv = en[f]->o_uv[gs];
      ci.p_uv = !split ? end_uv[0] : k == 0 ? en[0]->rail_uv[gs] : seam_uv[1];
      ci.q_uv = !split ? end_uv[1] : k == 0 ? seam_uv[0] : en[1]->rail_uv[gs];
      ci.meet = &sh[f];
      ci.meet_o_uv = en[f]->o_uv[hs];
      ci.meet_r_uv = en[f]->rail_uv[hs];
      SubregionOptions so;
      so.method = fo.method;
      try {
        parts[k] = bridge_corner(ci, fo.blend, tol, so);
      } catch (const Error& e) {
        throw e.within(where + (split ? " (on " + face_of(k, gs).name + ")" : std::string()));
      }
      parts[k].junction = jidx;
      parts[k].part = split ? static_cast<int>(k) : -1;
      exact_singular_rows(parts[k].cells, gs);
    }
    // C0 glue (Sec. 6.1: the bridge meets its neighbours along their end sections): the
    // bridge's end faces against the neighbours' end faces at the same (v, w), cell for cell
    // (both are ruled halves: v from the rail to C, w from S^_i to S_b); the pair of ends (u0 or
    // u1 of each) that fits best is the junction. Measured, then pinned (pin_end) and measured
    // again: glue_before is what the bridge's own fit and section left, glue what remains. Split
    // at a seam, part 0 glues to the arriving piece, part 1 to the leaving one.
    std::array<const Fillet*, 2> glued_f{};
    std::array<std::array<spline::Face, 2>, 2> glued_n{};  // per side: the neighbour's end, the bridge's
    for (std::size_t side = 0; side < 2; ++side) {
      CornerFillet& cf = parts[split ? side : 0];
      FilletPiece& nb = out.pieces[jn.piece[side]];
      double best = std::numeric_limits<double>::infinity();
      Fillet* best_f = nullptr;
      spline::Face best_n = spline::Face::u0, best_b = spline::Face::u0;
      std::array<double, 2> best_jump{};
      for (Fillet& fl : nb.fillets)
        for (spline::Face fn : {spline::Face::u0, spline::Face::u1})
          for (spline::Face fb : {spline::Face::u0, spline::Face::u1}) {
            if (!split && side == 1 && fb == cf.ends[0]) continue;  // the other end is the other neighbour's
            const auto g0 = face_gaps(spline::boundary_face(cf.cells[0], fb), spline::boundary_face(fl.cells.at(0), fn));
            const auto g1 = face_gaps(spline::boundary_face(cf.cells[1], fb), spline::boundary_face(fl.cells.at(1), fn));
            const double g = std::max(g0[0], g1[0]);
            if (g < best) best = g, best_f = &fl, best_n = fn, best_b = fb, best_jump = {g0[1], g1[1]};
          }
      cf.quality.glue_before[side] = best;
      cf.quality.property_jump_before[side] = std::max(best_jump[0], best_jump[1]);
      if (best_f == nullptr || !(best <= jt))
        throw Error("fillet corner at " + at(jn.o) + ": the bridge's end section lies " + num(best) +
                        " from the neighbour " + piece_name(nb, side1, side2) + "'s; expected at most the join tolerance " +
                        num(jt),
                    ErrorKind::failed);
      cf.ends[side] = best_b;
      if (split) cf.ends[1 - side] = best_b == spline::Face::u0 ? spline::Face::u1 : spline::Face::u0;  // at s
      pin_end(cf.cells, static_cast<int>(gs), best_b, best_f->cells, best_n);
      glued_f[side] = best_f;
      glued_n[side] = {best_n, best_b};
    }
    if (split) {
      // The seam: part 1's end at s pinned onto part 0's (a copy, as for the stitches: part 0's
      // layers stay as they are); no singular rows to carry, both hold o and r exactly.
      const spline::Face e0 = parts[0].ends[1], e1 = parts[1].ends[0];
      for (std::size_t c = 0; c < 2; ++c)
        seam.seam_glue_before = std::max(seam.seam_glue_before, face_gaps(spline::boundary_face(parts[1].cells[c], e1),
                                                                          spline::boundary_face(parts[0].cells[c], e0))[0]);
      if (!(seam.seam_glue_before <= jt))
        throw Error(where + ": the bridge's two parts' sections at the seam point " + at(seam.seam_point[0]) + " lie " +
                        num(seam.seam_glue_before) + " apart; expected at most the join tolerance " + num(jt),
                    ErrorKind::failed);
      std::array<Trivariate, 2> first = parts[0].cells;
      pin_end(parts[1].cells, -1, e1, first, e0);
      for (std::size_t c = 0; c < 2; ++c) {
        const auto g = face_gaps(spline::boundary_face(parts[1].cells[c], e1), spline::boundary_face(parts[0].cells[c], e0));
        seam.seam_glue = std::max(seam.seam_glue, g[0]);
        seam.seam_property_jump = std::max(seam.seam_property_jump, g[1]);
      }
    }
    // The glue once every pin is made, and the rail's ends: the neighbours' rail ends p and q
    // (and s, where split).
    for (std::size_t side = 0; side < 2; ++side) {
      CornerFillet& cf = parts[split ? side : 0];
      std::array<double, 2> after{};
      for (std::size_t c = 0; c < 2; ++c) {
        const auto g = face_gaps(spline::boundary_face(cf.cells[c], glued_n[side][1]),
                                 spline::boundary_face(glued_f[side]->cells.at(c), glued_n[side][0]));
        after = {std::max(after[0], g[0]), std::max(after[1], g[1])};
      }
      cf.quality.glue[side] = after[0];
      cf.quality.property_jump[side] = after[1];
    }
    for (std::size_t k = 0; k < nparts; ++k) {
      CornerFillet& cf = parts[k];
      measure_cells(cf);
      // The half on S_g: its face v = 0 (half 0) or v = 1 (half 1) collapses onto the rail.
      const Trivariate& h = cf.cells[gs];
      const auto du = h.domain(0), dv = h.domain(1), dw = h.domain(2);
      const double v = dv[gs];
      double e = 0.0;
      for (std::size_t side = 0; side < 2; ++side) {
        const double u = du[cf.ends[side] == spline::Face::u0 ? 0 : 1];
        const Vec want = !split ? (side == 0 ? jn.p : jn.q) : (k == side ? (side == 0 ? jn.p : jn.q) : seam.seam_point[0]);
        e = std::max(e, norm(sub(xyz(h.eval({u, v, dw[0]})), want)));
      }
      cf.quality.end_error = std::max(cf.quality.end_error, e);
      if (split) {
        cf.quality.seam_point = seam.seam_point;
        cf.quality.seam_gap = seam.seam_gap;
        cf.quality.seam_angle = seam.seam_angle;
        cf.quality.seam_glue = seam.seam_glue;
        cf.quality.seam_glue_before = seam.seam_glue_before;
        cf.quality.seam_property_jump = seam.seam_property_jump;
        const std::size_t at_s = 1 - k;  // the part's side glued to the other part
        cf.quality.glue_before[at_s] = seam.seam_glue_before;
        cf.quality.glue[at_s] = seam.seam_glue;
        cf.quality.property_jump[at_s] = seam.seam_property_jump;
        cf.quality.property_jump_before[at_s] = 0.0;
      }
      out.corners.push_back(std::move(cf));
    }
  }
  return out;
}

}  // namespace trivox::fillet
