/// @file src/fillet/corner_fillet.cpp
/// @brief The bridging fillet at a convex corner (Masalha et al. 2021, Sec. 6.1, Fig. 12):
/// bridge_corner and its report. B_d, the arc of S_g at distance d about the corner o from p to
/// q, traced by Newton in the half-planes through o and interpolated (samples doubled until
/// within the tolerance); the fan from B_d to o on S_g (Eqs. 2-3 with C collapsed to o) and the
/// edge segment o r on the other body (fillet/compose.hpp's sub-regions); the Hermite section of
/// Alg. 1 between B_d and r, its control points interpolated at Greville points (knots halved
/// until within the tolerance); the two ruled halves (Alg. 2). trivox/fillet/corners.hpp derives
/// the construction.
///
/// Cost: a few hundred surface evaluations and Newton solves for B_d, one composition or fit per
/// sub-region, one interpolation per halving, one ruling; the report samples B_d at 257 points
/// and det J and the volumes of both cells.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "corner_util.hpp"
#include "fillet_util.hpp"
#include "trivox/error.hpp"
#include "trivox/fillet/corners.hpp"
#include "trivox/fillet/ruled_fillet.hpp"
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

}  // namespace

namespace detail {

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

}  // namespace detail

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

}  // namespace trivox::fillet
