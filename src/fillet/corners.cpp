#include "trivox/fillet/corners.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <string>

#include "fillet_util.hpp"
#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/fillet/ruled_fillet.hpp"
#include "trivox/geom/closest_point.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/fit.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet {

using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using spline::Trivariate;
using detail::Vec;
using namespace detail;

std::string CornerQuality::jacobian() const {
  if (det_min > 0.0) return "positive";
  if (det_max < 0.0) return "negative";
  return "changes sign";
}

namespace {

std::string at(const Vec& p) { return "(" + num(p[0]) + ", " + num(p[1]) + ", " + num(p[2]) + ")"; }

Vec point_at(const Surface& s, const std::array<double, 2>& uv) { return xyz(s.eval({uv[0], uv[1]})); }

/// A constant curve at uv in the space `knots` (R^2).
Curve constant_curve(const KnotVector& knots, const std::array<double, 2>& uv) {
  std::vector<double> pts;
  for (int i = 0; i < knots.size(); ++i) pts.insert(pts.end(), {uv[0], uv[1]});
  return Curve({knots}, 2, std::move(pts));
}

/// B_d (see corners.hpp): the point of s in the half-plane through o spanned by n_o and m, at
/// distance d from o, by Newton from uv (updated). False when Newton does not converge.
bool solve_bd(const Surface& s, const Vec& o, const Vec& nu, double d, double tol, std::array<double, 2>& uv) {
  const auto du = s.domain(0), dv = s.domain(1);
  const std::size_t k = static_cast<std::size_t>(s.dim());
  for (int it = 0; it < 60; ++it) {
    const auto e = s.eval_derivatives({uv[0], uv[1]}, 1);
    const Vec x = sub(xyz(e.data()), o), xu = xyz(e.data() + k), xv = xyz(e.data() + 2 * k);
    const double f1 = 0.5 * (dot(x, x) - d * d), f2 = dot(x, nu);
    if (std::abs(f1) <= 1e-3 * tol * d && std::abs(f2) <= 1e-3 * tol) return true;
    const double a = dot(x, xu), b = dot(x, xv), c = dot(nu, xu), dd = dot(nu, xv);
    const double det = a * dd - b * c;
    if (!(std::abs(det) > 0.0)) return false;
    double su = (f1 * dd - b * f2) / det, sv = (a * f2 - c * f1) / det;
    // Damp steps larger than a tenth of the domain (a far start).
    const double big = 0.1 * std::max(du[1] - du[0], dv[1] - dv[0]);
    const double len = std::hypot(su, sv);
    if (len > big) su *= big / len, sv *= big / len;
    uv = {std::clamp(uv[0] - su, du[0], du[1]), std::clamp(uv[1] - sv, dv[0], dv[1])};
  }
  return false;
}

struct Frame {
  Vec o, n, a, c;
  double angle = 0.0, dp = 0.0, dq = 0.0;
  /// The half-plane normal and the distance at phi.
  void at(double phi, Vec& nu, double& d) const {
    const double s = std::sin(angle);
    const Vec m = unit(axpy(scale(a, std::sin((1.0 - phi) * angle) / s), std::sin(phi * angle) / s, c));
    nu = unit(cross(n, m));
    d = (1.0 - phi) * dp + phi * dq;
  }
};

/// B_d in s's parameters: samples from p (phi = 0) to q (phi = 1), interpolated, doubled until the
/// curve is within tol of B_d halfway between samples.
Curve trace_bd(const Surface& s, const Frame& f, const CornerInput& in, double tol, int& samples) {
  const auto du = s.domain(0), dv = s.domain(1);
  const auto off_face = [&](const std::array<double, 2>& uv, double phi) {
    const double eu = 1e-9 * (du[1] - du[0]), ev = 1e-9 * (dv[1] - dv[0]);
    return (uv[0] <= du[0] + eu && in.p_uv[0] > du[0] + eu && in.q_uv[0] > du[0] + eu) ||
                   (uv[0] >= du[1] - eu && in.p_uv[0] < du[1] - eu && in.q_uv[0] < du[1] - eu) ||
                   (uv[1] <= dv[0] + ev && in.p_uv[1] > dv[0] + ev && in.q_uv[1] > dv[0] + ev) ||
                   (uv[1] >= dv[1] - ev && in.p_uv[1] < dv[1] - ev && in.q_uv[1] < dv[1] - ev)
               ? phi
               : -1.0;
  };
  const auto solve = [&](double phi, std::array<double, 2>& uv) {
    Vec nu;
    double d = 0.0;
    f.at(phi, nu, d);
    if (!solve_bd(s, f.o, nu, d, tol, uv))
      throw Error("fillet corner at " + at(f.o) + ": the circle B_d of radius " + num(d) +
                      " on the face does not converge at phi = " + num(phi),
                  ErrorKind::failed);
    if (off_face(uv, phi) >= 0.0)
      throw Error("fillet corner at " + at(f.o) + ": the bridge's rail B_d (radius " + num(d) +
                  ") leaves the face at phi = " + num(phi) + ", (u, v) = (" + num(uv[0]) + ", " + num(uv[1]) +
                  "); expected a face that holds the disk of that radius about the corner");
  };
  for (int n = 8; n <= 1024; n *= 2) {
    std::vector<double> params, values;
    std::array<double, 2> uv = in.p_uv;
    for (int j = 0; j <= n; ++j) {
      const double phi = static_cast<double>(j) / n;
      if (j == 0) {
        uv = in.p_uv;
      } else if (j == n) {
        // Continue onto q, then pin it.
        std::array<double, 2> end = uv;
        solve(phi, end);
        if (norm(sub(point_at(s, end), point_at(s, in.q_uv))) > 100.0 * tol)
          throw Error("fillet corner at " + at(f.o) + ": B_d from p " + at(point_at(s, in.p_uv)) +
                          " reaches " + at(point_at(s, end)) + ", not q " + at(point_at(s, in.q_uv)),
                      ErrorKind::failed);
        uv = in.q_uv;
      } else {
        // Sub-steps from the previous sample, so Newton always starts close.
        for (int sstep = 1; sstep <= 4; ++sstep) solve((j - 1 + sstep / 4.0) / n, uv);
      }
      params.push_back(phi);
      values.insert(values.end(), {uv[0], uv[1]});
    }
    const Curve c = spline::interpolate_curve(params, 2, values, 4);
    double worst = 0.0;
    for (int j = 0; j < n; ++j) {
      const double phi = (j + 0.5) / n;
      std::array<double, 2> uv2{values[2 * static_cast<std::size_t>(j)], values[2 * static_cast<std::size_t>(j) + 1]};
      solve(phi, uv2);
      const auto cu = c.eval({phi});
      worst = std::max(worst, norm(sub(point_at(s, {cu[0], cu[1]}), point_at(s, uv2))));
    }
    if (worst <= tol) {
      samples = n + 1;
      return c;
    }
  }
  throw Error("fillet corner at " + at(f.o) + ": B_d does not reach the tolerance " + num(tol) + " with 1025 samples",
              ErrorKind::failed);
}

/// The bridge's cells: sampled det J and volumes.
void measure_cells(CornerFillet& cf) {
  CornerQuality& qa = cf.quality;
  qa.det_min = std::numeric_limits<double>::infinity();
  qa.det_max = -qa.det_min;
  for (std::size_t c = 0; c < 2; ++c) {
    const auto rg = sampled_jacobian(cf.cells[c]);
    qa.cell_jacobian[c] = rg;
    qa.det_min = std::min(qa.det_min, rg[0]);
    qa.det_max = std::max(qa.det_max, rg[1]);
    qa.cell_volume[c] = std::abs(boundary_volume(cf.cells[c]));
  }
}

}  // namespace

