#include "trivox/fillet/matched.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "fillet_util.hpp"
#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/fillet/compose.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet {

namespace {

using namespace detail;
using spline::Curve;
using spline::Surface;

std::array<double, 2> at2(const Curve& c, double t) {
  std::array<double, 2> p{};
  double v[8];
  c.eval({t}, v);
  p[0] = v[0], p[1] = v[1];
  return p;
}

/// All t in [0, 1] with c(t)[coord] = value: sign changes on 32 samples per span of c, then
/// bisection to 1e-15 (a touching without crossing is not a crossing).
std::vector<double> level_crossings(const Curve& c, int coord, double value) {
  std::vector<double> out;
  const auto br = c.knots(0).breakpoints();
  auto f = [&](double t) { return at2(c, t)[static_cast<std::size_t>(coord)] - value; };
  constexpr int per_span = 32;
  for (std::size_t s = 0; s + 1 < br.size(); ++s) {
    const double a = br[s].value, b = br[s + 1].value;
    double t0 = a, f0 = f(a);
    for (int k = 1; k <= per_span; ++k) {
      const double t1 = a + (b - a) * k / per_span, f1 = f(t1);
      if (f0 == 0.0) {
        if (out.empty() || t0 - out.back() > 1e-12) out.push_back(t0);
      } else if ((f0 < 0.0) != (f1 < 0.0) && f1 != 0.0) {
        double lo = t0, hi = t1, flo = f0;
        for (int it = 0; it < 80 && hi - lo > 1e-15; ++it) {
          const double mid = 0.5 * (lo + hi), fm = f(mid);
          if ((fm < 0.0) == (flo < 0.0)) lo = mid, flo = fm;
          else hi = mid;
        }
        const double root = 0.5 * (lo + hi);
        if (out.empty() || root - out.back() > 1e-12) out.push_back(root);
      }
      t0 = t1, f0 = f1;
    }
  }
  if (f(br.back().value) == 0.0 && (out.empty() || br.back().value - out.back() > 1e-12)) out.push_back(br.back().value);
  return out;
}

/// Interior knot values of a face's direction d (its knot lines).
std::vector<double> knot_lines(const Surface& s, int d) {
  std::vector<double> out;
  const auto br = s.knots(d).breakpoints();
  for (std::size_t i = 1; i + 1 < br.size(); ++i) out.push_back(br[i].value);
  return out;
}

/// Unit partials of a face at (u, v): S_u / |S_u|, S_v / |S_v| (xyz).
std::array<Vec, 2> unit_partials(const Surface& s, const std::array<double, 2>& uv) {
  const auto d = s.eval_derivatives({uv[0], uv[1]}, 1);
  const auto k = static_cast<std::size_t>(s.dim());
  Vec su = xyz(d.data() + k), sv = xyz(d.data() + 2 * k);
  return {scale(su, 1.0 / std::max(norm(su), 1e-300)), scale(sv, 1.0 / std::max(norm(sv), 1e-300))};
}

/// C'(t) in xyz, from face 1: S_1u u' + S_1v v' along c^{S_1}.
Vec curve_tangent(const Surface& s, const Curve& base, double t) {
  double c[16];
  base.eval_derivatives({t}, 1, c);  // value, then d/dt (2 coordinates each)
  const auto d = s.eval_derivatives({c[0], c[1]}, 1);
  const auto k = static_cast<std::size_t>(s.dim());
  return axpy(scale(xyz(d.data() + k), c[2]), c[3], xyz(d.data() + 2 * k));
}

/// Cyclic distance between parameters on a closed curve of period 1 (plain distance when open).
double param_gap(double a, double b, bool closed) {
  const double d = std::abs(a - b);
  return closed ? std::min(d, 1.0 - d) : d;
}

/// Curve c's piece over [a, b] of its parameter, reparametrised onto [0, 1].
Curve piece(const Curve& c, double a, double b) {
  return spline::reparametrize(spline::restrict_to(c, 0, a, b), 0, 0.0, 1.0);
}

}  // namespace

