#include "trivox/geom/face_trim.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>
#include <utility>

#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::geom {
namespace {

using Pt = std::array<double, 2>;
using Poly = std::vector<Pt>;

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

spline::Curve line(Pt a, Pt b) {
  return spline::Curve({spline::KnotVector::bezier(2)}, 2, std::vector<double>{a[0], a[1], b[0], b[1]});
}

Pt eval2(const spline::Curve& c, double t) {
  double p[2];
  c.eval({t}, p);
  return {p[0], p[1]};
}

Poly sample(const spline::Curve& c) {
  const auto& kv = c.knots(0);
  std::vector<double> br;
  for (double k : kv.knots())
    if (k >= kv.front() && k <= kv.back() && (br.empty() || k > br.back())) br.push_back(k);
  const int per = std::max(2, std::min(16, 4096 / std::max<int>(1, static_cast<int>(br.size()) - 1)));
  Poly p;
  for (std::size_t i = 0; i + 1 < br.size(); ++i)
    for (int j = 0; j < per; ++j) p.push_back(eval2(c, br[i] + (br[i + 1] - br[i]) * j / per));
  p.push_back(eval2(c, kv.back()));
  return p;
}

double signed_area(const Poly& p) {
  double a = 0;
  for (std::size_t i = 0; i + 1 < p.size(); ++i) a += p[i][0] * p[i + 1][1] - p[i + 1][0] * p[i][1];
  a += p.back()[0] * p[0][1] - p[0][0] * p.back()[1];
  return 0.5 * a;
}

// Winding number of a closed polyline (last point joined to the first) around q.
int winding(const Poly& p, Pt q) {
  int w = 0;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Pt& a = p[i];
    const Pt& b = p[(i + 1) % n];
    const double cr = (b[0] - a[0]) * (q[1] - a[1]) - (q[0] - a[0]) * (b[1] - a[1]);
    if (a[1] <= q[1]) {
      if (b[1] > q[1] && cr > 0) ++w;
    } else if (b[1] <= q[1] && cr < 0) {
      --w;
    }
  }
  return w;
}

double seg_dist(Pt q, Pt a, Pt b) {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(q[0] - a[0] - t * dx, q[1] - a[1] - t * dy);
}

bool segments_cross(Pt a, Pt b, Pt c, Pt d) {
  auto orient = [](Pt p, Pt q, Pt r) { return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]); };
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  return ((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0));
}

struct Event {
  double s;   // perimeter position
  int curve;  // cut index
  int end;    // 0 start, 1 end
  Pt p;       // the curve's actual end point
};

struct Region {
  TrimLoop outer;
  Poly outer_poly;
  std::vector<int> holes;  // closed curve indices
};

}  // namespace