CornerFillet bridge_corner(const CornerInput& in, const BlendOptions& blend, double tol, const SubregionOptions& sopt) {
  const auto start = std::chrono::steady_clock::now();
  if (in.face == nullptr || in.meet == nullptr) throw Error("fillet corner: no face given");
  if (blend.section != Section::hermite)
    throw Error("fillet corner: the bridging fillet (Masalha et al. 2021, Sec. 6.1) takes the Hermite section; expected "
                "\"section\": \"hermite\" with corners");
  if (!(tol > 0.0)) throw Error("fillet corner: tolerance " + num(tol) + "; expected a positive value");
  if (in.face->dim() != in.meet->dim() || in.face->dim() < 3)
    throw Error("fillet corner: the faces have " + std::to_string(in.face->dim()) + " and " +
                std::to_string(in.meet->dim()) + " coordinates; expected the same, at least 3");
  const Surface& s = *in.face;
  const int g = in.gap_side;
  Frame f;
  f.o = point_at(s, in.o_uv);
  f.n = unit_normal(s, in.o_uv[0], in.o_uv[1]);
  const Vec p = point_at(s, in.p_uv), q = point_at(s, in.q_uv);
  f.dp = norm(sub(p, f.o));
  f.dq = norm(sub(q, f.o));
  f.a = unit(sub(p, f.o));
  f.c = unit(sub(q, f.o));
  f.angle = std::acos(std::clamp(dot(f.a, f.c), -1.0, 1.0));
  if (!(f.dp > 0.0) || !(f.dq > 0.0) || !(f.angle > 1e-9) || !(f.angle < std::numbers::pi - 1e-6) || !(norm(f.n) > 0.0))
    throw Error("fillet corner at " + at(f.o) + ": p " + at(p) + " and q " + at(q) +
                " do not span a gap about o; expected rail ends on either side of the corner");
  CornerFillet out;
  CornerQuality& qa = out.quality;
  // The bridge's rail on S_g, and the fan from it to o (Eqs. 2-3 with C collapsed to o).
  const Curve bd = trace_bd(s, f, in, tol, qa.bd_samples[0]);
  const Curve ouv = constant_curve(bd.knots(0), in.o_uv);
  SubregionOptions so = sopt;
  so.tolerance = 0.25 * tol;  // the neighbours fit to tol: their end sections and ours then differ by little more
  if (so.method == SubregionMethod::matched) so.method = SubregionMethod::automatic;
  const Surface fan = g == 0 ? subregion(s, bd, ouv, so) : subregion(s, ouv, bd, so);
  // The segment o r on the other body, constant in phi: the singular face.
  const KnotVector lin = KnotVector::bezier(2);
  const Surface seg = g == 0 ? subregion(*in.meet, constant_curve(lin, in.meet_o_uv), constant_curve(lin, in.meet_r_uv), so)
                             : subregion(*in.meet, constant_curve(lin, in.meet_r_uv), constant_curve(lin, in.meet_o_uv), so);
  const Vec r = point_at(*in.meet, in.meet_r_uv);
  const Vec tb = unit(sub(r, f.o));  // T on the edge: from o towards r
  // The Hermite section (Alg. 1): Q0 = C_1, Q1 = C_1 + L/3 T_1, Q2 = C_2 - L/3 T_2, Q3 = C_2,
  // L = tau |C_1 - C_2|; the rail on S_g is the fan's boundary itself.
  Curve rail = spline::iso(fan, 1, g == 0 ? 0.0 : 1.0);
  rail = spline::coordinates(rail, 0, 3);
  const auto section = [&](double phi, Vec& q1, Vec& q2) {
    const Vec b = xyz(rail.eval({phi}));
    const auto uv = bd.eval({phi});
    const Vec n = unit_normal(s, uv[0], uv[1]);
    const Vec toward = sub(f.o, b);
    const Vec tg = unit(axpy(toward, -dot(toward, n), n));  // towards o in S_g's tangent plane
    const double len = blend.tau * norm(sub(b, r)) / 3.0;
    if (g == 0) {  // rail 1 = B_d, T_1 towards C; rail 2 = r, T_2 from C to r
      q1 = axpy(b, len, tg);
      q2 = axpy(r, -len, tb);
    } else {  // rail 1 = r, T_1 from r towards C; rail 2 = B_d, T_2 away from o
      q1 = axpy(r, -len, tb);
      q2 = axpy(b, len, tg);
    }
  };
  KnotVector kv = rail.knots(0);
  Curve c1, c2;
  for (int round = 0;; ++round) {
    const std::vector<double> gr = kv.greville();
    std::vector<double> v1, v2;
    for (double phi : gr) {
      Vec a, b;
      section(phi, a, b);
      v1.insert(v1.end(), a.begin(), a.end());
      v2.insert(v2.end(), b.begin(), b.end());
    }
    c1 = spline::interpolate_curve(gr, 3, v1, kv);
    c2 = spline::interpolate_curve(gr, 3, v2, kv);
    double worst = 0.0;
    for (std::size_t j = 0; j + 1 < gr.size(); ++j)
      for (const double t : {0.25, 0.5, 0.75}) {
        const double phi = gr[j] + t * (gr[j + 1] - gr[j]);
        Vec a, b;
        section(phi, a, b);
        worst = std::max({worst, norm(sub(xyz(c1.eval({phi})), a)), norm(sub(xyz(c2.eval({phi})), b))});
      }
    if (worst <= tol) break;
    if (round >= std::max(1, blend.max_rounds))
      throw Error("fillet corner at " + at(f.o) + ": the section's control points do not reach the tolerance " +
                      num(tol) + " (" + num(worst) + ")",
                  ErrorKind::failed);
    kv = halved(kv);
    rail = spline::to_space(rail, 0, kv);
  }
  qa.bd_samples[1] = kv.size();
  const int n = kv.size();
  std::vector<double> pts(static_cast<std::size_t>(n) * 4 * 3);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < n; ++i) {
      Vec x;
      if ((j == 0 && g == 0) || (j == 3 && g == 1)) x = xyz(rail.point(i).data());
      else if (j == 0 || j == 3) x = r;
      else x = xyz((j == 1 ? c1 : c2).point(i).data());
      std::copy(x.begin(), x.end(), pts.begin() + 3 * (i + n * j));
    }
  const Surface sb({kv, KnotVector::bezier(4)}, 3, std::move(pts));
  const auto halves = g == 0 ? ruled_fillet(fan, seg, sb) : ruled_fillet(seg, fan, sb);
  out.cells = halves;
  // Quality.
  qa.end_error = std::max(norm(sub(xyz(rail.eval({0.0})), p)), norm(sub(xyz(rail.eval({1.0})), q)));
  const Curve at_o = spline::coordinates(spline::iso(fan, 1, g == 0 ? 1.0 : 0.0), 0, 3);
  const Curve at_r = spline::coordinates(spline::iso(sb, 1, g == 0 ? 1.0 : 0.0), 0, 3);
  for (int a = 0; a <= 256; ++a) {
    const double phi = a / 256.0;
    const Vec b = xyz(rail.eval({phi}));
    qa.radius_error = std::max(qa.radius_error, std::abs(norm(sub(b, f.o)) - ((1 - phi) * f.dp + phi * f.dq)));
    qa.o_error = std::max(qa.o_error, norm(sub(xyz(at_o.eval({phi})), f.o)));
    qa.r_error = std::max(qa.r_error, norm(sub(xyz(at_r.eval({phi})), r)));
    // G1 along B_d: S_b's normal there against S_g's.
    const auto uv = bd.eval({phi});
    const double vb = g == 0 ? 0.0 : 1.0;
    const auto d = sb.eval_derivatives({phi, vb}, 1);
    const Vec nb = cross(xyz(d.data() + 3), xyz(d.data() + 6));
    if (norm(nb) > 1e-12 * std::max(1.0, norm(xyz(d.data() + 3)) * norm(xyz(d.data() + 6)))) {
      const double cs = std::abs(dot(unit(nb), unit_normal(s, uv[0], uv[1])));
      qa.g1_angle = std::max(qa.g1_angle, std::acos(std::min(1.0, cs)));
    }
  }
  measure_cells(out);
  qa.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