std::vector<MatchedCut> matched_cuts(const Surface& face1, const Surface& face2, const RailPair& rails) {
  const std::array<const Surface*, 2> face{&face1, &face2};
  const bool closed = rails.closed;
  // Alg. 4: the cutting lines. From each knot line of face i crossed by c^{S_i} at t0: that line
  // on face i, and on face j the iso-line through c^{S_j}(t0) most nearly orthogonal to C there.
  struct Line {
    int dir;
    double value;
    bool knot;
  };
  std::vector<MatchedCut> cuts;
  for (int i = 0; i < 2; ++i) {
    const int j = 1 - i;
    const Rail& ri = rails.rails[static_cast<std::size_t>(i)];
    const Rail& rj = rails.rails[static_cast<std::size_t>(j)];
    for (int d = 0; d < 2; ++d)
      for (double k : knot_lines(*face[static_cast<std::size_t>(i)], d))
        for (double t0 : level_crossings(ri.base, d, k)) {
          if (t0 <= 1e-12 || t0 >= 1.0 - 1e-12) continue;  // at the ends (open) or the seam (closed)
          MatchedCut cut;
          cut.t = t0;
          cut.dir[static_cast<std::size_t>(i)] = d;
          cut.value[static_cast<std::size_t>(i)] = k;
          cut.knot[static_cast<std::size_t>(i)] = true;
          // AddSubdivVal on face j.
          const auto uvj = at2(rj.base, t0);
          const auto du_dv = unit_partials(*face[static_cast<std::size_t>(j)], uvj);
          Vec dc = curve_tangent(*face[static_cast<std::size_t>(i)], ri.base, t0);
          dc = scale(dc, 1.0 / std::max(norm(dc), 1e-300));
          // The line u = const runs along S_v, v = const along S_u: take the one more nearly
          // orthogonal to C (the smaller |<tangent, d_c>|). See matched.hpp on the paper's test.
          const int dj = std::abs(dot(du_dv[1], dc)) < std::abs(dot(du_dv[0], dc)) ? 0 : 1;
          cut.dir[static_cast<std::size_t>(j)] = dj;
          cut.value[static_cast<std::size_t>(j)] = uvj[static_cast<std::size_t>(dj)];
          cut.knot[static_cast<std::size_t>(j)] = false;
          cuts.push_back(cut);
        }
  }
  std::sort(cuts.begin(), cuts.end(), [](const MatchedCut& a, const MatchedCut& b) { return a.t < b.t; });
  // Where both faces' knot lines cross C at one point (within rounding), one cut serves both.
  std::vector<MatchedCut> merged;
  for (const auto& c : cuts) {
    if (!merged.empty() && c.t - merged.back().t < 1e-9) {
      auto& m = merged.back();
      for (std::size_t i = 0; i < 2; ++i)
        if (c.knot[i] && !m.knot[i]) m.dir[i] = c.dir[i], m.value[i] = c.value[i], m.knot[i] = true;
      continue;
    }
    merged.push_back(c);
  }
  // Verify (Alg. 5 line 15, Lemma 1) and Split: each cutting line of face i crosses C and rail i
  // equally often; its crossings with C pair with its nearest crossings of the rail.
  for (int i = 0; i < 2; ++i) {
    const Rail& ri = rails.rails[static_cast<std::size_t>(i)];
    const auto ui = static_cast<std::size_t>(i);
    // A line that C crosses several times is one cutting line for several cuts: its crossings
    // with C and with the rail are found once.
    struct Crossings {
      int dir;
      double value;
      std::vector<double> on_c, on_r;
    };
    std::vector<Crossings> lines;
    const auto crossings_of = [&](int dir, double value) -> const Crossings& {
      for (const auto& l : lines)
        if (l.dir == dir && l.value == value) return l;
      lines.push_back({dir, value, level_crossings(ri.base, dir, value), level_crossings(ri.rail, dir, value)});
      return lines.back();
    };
    for (auto& cut : merged) {
      const Crossings& x = crossings_of(cut.dir[ui], cut.value[ui]);
      const auto& on_c = x.on_c;
      const auto& on_r = x.on_r;
      const std::string line = std::string(cut.dir[ui] == 0 ? "u = " : "v = ") + num(cut.value[ui]);
      if (on_c.size() != on_r.size())
        throw Error("fillet (Masalha et al. 2021, Alg. 5): face " + std::to_string(i + 1) + "'s cutting line " + line + " crosses C " +
                        std::to_string(on_c.size()) + " times and its rail " + std::to_string(on_r.size()) +
                        " times; expected equal counts (Lemma 1), or method \"fit\" (Sec. 4.3)",
                    ErrorKind::failed);
      // The rail crossing nearest along the curve to this cut's t, which must pair back.
      double best = std::numeric_limits<double>::infinity(), r = 0.0;
      for (double x : on_r)
        if (param_gap(x, cut.t, closed) < best) best = param_gap(x, cut.t, closed), r = x;
      cut.rail[ui] = r;
    }
    // The rail pieces must follow C's order, without wrapping past the ends.
    for (std::size_t k = 0; k + 1 < merged.size(); ++k)
      if (!(merged[k].rail[ui] < merged[k + 1].rail[ui]))
        throw Error("fillet (Masalha et al. 2021, Alg. 5): on face " + std::to_string(i + 1) + " the rail crosses the cutting lines at t = " +
                        num(merged[k].rail[ui]) + " and " + num(merged[k + 1].rail[ui]) +
                        ", out of C's order (t = " + num(merged[k].t) + ", " + num(merged[k + 1].t) +
                        "); expected matched pieces, or method \"fit\" (Sec. 4.3)",
                    ErrorKind::failed);
  }
  return merged;
}