std::vector<FaceRegion> face_regions(const spline::Surface& face, const std::vector<spline::Curve>& cuts,
                                     const KeepPredicate& keep, const FaceTrimOptions& options) {
  const std::string& name = options.face_name;
  if (face.dim() < 3) throw Error(name + ": the face has " + std::to_string(face.dim()) + " coordinates; expected at least 3 (xyz)");
  if (!(options.tolerance > 0 && options.tolerance < 1e-3))
    throw Error(name + ": tolerance " + fmt(options.tolerance) + "; expected > 0 and < 1e-3");
  if (static_cast<int>(cuts.size()) > options.max_curves)
    throw Error(name + ": " + std::to_string(cuts.size()) + " cutting curves; expected at most " + std::to_string(options.max_curves));
  if (!keep) throw Error(name + ": no predicate given");
  const auto du = face.domain(0), dv = face.domain(1);
  const double u0 = du[0], u1 = du[1], v0 = dv[0], v1 = dv[1];
  const double W = u1 - u0, H = v1 - v0, L = std::max(W, H);
  const double tol = options.tolerance * L;
  const Pt corners[4] = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
  const double corner_s[4] = {0.0, W, W + H, 2 * W + H};
  const double perimeter = 2 * (W + H);

  // Validation, then chains: open curves whose ends meet off the boundary are joined end to end
  // (intersection curves with several faces of another cell meet at its edges).
  std::vector<Poly> raw;
  auto off_boundary = [&](Pt q) {
    return std::min({std::abs(q[0] - u0), std::abs(q[0] - u1), std::abs(q[1] - v0), std::abs(q[1] - v1)});
  };
  auto dist = [](Pt a, Pt b) { return std::hypot(a[0] - b[0], a[1] - b[1]); };
  for (std::size_t i = 0; i < cuts.size(); ++i) {
    const auto& c = cuts[i];
    const std::string who = name + ": cutting curve " + std::to_string(i);
    if (c.dim() != 2) throw Error(who + " has " + std::to_string(c.dim()) + " coordinates; expected 2 (u, v)");
    if (c.rational()) throw Error(who + " is rational; expected a polynomial curve");
    Poly p = sample(c);
    for (const Pt& q : p)
      if (q[0] < u0 - tol || q[0] > u1 + tol || q[1] < v0 - tol || q[1] > v1 + tol)
        throw Error(who + " leaves the parameter rectangle at (" + fmt(q[0]) + ", " + fmt(q[1]) + ")");
    raw.push_back(std::move(p));
  }
  // chains[k]: (curve, reversed) in order; a curve closed by itself is a chain alone.
  std::vector<std::vector<std::pair<int, bool>>> chains;
  {
    const std::size_t n = cuts.size();
    std::vector<bool> used(n, false);
    auto end_of = [&](int i, bool rev, bool last) {
      const Poly& p = raw[static_cast<std::size_t>(i)];
      return (last != rev) ? p.back() : p.front();
    };
    // Extends a chain at its last end while that end lies off the boundary and meets another
    // curve's end (the first such curve in input order).
    auto extend = [&](std::vector<std::pair<int, bool>>& ch) {
      for (;;) {
        const Pt e = end_of(ch.back().first, ch.back().second, true);
        if (dist(e, end_of(ch.front().first, ch.front().second, false)) <= tol) return;  // closed
        if (off_boundary(e) <= tol) return;
        bool found = false;
        for (std::size_t j = 0; j < n && !found; ++j) {
          if (used[j]) continue;
          const Poly& q = raw[j];
          if (dist(q.front(), q.back()) <= tol) continue;
          if (dist(e, q.front()) <= tol) ch.push_back({static_cast<int>(j), false}), found = true;
          else if (dist(e, q.back()) <= tol) ch.push_back({static_cast<int>(j), true}), found = true;
          if (found) used[j] = true;
        }
        if (!found) return;
      }
    };
    // Chains starting on the boundary first, then the rest (closed chains of open curves).
    for (int pass = 0; pass < 2; ++pass)
      for (std::size_t i = 0; i < n; ++i) {
        if (used[i]) continue;
        const Poly& p = raw[i];
        if (dist(p.front(), p.back()) <= tol) {
          if (pass == 0) {
            used[i] = true;
            chains.push_back({{static_cast<int>(i), false}});
          }
          continue;
        }
        bool rev = false;
        if (pass == 0) {
          if (off_boundary(p.front()) <= tol) rev = false;
          else if (off_boundary(p.back()) <= tol) rev = true;
          else continue;
        }
        used[i] = true;
        chains.push_back({{static_cast<int>(i), rev}});
        extend(chains.back());
      }
  }
  std::vector<Poly> polys;
  std::vector<bool> closed;
  std::vector<std::vector<spline::Curve>> chain_pieces;
  for (const auto& ch : chains) {
    Poly p;
    std::vector<spline::Curve> pieces;
    for (const auto& [i, rev] : ch) {
      Poly q = raw[static_cast<std::size_t>(i)];
      if (rev) std::reverse(q.begin(), q.end());
      if (!p.empty()) p.pop_back();
      p.insert(p.end(), q.begin(), q.end());
      pieces.push_back(rev ? spline::reverse(cuts[static_cast<std::size_t>(i)], 0) : cuts[static_cast<std::size_t>(i)]);
    }
    const std::string who = name + ": cutting curve " + std::to_string(ch.front().first);
    const bool cl = dist(p.front(), p.back()) <= tol;
    if (!cl) {
      for (const Pt& q : {p.front(), p.back()}) {
        const double d = off_boundary(q);
        if (d > tol)
          throw Error(who + (ch.size() > 1 ? " (joined with " + std::to_string(ch.size() - 1) + " more)" : std::string()) +
                      " is open and its end (" + fmt(q[0]) + ", " + fmt(q[1]) + ") lies " + fmt(d) +
                      " from the parameter rectangle's boundary and meets no other curve's end; expected a closed curve or ends on the boundary within " + fmt(tol));
      }
    } else {
      p.pop_back();
      if (std::abs(signed_area(p)) <= tol * L) throw Error(who + " is closed but encloses no area");
    }
    polys.push_back(std::move(p));
    closed.push_back(cl);
    chain_pieces.push_back(std::move(pieces));
  }
  // Crossings between curves and of a curve with itself (segments sharing a point skipped).
  {
    std::vector<std::pair<Pt, Pt>> segs;
    std::vector<std::pair<int, int>> owner;
    for (std::size_t i = 0; i < polys.size(); ++i) {
      const Poly& p = polys[i];
      const std::size_t n = closed[i] ? p.size() : p.size() - 1;
      for (std::size_t k = 0; k < n; ++k) {
        segs.push_back({p[k], p[(k + 1) % p.size()]});
        owner.push_back({static_cast<int>(i), static_cast<int>(k)});
      }
    }
    if (segs.size() > 200'000) throw Error(name + ": cutting curves too long (" + std::to_string(segs.size()) + " polyline segments)");
    for (std::size_t a = 0; a < segs.size(); ++a)
      for (std::size_t b = a + 1; b < segs.size(); ++b) {
        if (owner[a].first == owner[b].first) {
          const int n = static_cast<int>(polys[static_cast<std::size_t>(owner[a].first)].size());
          const int k = std::abs(owner[a].second - owner[b].second);
          if (k <= 1 || (closed[static_cast<std::size_t>(owner[a].first)] && k == n - 1)) continue;
        }
        if (segments_cross(segs[a].first, segs[a].second, segs[b].first, segs[b].second))
          throw Error(name + ": cutting curves " + std::to_string(owner[a].first) + " and " + std::to_string(owner[b].first) +
                      " cross near (" + fmt(segs[a].first[0]) + ", " + fmt(segs[a].first[1]) +
                      "); expected curves that meet only on the boundary");
      }
  }

  auto perim = [&](Pt q) {
    const double d[4] = {std::abs(q[1] - v0), std::abs(q[0] - u1), std::abs(q[1] - v1), std::abs(q[0] - u0)};
    const int side = static_cast<int>(std::min_element(d, d + 4) - d);
    switch (side) {
      case 0: return std::clamp(q[0] - u0, 0.0, W);
      case 1: return W + std::clamp(q[1] - v0, 0.0, H);
      case 2: return W + H + std::clamp(u1 - q[0], 0.0, W);
      default: return std::fmod(2 * W + H + std::clamp(v1 - q[1], 0.0, H), perimeter);
    }
  };

  std::vector<Event> events;
  for (std::size_t i = 0; i < polys.size(); ++i) {
    if (closed[i]) continue;
    events.push_back({perim(polys[i].front()), static_cast<int>(i), 0, polys[i].front()});
    events.push_back({perim(polys[i].back()), static_cast<int>(i), 1, polys[i].back()});
  }
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) {
    if (a.s != b.s) return a.s < b.s;
    if (a.curve != b.curve) return a.curve < b.curve;
    return a.end < b.end;
  });
  const std::size_t ne = events.size();
  std::vector<std::size_t> partner(ne);
  for (std::size_t k = 0; k < ne; ++k)
    for (std::size_t j = 0; j < ne; ++j)
      if (j != k && events[j].curve == events[k].curve) partner[k] = j;

  // Regions bounded by the rectangle's boundary.
  std::vector<Region> regions;
  auto add_line = [&](Region& r, Pt a, Pt b) {
    if (std::hypot(b[0] - a[0], b[1] - a[1]) <= 0.01 * tol) return;
    r.outer.pieces.push_back(line(a, b));
    r.outer_poly.push_back(a);
  };
  auto add_arc = [&](Region& r, const Event& from, const Event& to, bool full) {
    // Boundary from `from` counter-clockwise to `to`, through the corners in between.
    Pt cur = from.p;
    for (int k = 0; k < 8; ++k) {
      const int c = k % 4;
      double cs = corner_s[c] + (k >= 4 ? perimeter : 0.0);
      double ts = to.s < from.s || full ? to.s + perimeter : to.s;
      if (cs > from.s && cs < ts) {
        add_line(r, cur, corners[c]);
        cur = corners[c];
      }
    }
    add_line(r, cur, to.p);
  };
  if (ne == 0) {
    Region r;
    for (int c = 0; c < 4; ++c) add_line(r, corners[c], corners[(c + 1) % 4]);
    regions.push_back(std::move(r));
  } else {
    std::vector<bool> used(ne, false);
    for (std::size_t start = 0; start < ne; ++start) {
      if (used[start]) continue;
      Region r;
      std::size_t k = start;
      for (std::size_t guard = 0; guard <= ne; ++guard) {
        used[k] = true;
        const std::size_t next = (k + 1) % ne;
        add_arc(r, events[k], events[next], ne == 1);
        const Event& e = events[next];
        const auto& c = chain_pieces[static_cast<std::size_t>(e.curve)];
        const Poly& p = polys[static_cast<std::size_t>(e.curve)];
        if (e.end == 0) {
          r.outer.pieces.insert(r.outer.pieces.end(), c.begin(), c.end());
          r.outer_poly.insert(r.outer_poly.end(), p.begin(), p.end() - 1);
        } else {
          for (auto it = c.rbegin(); it != c.rend(); ++it) r.outer.pieces.push_back(spline::reverse(*it, 0));
          r.outer_poly.insert(r.outer_poly.end(), p.rbegin(), p.rend() - 1);
        }
        k = partner[next];
        if (k == start) break;
      }
      regions.push_back(std::move(r));
    }
  }
  const std::size_t n_open = regions.size();

  // Closed curves: oriented counter-clockwise, nesting by winding numbers.
  std::vector<int> closed_ids;
  std::vector<TrimLoop> ccw;
  std::vector<Poly> ccw_poly;
  std::vector<double> areas;
  for (std::size_t i = 0; i < polys.size(); ++i) {
    if (!closed[i]) continue;
    const double a = signed_area(polys[i]);
    TrimLoop l;
    Poly p = polys[i];
    if (a > 0) {
      l.pieces = chain_pieces[i];
    } else {
      for (auto it = chain_pieces[i].rbegin(); it != chain_pieces[i].rend(); ++it) l.pieces.push_back(spline::reverse(*it, 0));
      std::reverse(p.begin(), p.end());
    }
    closed_ids.push_back(static_cast<int>(i));
    ccw.push_back(std::move(l));
    ccw_poly.push_back(std::move(p));
    areas.push_back(std::abs(a));
  }
  const std::size_t nc = closed_ids.size();
  // Innermost closed curve containing q (-1: none), skipping `self`.
  auto innermost = [&](Pt q, std::ptrdiff_t self) {
    std::ptrdiff_t best = -1;
    for (std::size_t j = 0; j < nc; ++j) {
      if (static_cast<std::ptrdiff_t>(j) == self) continue;
      if (winding(ccw_poly[j], q) != 0 && (best < 0 || areas[j] < areas[static_cast<std::size_t>(best)]))
        best = static_cast<std::ptrdiff_t>(j);
    }
    return best;
  };
  auto open_region = [&](Pt q) {
    for (std::size_t r = 0; r < n_open; ++r)
      if (winding(regions[r].outer_poly, q) != 0) return static_cast<std::ptrdiff_t>(r);
    return static_cast<std::ptrdiff_t>(-1);
  };
  std::vector<std::vector<int>> children(nc);
  for (std::size_t j = 0; j < nc; ++j) {
    const Pt q = ccw_poly[j].front();
    const std::ptrdiff_t par = innermost(q, static_cast<std::ptrdiff_t>(j));
    if (par >= 0) {
      children[static_cast<std::size_t>(par)].push_back(static_cast<int>(j));
    } else {
      std::ptrdiff_t r = open_region(q);
      if (r < 0) {  // on a chord: use a neighbouring point of the curve
        for (const Pt& q2 : ccw_poly[j])
          if ((r = open_region(q2)) >= 0) break;
      }
      if (r < 0) throw Error(name + ": cannot place closed cutting curve " + std::to_string(chains[static_cast<std::size_t>(closed_ids[static_cast<std::size_t>(j)])].front().first));
      regions[static_cast<std::size_t>(r)].holes.push_back(static_cast<int>(j));
    }
  }
  for (std::size_t j = 0; j < nc; ++j) {
    Region r;
    r.outer = ccw[j];
    r.outer_poly = ccw_poly[j];
    r.holes = children[j];
    regions.push_back(std::move(r));
  }
  const std::size_t nr = regions.size();

  // Interior points: the grid point of each region farthest from every curve and the boundary.
  std::vector<std::pair<Pt, Pt>> segs;
  for (std::size_t i = 0; i < polys.size(); ++i) {
    const Poly& p = polys[i];
    const std::size_t n = closed[i] ? p.size() : p.size() - 1;
    for (std::size_t k = 0; k < n; ++k) segs.push_back({p[k], p[(k + 1) % p.size()]});
  }
  auto which = [&](Pt q) -> std::ptrdiff_t {
    const std::ptrdiff_t c = innermost(q, -1);
    if (c >= 0) return static_cast<std::ptrdiff_t>(n_open) + c;
    return open_region(q);
  };
  std::vector<double> best_d(nr, -1.0);
  std::vector<Pt> best_p(nr);
  for (int G = 32;; G *= 2) {
    for (int i = 0; i < G; ++i)
      for (int j = 0; j < G; ++j) {
        const Pt q{u0 + W * (i + 0.5) / G, v0 + H * (j + 0.5) / G};
        const std::ptrdiff_t r = which(q);
        if (r < 0) continue;
        double d = std::min({(q[0] - u0) / W * L, (u1 - q[0]) / W * L, (q[1] - v0) / H * L, (v1 - q[1]) / H * L});
        for (const auto& s : segs) d = std::min(d, seg_dist(q, s.first, s.second));
        auto& bd = best_d[static_cast<std::size_t>(r)];
        if (d > bd) {
          bd = d;
          best_p[static_cast<std::size_t>(r)] = q;
        }
      }
    bool all = true;
    for (std::size_t r = 0; r < nr; ++r) all = all && best_d[r] > 1e3 * tol;
    if (all) break;
    if (G >= 256) {
      for (std::size_t r = 0; r < nr; ++r)
        if (!(best_d[r] > 1e3 * tol))
          throw Error(name + ": region " + std::to_string(r) + " of the cut face is too thin to hold an interior point (no grid point of 256 x 256 farther than " + fmt(1e3 * tol) + " from the curves)");
    }
  }

  std::vector<FaceRegion> out;
  std::vector<double> xyz(static_cast<std::size_t>(face.dim()));
  for (std::size_t r = 0; r < nr; ++r) {
    std::vector<TrimLoop> loops{regions[r].outer};
    for (int h : regions[r].holes) {
      TrimLoop l;
      const auto& pc = ccw[static_cast<std::size_t>(h)].pieces;
      for (auto it = pc.rbegin(); it != pc.rend(); ++it) l.pieces.push_back(spline::reverse(*it, 0));
      loops.push_back(std::move(l));
    }
    const Pt q = best_p[r];
    face.eval({q[0], q[1]}, xyz.data());
    const bool k = keep(xyz.data());
    out.push_back(FaceRegion{TrimmedSurface(face, std::move(loops), options.tolerance), q[0], q[1], k});
  }
  return out;
}

std::vector<TrimmedSurface> trim_face(const spline::Surface& face, const std::vector<spline::Curve>& cuts,
                                      const KeepPredicate& keep, const FaceTrimOptions& options) {
  std::vector<TrimmedSurface> out;
  for (auto& r : face_regions(face, cuts, keep, options))
    if (r.kept) out.push_back(std::move(r.surface));
  return out;
}

}  // namespace trivox::geom