namespace {

/// Largest xyz distance, and largest property difference (coordinates 3..k-1), between two faces
/// at the same relative parameters (13 x 13 samples).
std::array<double, 2> face_gaps(const Surface& a, const Surface& b) {
  std::array<double, 2> worst{};
  constexpr int n = 12;
  const auto au = a.domain(0), av = a.domain(1), bu = b.domain(0), bv = b.domain(1);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double s = static_cast<double>(i) / n, t = static_cast<double>(j) / n;
      const auto x = a.eval({au[0] + (au[1] - au[0]) * s, av[0] + (av[1] - av[0]) * t});
      const auto y = b.eval({bu[0] + (bu[1] - bu[0]) * s, bv[0] + (bv[1] - bv[0]) * t});
      worst[0] = std::max(worst[0], norm(sub(xyz(x), xyz(y))));
      for (std::size_t c = 3; c < x.size() && c < y.size(); ++c) worst[1] = std::max(worst[1], std::abs(x[c] - y[c]));
    }
  return worst;
}

/// The bridge's singular rows (corners.hpp), control point (v index a, w index b) of half
/// `half` (nv points along v): in the fan half (on S_g, half gs) the collapsed C edge (v at C,
/// w = 0), all o; in the segment half the face w = 0 (the edge segment o r, the same in every
/// layer along phi) and the rail face (v at the rail), all r.
bool singular_row(std::size_t half, std::size_t gs, int a, int b, int nv) {
  const int c_side = half == 0 ? nv - 1 : 0, rail_side = nv - 1 - c_side;
  if (half == gs) return a == c_side && b == 0;
  return b == 0 || a == rail_side;
}