std::vector<MatchedPiece> matched_pieces(const Surface& face1, const Surface& face2, const RailPair& rails,
                                         const std::vector<MatchedCut>& cuts) {
  // Piece boundaries: the ends (t = 0 and 1, where the four curves share the parameter; for a
  // closed C the seam) and the cuts.
  struct Bound {
    double t;
    std::array<double, 2> rail;
  };
  std::vector<Bound> b{{0.0, {0.0, 0.0}}};
  for (const auto& c : cuts) b.push_back({c.t, c.rail});
  b.push_back({1.0, {1.0, 1.0}});
  std::vector<MatchedPiece> out;
  SubregionOptions exact;
  exact.method = SubregionMethod::compose;
  const std::array<const Surface*, 2> face{&face1, &face2};
  for (std::size_t p = 0; p + 1 < b.size(); ++p) {
    MatchedPiece mp;
    mp.t = {b[p].t, b[p + 1].t};
    std::array<Curve, 4> parts;  // base 1, rail 1, base 2, rail 2
    for (std::size_t i = 0; i < 2; ++i) {
      mp.rail[i] = {b[p].rail[i], b[p + 1].rail[i]};
      parts[2 * i] = piece(rails.rails[i].base, mp.t[0], mp.t[1]);
      parts[2 * i + 1] = piece(rails.rails[i].rail, mp.rail[i][0], mp.rail[i][1]);
    }
    // One function space for the four pieces (Eq. 3's ruled surfaces need it). The pieces'
    // knots come from restrictions to different ranges: near-coincident ones (within knot_merge of
    // unit interval) become one, so that the union has no sliver spans.
    std::vector<Curve> normal;
    for (const auto& q : parts) normal.push_back(construct::normalized(q));
    merge_close_knots<1>(normal, 0, knot_merge);
    const std::vector<Curve> c = construct::common_space<1>(std::span<const Curve>(normal.data(), normal.size()));
    for (std::size_t i = 0; i < 2; ++i)
      if (crosses_knot_lines(*face[i], c[2 * i + 1]) || crosses_knot_lines(*face[i], c[2 * i]))
        throw Error("fillet (Masalha et al. 2021, Alg. 5): piece " + std::to_string(p + 1) + " of face " + std::to_string(i + 1) +
                        "'s sub-region (C from t = " + num(mp.t[0]) + " to " + num(mp.t[1]) + ", the rail from " +
                        num(mp.rail[i][0]) + " to " + num(mp.rail[i][1]) +
                        ") crosses a knot line of the face; expected one Bezier patch per piece, or method \"fit\" (Sec. 4.3)",
                    ErrorKind::failed);
    try {
      mp.sub1 = subregion(face1, c[1], c[0], exact);  // v = 0 on rail 1, v = 1 on C
      mp.sub2 = subregion(face2, c[2], c[3], exact);  // v = 0 on C, v = 1 on rail 2
    } catch (const Error& e) {
      throw Error("fillet (Masalha et al. 2021, Alg. 5): piece " + std::to_string(p + 1) + ": " + e.what() +
                      "; method \"fit\" (Sec. 4.3) applies",
                  ErrorKind::failed);
    }
    mp.blend.faces = {&face1, &face2};
    mp.blend.rail_uv = {c[1], c[3]};
    mp.blend.rail = {spline::iso(mp.sub1, 1, 0.0), spline::iso(mp.sub2, 1, 1.0)};
    mp.blend.center = spline::iso(mp.sub1, 1, 1.0);
    out.push_back(std::move(mp));
  }
  return out;
}

}  // namespace trivox::fillet