/// Makes the singular rows exactly the same in every layer along phi (the middle layer's): the
/// fan's and the segment's fits hold them constant only to rounding.
void exact_singular_rows(std::array<Trivariate, 2>& cells, std::size_t gs) {
  for (std::size_t c = 0; c < 2; ++c) {
    Trivariate& h = cells[c];
    const int nu = h.count(0), nv = h.count(1), nw = h.count(2), mid = nu / 2;
    const std::size_t k = static_cast<std::size_t>(h.dim());
    for (int b = 0; b < nw; ++b)
      for (int a = 0; a < nv; ++a)
        if (singular_row(c, gs, a, b, nv))
          for (int i = 0; i < nu; ++i)
            if (i != mid) std::copy_n(h.point(h.row({mid, a, b})).data(), k, h.point(h.row({i, a, b})).data());
  }
}

/// Pins the bridge's end face `end` (u0 or u1) onto the neighbour's end face `nb_end`, half for
/// half: each pair of cells is brought into one (v, w) function space (exact: knot insertion and
/// degree raising), the neighbour's end layer takes the bridge's singular rows (it moves there by
/// its fit's error: its C end, its edge segment and r), and the bridge's end layer becomes the
/// neighbour's. The faces are then one function, so the C0 glue of Sec. 6.1 holds to rounding,
/// whatever the neighbour's fit and the bridge's interpolated section differed by, and the
/// bridge keeps its exact singular structure (det J = 0 on the collapsed edges, not slightly
/// negative). The change fades out over the first knot span along phi.
/// With gs < 0 (a stitch: no singular rows) the neighbour is left as it is.
void pin_end(std::span<Trivariate> cells, int gs, spline::Face end, std::span<Trivariate> nb, spline::Face nb_end) {
  if (cells.size() != 2 || nb.size() != 2) throw Error("fillet corner: expected two ruled halves", ErrorKind::failed);
  for (std::size_t c = 0; c < 2; ++c) {
    Trivariate& cell = cells[c];
    Trivariate& n = nb[c];
    if (cell.rational() || n.rational() || !cell.knots(0).clamped() || !n.knots(0).clamped() || cell.count(0) < 2)
      throw Error("fillet corner: cannot pin a rational or unclamped cell", ErrorKind::failed);
    for (int d = 1; d < 3; ++d) n = spline::reparametrize(n, d, cell.domain(d)[0], cell.domain(d)[1]);
    const auto [ca, cb] = spline::make_compatible(spline::boundary_face(cell, end), spline::boundary_face(n, nb_end));
    for (int d = 0; d < 2; ++d) {
      cell = spline::to_space(cell, d + 1, ca.knots(d));
      n = spline::to_space(n, d + 1, ca.knots(d));
    }
    const int i = end == spline::Face::u0 ? 0 : cell.count(0) - 1, inner = i == 0 ? 1 : i - 1;
    const int in = nb_end == spline::Face::u0 ? 0 : n.count(0) - 1;
    const std::size_t k = static_cast<std::size_t>(cell.dim());
    for (int b = 0; b < cell.count(2); ++b)
      for (int a = 0; a < cell.count(1); ++a) {
        double* src = n.point(n.row({in, a, b})).data();
        if (gs >= 0 && singular_row(c, static_cast<std::size_t>(gs), a, b, cell.count(1))) std::copy_n(cell.point(cell.row({inner, a, b})).data(), k, src);
        std::copy_n(src, k, cell.point(cell.row({i, a, b})).data());
      }
  }
}

/// Where two rails on one face cross: s on ra, t on rb (both in the face's parameters), by
/// Newton on ra(s) = rb(t) from (s0, t0), the rails' ends at the corner. False when it does not
/// converge inside both domains.
bool rails_cross(const Curve& ra, const Curve& rb, double& s, double& t) {
  for (int it = 0; it < 60; ++it) {
    const auto a = ra.eval_derivatives({s}, 1), b = rb.eval_derivatives({t}, 1);
    const double fx = a[0] - b[0], fy = a[1] - b[1];
    if (std::hypot(fx, fy) <= 1e-15 * (1.0 + std::hypot(a[0], a[1]))) return true;
    // [a' -b'] (ds, dt) = -f
    const double det = a[2] * (-b[3]) - (-b[2]) * a[3];
    if (!(std::abs(det) > 0.0)) return false;
    const double ds = (-fx * (-b[3]) + b[2] * (-fy)) / det;
    const double dt = (a[2] * (-fy) - a[3] * (-fx)) / det;
    s = std::clamp(s + ds, 0.0, 1.0);
    t = std::clamp(t + dt, 0.0, 1.0);
  }
  return false;
}

/// The root in u of (f(u, v) - o) . n on [lo, hi] (sign change from the clipped end `near`
/// towards `far`), or `near` when f(near, v) is already on the kept side (`side` > 0: kept
/// where (f - o) . n has the sign of side). Bisection, then secant polish.
double plane_root(const Surface& f, double v, const Vec& o, const Vec& n, double side, double near, double far) {
  const auto g = [&](double u) { return side * dot(sub(xyz(f.eval({u, v})), o), n); };
  double a = near, b = far, ga = g(a), gb = g(b);
  if (ga >= 0.0) return near;
  if (gb <= 0.0) return far;
  for (int it = 0; it < 200 && std::abs(b - a) > 1e-15 * (1.0 + std::abs(a)); ++it) {
    double m = a - ga * (b - a) / (gb - ga);  // regula falsi (Illinois)
    if (!(m > std::min(a, b) && m < std::max(a, b))) m = 0.5 * (a + b);
    const double gm = g(m);
    if (gm == 0.0) return m;
    if ((gm < 0.0) == (ga < 0.0)) a = m, ga = gm, gb *= 0.5;
    else b = m, gb = gm, ga *= 0.5;
  }
  return 0.5 * (a + b);
}

/// Masalha et al. 2021, Sec. 6, the concave corner: a ruled fillet half clipped by the stitch plane Pi
/// (through o, n its normal): each of its faces w = 0 (on S^_i) and w = 1 (on S_b) becomes
/// F(u(s, v), v), u running from where F's v-iso crosses Pi (a(v), interpolated at the Greville
/// points of a cubic space, spans doubled until F(a(v), v) is within tol of Pi) to the far end
/// (fillet/compose.hpp's sub-region with the ruled map between (a(v), v) and (u_far, v):
/// composed, or fitted to tol), and the cell is ruled between them again (Alg. 2): the cut
/// rulings from the clipped S^_i to the clipped S_b lie in Pi at s = 0. `end` is the cell's end at
/// the corner (u0 or u1); the result keeps u's direction.
Trivariate clip_half(const Trivariate& h, spline::Face end, const Vec& o, const Vec& n, double side, double tol) {
  const auto du = h.domain(0);
  const double near = end == spline::Face::u0 ? du[0] : du[1], far = end == spline::Face::u0 ? du[1] : du[0];
  std::array<Surface, 2> cut;
  for (std::size_t wf = 0; wf < 2; ++wf) {
    const Surface f = spline::boundary_face(h, wf == 0 ? spline::Face::w0 : spline::Face::w1);  // (u, v)
    const auto dv = f.domain(1);
    Curve a;
    bool ok = false;
    for (int spans = 4; spans <= 512 && !ok; spans *= 2) {
      const KnotVector kv = KnotVector::uniform(4, spans, dv[0], dv[1]);
      const std::vector<double> gr = kv.greville();
      std::vector<double> val;
      for (double v : gr) val.push_back(plane_root(f, v, o, n, side, near, far));
      a = spline::interpolate_curve(gr, 1, val, kv);
      double worst = 0.0;
      for (std::size_t j = 0; j + 1 < gr.size(); ++j)
        for (const double t : {0.25, 0.5, 0.75}) {
          const double v = gr[j] + t * (gr[j + 1] - gr[j]);
          const double u = std::clamp(a.eval({v})[0], std::min(near, far), std::max(near, far));
          const double want = plane_root(f, v, o, n, side, near, far);
          worst = std::max(worst, norm(sub(xyz(f.eval({u, v})), xyz(f.eval({want, v})))));
        }
      ok = worst <= 0.1 * tol;
    }
    if (!ok)
      throw Error("fillet stitch at " + at(o) + ": the stitch plane's trace on the fillet does not reach the tolerance " +
                      num(tol) + " with 512 spans",
                  ErrorKind::failed);
    // The map's curves in one cubic space: (a(v), v) and (u_far, v), v by its Greville points.
    const KnotVector& kv = a.knots(0);
    const std::vector<double> gr = kv.greville();
    std::vector<double> pa, pf;
    for (int i = 0; i < kv.size(); ++i) {
      const double ai = std::clamp(a.point(i)[0], std::min(near, far), std::max(near, far));
      pa.insert(pa.end(), {ai, gr[static_cast<std::size_t>(i)]});
      pf.insert(pf.end(), {far, gr[static_cast<std::size_t>(i)]});
    }
    const Curve ca({kv}, 2, std::move(pa)), cf({kv}, 2, std::move(pf));
    SubregionOptions so;
    so.tolerance = 0.25 * tol;
    // s from the clipped end towards the far one along u's own direction.
    const Surface y = end == spline::Face::u0 ? subregion(f, ca, cf, so) : subregion(f, cf, ca, so);  // (v, s)
    cut[wf] = spline::swap_directions(y, 0, 1);
  }
  Trivariate out = construct::ruled(cut[0], cut[1]);
  if (jacobian_at(out, {0.5, 0.5, 0.5}) * jacobian_at(h, {0.5 * (du[0] + du[1]), 0.5, 0.5}) < 0.0)
    throw Error("fillet stitch at " + at(o) + ": the clipped fillet turned inside out", ErrorKind::failed);
  return out;
}

/// A clipped or stitched piece's fillet: det J at interior samples, volumes and the halves' glue
/// again (the gaps to the faces, the G1 angle and the property jump stay those of the unclipped
/// fillet, of which the clipped cells are the part beyond the stitch plane, refitted to a quarter
/// of the tolerance).
void remeasure(Fillet& fl) {
  FilletQuality& q = fl.quality;
  q.cell_jacobian.clear();
  q.cell_volume.clear();
  q.det_min = std::numeric_limits<double>::infinity();
  q.det_max = -q.det_min;
  for (const Trivariate& h : fl.cells) {
    const std::array<double, 2> r = sampled_jacobian(h);
    q.cell_jacobian.push_back(r);
    q.cell_volume.push_back(std::abs(boundary_volume(h)));
    q.det_min = std::min(q.det_min, r[0]);
    q.det_max = std::max(q.det_max, r[1]);
  }
  q.glue = face_gaps(spline::boundary_face(fl.cells.at(0), spline::Face::v1), spline::boundary_face(fl.cells.at(1), spline::Face::v0))[0];
  q.cells.clear();
  for (const Trivariate& h : fl.cells) {
    SplineShape sh;
    for (int d = 0; d < 3; ++d) sh.orders.push_back(h.orders()[static_cast<std::size_t>(d)]), sh.counts.push_back(h.count(d));
    q.cells.push_back(sh);
  }
  q.fillet = q.cells.front();
}

Vec eval3(const Surface& s, const Curve& c, double t, Vec* tangent = nullptr) {
  const auto cd = c.eval_derivatives({t}, 1);
  const auto d = s.eval_derivatives({cd[0], cd[1]}, 1);
  const std::size_t k = static_cast<std::size_t>(s.dim());
  if (tangent) *tangent = axpy(scale(xyz(d.data() + k), cd[2]), cd[3], xyz(d.data() + 2 * k));
  return xyz(d.data());
}

/// Where B_d (radius d about o) crosses the boundaries of s through o: for every boundary
/// iso-curve c of s that holds o's parameters o_uv, the root of |c(t) - o| = d on the side of o
/// where c runs towards `into` (the gap), by regula falsi from o. None where c leaves s first.
std::vector<std::array<double, 2>> seam_crossings(const Surface& s, const std::array<double, 2>& o_uv, const Vec& o,
                                                  const Vec& into, double d) {
  std::vector<std::array<double, 2>> found;
  const std::array<std::array<double, 2>, 2> dom{s.domain(0), s.domain(1)};
  const std::size_t k = static_cast<std::size_t>(s.dim());
  for (std::size_t fix = 0; fix < 2; ++fix)
    for (const double edge : dom[fix]) {
      if (std::abs(o_uv[fix] - edge) > 1e-9 * (dom[fix][1] - dom[fix][0])) continue;
      const std::size_t fr = 1 - fix;
      const auto uv_at = [&](double t) {
        std::array<double, 2> uv{};
        uv[fix] = edge;
        uv[fr] = t;
        return uv;
      };
      const auto e = s.eval_derivatives({uv_at(o_uv[fr])[0], uv_at(o_uv[fr])[1]}, 1);
      const double run = dot(xyz(e.data() + (fr == 0 ? k : 2 * k)), into);
      if (!(std::abs(run) > 0.0)) continue;
      const double end = run > 0.0 ? dom[fr][1] : dom[fr][0];
      const auto g = [&](double t) { return norm(sub(point_at(s, uv_at(t)), o)) - d; };
      double a = o_uv[fr], b = end, ga = g(a), gb = g(b);
      if (!(gb >= 0.0)) continue;  // the boundary ends inside the sphere
      for (int it = 0; it < 200 && std::abs(b - a) > 1e-15 * (1.0 + std::abs(a)) && ga != 0.0 && gb != 0.0; ++it) {
        double m = a - ga * (b - a) / (gb - ga);  // Illinois
        if (!(m > std::min(a, b) && m < std::max(a, b))) m = 0.5 * (a + b);
        const double gm = g(m);
        if (gm == 0.0) a = b = m;
        else if ((gm < 0.0) == (ga < 0.0)) a = m, ga = gm, gb *= 0.5;
        else b = m, gb = gm, ga *= 0.5;
      }
      const double t = std::abs(ga) <= std::abs(gb) ? a : b;
      if (dot(sub(point_at(s, uv_at(t)), o), into) > 0.0) found.push_back(uv_at(t));
    }
  return found;
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
