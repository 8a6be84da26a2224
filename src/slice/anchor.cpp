// Anchors and their certified rectangles (anchor.hpp): from one expansion at a voxel, the
// inverse Jacobian J0^-1 and the piece's bounds on second partials (StepBounds) give, for a
// rectangle of voxels, a Taylor bound on the linear model's residual and the Newton-Kantorovich
// radius within which the exact preimage of every voxel's centre lies (Deuflhard 2004, in the
// affine-covariant form, in a plain and a scaled norm of the parameters), and the error of the
// properties taken from the first-order model or from exact samples interpolated along the rows.
// The widest rectangle is found by doubling and bisection, a certificate per trial: O(1) each,
// a few dozen per anchor.
#include "anchor.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "mat3.hpp"

namespace trivox::slice::detail {

namespace {

constexpr double sqrt3 = 1.7320508075688772;
/// Property error the stepping certifies: the contract's 1/512 less 5% for rounding (the float
/// stored is within 1e-7 of the double computed).
constexpr double prop_budget = 0.95 / 512.0;

}  // namespace

bool AnchorMaker::make(const Expansion& e, int i, int l, const Vec3& p, Anchor& a, int shift) {
  std::array<Vec3, 3> inv;
  // The whole piece's bounds: those of its part around the anchor (3/8 of it along each
  // direction, 8^3 parts per piece) were tighter, but their box ended most anchors on the
  // twisted column at printer pitch (callgrind: the sampler 2.34G -> 2.18G instructions with
  // the whole piece's, 52k anchors instead of 67k; the teapot's job the same within the noise).
  b_ = &loc_.step_bounds(e.piece);
  if (!b_->valid || !invert(e.jac, inv)) return false;
  e_ = &e;
  c0_ = mul(inv, {p[0] - e.x[0], p[1] - e.x[1], p[2] - e.x[2]});
  a.ia = i;
  a.la = l;
  a.dx = {inv[0][0] * px_, inv[1][0] * px_, inv[2][0] * px_};
  a.dy = {-inv[0][1] * py_, -inv[1][1] * py_, -inv[2][1] * py_};  // the next image row is py lower
  dx_ = a.dx;
  dy_ = a.dy;
  // Affine-covariant bounds (Deuflhard): the second partials seen through J0^-1. With
  // |J0^-1| taken entrywise, |J0^-1 v| <= | |J0^-1| b2v | for any v bounded entrywise by b2v,
  // so w[d][e] bounds |J0^-1 d^2X/dt_d dt_e| in the whole piece, whatever the cell's shape
  // (a layer-thin or sheared slab is as well conditioned as a cube).
  // The norm is that of the scaled parameters s_j = D_j t_j, D_j = |dX/dt_j| at the anchor
  // (lengths in mm): Newton-Kantorovich holds in any norm, and in the unscaled one a shell's
  // thin direction (2 mm per unit of w) against its long one (125 mm per unit of u) made the
  // curvature term J0^-1 d^2X/du^2 hundreds of units of w per unit of u, so that theta passed
  // 1/2 within a few voxels although the linear model stayed exact to 1e-5 of the pitch.
  // In s: G_s = D G, G_s' = D G' D^-1, so w[d][e] bounds |D J0^-1 d^2X/dt_d dt_e| / (D_d D_e).
  // Both norms are kept (Norm): the scaled one certifies rectangles inside the piece, the
  // plain one is tried where that fails (an isotropic cell may do better unscaled) and alone
  // certifies rectangles reaching out of the piece (the layer-thin cells' faces).
  Vec3 len{};
  for (std::size_t d = 0; d < 3; ++d) {
    const Vec3& c = e.jac[d];
    len[d] = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  }
  norms_[1].valid = len[0] > 0.0 && len[1] > 0.0 && len[2] > 0.0 && std::isfinite(len[0] + len[1] + len[2]);
  if (norms_[1].valid) norms_[1].scale = len;  // norms_[0] keeps scale 1
  for (Norm& nm : norms_) {
    if (!nm.valid) continue;
    std::array<Vec3, 3> ainv;
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t k = 0; k < 3; ++k) ainv[r][k] = nm.scale[r] * std::abs(inv[r][k]);
    // b2v is symmetric in (d, k) (mixed partials), and so is w: six products, not nine.
    for (std::size_t d = 0; d < 3; ++d)
      for (std::size_t k = d; k < 3; ++k) {
        const Vec3 v = mul(ainv, b_->b2v[d][k]);
        nm.w[d][k] = nm.w[k][d] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) / (nm.scale[d] * nm.scale[k]);
      }
    nm.omega = 0.0;
    for (std::size_t d = 0; d < 3; ++d) {
      double row2 = 0.0;
      for (std::size_t k = 0; k < 3; ++k) row2 += nm.w[d][k] * nm.w[d][k];
      nm.omega = std::max(nm.omega, std::sqrt(row2));  // |G_s'(x) - G_s'(y)|_F <= omega |x - y|_1 (in s)
    }
  }
  gmax_ = {0.0, 0.0, 0.0};
  for (std::size_t h = 0; h < static_cast<std::size_t>(m_); ++h)
    for (std::size_t d = 0; d < 3; ++d) gmax_[d] = std::max(gmax_[d], std::abs(e.grad[h][d]));
  a.piece = e.piece;
  a.step = 0;
  a.quad = false;
  for (std::size_t j = 0; j < 3; ++j) {
    // box_cap's terms: the room between t0 + c0 and the box grown by tol / slope.
    const double base = e.t[j] + c0_[j];
    const bool bounded = a.dx[j] != 0.0 && b_->slope[j] > 0.0;
    const double reach = bounded ? tol_ / b_->slope[j] : 0.0;
    room_hi_[j] = b_->hi[j] + reach - base;
    room_lo_[j] = base - (b_->lo[j] - reach);
    inv_dx_[j] = bounded ? 1.0 / std::abs(a.dx[j]) : 0.0;
  }
  for (std::size_t j = 0; j < 3; ++j) a.tb[j] = e.t[j] + c0_[j];
  for (std::size_t h = 0; h < static_cast<std::size_t>(m_); ++h) {
    a.pb[h] = e.props[h] + e.grad[h][0] * c0_[0] + e.grad[h][1] * c0_[1] + e.grad[h][2] * c0_[2];
    a.pdx[h] = e.grad[h][0] * a.dx[0] + e.grad[h][1] * a.dx[1] + e.grad[h][2] * a.dx[2];
    a.pdy[h] = e.grad[h][0] * a.dy[0] + e.grad[h][1] * a.dy[1] + e.grad[h][2] * a.dy[2];
  }
  a.lo.fill(1);
  a.hi.fill(0);
  // Candidate rectangles: rows l - up .. l + down with columns i - K .. i + K (the largest K),
  // for the whole block, the rows next to l, and l alone with columns i .. i + K; the one
  // covering most voxels wins.
  int best_up = 0, best_down = 0, best_k = -1, best_kn = 0;
  long best_area = 0;
  Errors best_err;
  auto consider = [&](int opt) {
    const int up = opt == 0 ? l : opt == 1 ? std::min(l, 1) : 0;
    const int down = opt == 0 ? rows_ - 1 - l : opt == 1 ? std::min(rows_ - 1 - l, 1) : 0;
    const bool both_ways = opt < 2;
    const auto uo = static_cast<std::size_t>(opt);
    const int cap = box_cap(both_ways ? -1 : 0, up, down);
    const int K = largest([&](int k) { return certified(both_ways ? k : 0, k, up, down); }, guess_[uo], cap, capped_[uo]);
    if (K < 0) return;
    guess_[uo] = K;
    capped_[uo] = K == cap;
    const long area = static_cast<long>(both_ways ? 2 * K + 1 : K + 1) * (up + down + 1);
    if (area > best_area) {
      best_area = area;
      best_up = up, best_down = down, best_k = K, best_kn = both_ways ? K : 0;
      best_err = err_;  // the search's last success is its K
    }
  };
  if (shift > 0) {
    const int up = l, down = rows_ - 1 - l;
    const int cap = box_cap(shift, up, down);
    const int K = largest([&](int k) { return certified(shift, k, up, down); }, guess_[0], cap, capped_[3]);
    if (K < 0) return false;
    guess_[0] = K;
    capped_[3] = K == cap;
    for (int r = 0; r < rows_; ++r) {
      a.lo[static_cast<std::size_t>(r)] = std::max(0, i - shift);
      a.hi[static_cast<std::size_t>(r)] = std::min(nx_ - 1, i + K);
    }
    a.step = sample_step(err_, a.quad);
    return true;
  }
  // The whole block first; the narrower shapes only when it spans few columns.
  consider(0);
  if (best_k < 2) {
    if (rows_ > 2) consider(1);
    consider(2);
  }
  if (best_k < 0) return false;
  for (int r = l - best_up; r <= l + best_down; ++r) {
    a.lo[static_cast<std::size_t>(r)] = std::max(0, i - best_kn);
    a.hi[static_cast<std::size_t>(r)] = std::min(nx_ - 1, i + best_k);
  }
  // The block's other rows, each with columns of its own: near a face that crosses the rows
  // at a slant (a run's first voxels), the rectangle spans one or two rows, while the others
  // are inside the cell a few columns to one side. Each is certified as a rectangle of one row
  // (certified_with takes any ranges k0..k1, d..d as -kn = k0, kp = k1, -ln = lp = d), its
  // columns first those where its parameters stay in the box (row_columns), within the
  // anchor row's reach K, then fewer until certified. The property errors are the largest of
  // all the rows' (sample_step).
  if (best_up + best_down + 1 < rows_ && best_k >= 2) {
    Errors worst = best_err;
    for (int r = 0; r < rows_; ++r) {
      if (r >= l - best_up && r <= l + best_down) continue;
      const int dr = r - l;
      for (int reach = best_k; reach >= 2; reach /= 2) {
        int k0, k1;
        if (!row_columns(dr, reach, i, k0, k1)) break;
        if (certified(-k0, k1, -dr, dr)) {
          a.lo[static_cast<std::size_t>(r)] = i + k0;
          a.hi[static_cast<std::size_t>(r)] = i + k1;
          worst.grad = std::max(worst.grad, err_.grad);
          worst.taylor = std::max(worst.taylor, err_.taylor);
          break;
        }
      }
    }
    best_err = worst;
  }
  a.step = sample_step(best_err, a.quad);
  return true;
}

// make()'s helpers are inline (but certified_with, the certificate itself), as make() calls them
// in its searches, a few dozen times per anchor.
inline int AnchorMaker::sample_step(const Errors& err, bool& quad) const {
  quad = false;
  if (m_ == 0 || err.grad + err.taylor <= prop_budget) return 0;
  const double grad = err.grad;
  const auto& P = b_->p2;
  const auto& P3 = b_->p3;
  double q2 = 0.0, q3 = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t f = 0; f < 3; ++f) {
      q2 += std::abs(dx_[d]) * std::abs(dx_[f]) * P[d][f];
      for (std::size_t g = 0; g < 3; ++g) q3 += std::abs(dx_[d]) * std::abs(dx_[f]) * std::abs(dx_[g]) * P3[d][f][g];
    }
  q2 *= 1.01;
  q3 *= 1.01;
  const double room = prop_budget - grad;
  const double most = static_cast<double>(std::max(nx_, 1));
  const double s = q2 > 0.0 ? std::floor(std::sqrt(8.0 * room / q2)) : most;
  const double s3 = q3 > 0.0 ? std::floor(std::cbrt(12.0 * room / q3)) : most;
  quad = s3 >= 2.0 && s3 > s;
  return static_cast<int>(std::clamp(quad ? s3 : s, 1.0, most));
}

inline int AnchorMaker::box_cap(int kn, int ln, int lp) const {
  double cap = nx_;
  for (std::size_t j = 0; j < 3; ++j) {
    if (!(inv_dx_[j] > 0.0)) continue;
    const double ya = -ln * dy_[j], yb = lp * dy_[j];
    const double up = room_hi_[j] - std::max(ya, yb), down = room_lo_[j] + std::min(ya, yb);
    if (kn < 0)
      cap = std::min(cap, std::min(up, down) * inv_dx_[j]);
    else
      cap = std::min(cap, (dx_[j] > 0.0 ? up : down) * inv_dx_[j]);
  }
  return cap >= 1.0 ? static_cast<int>(std::floor(cap)) : 0;  // NaN: 0
}

inline bool AnchorMaker::row_columns(int dr, int reach, int i, int& k0, int& k1) const {
  double lo = -reach, hi = reach;
  for (std::size_t j = 0; j < 3; ++j) {
    const double y = dr * dy_[j];
    if (!(inv_dx_[j] > 0.0)) continue;  // not bounded along the row (the certificate decides)
    // k dx_j + y within [-room_lo, room_hi]
    const double a = (-room_lo_[j] - y) * inv_dx_[j], b = (room_hi_[j] - y) * inv_dx_[j];
    if (dx_[j] > 0.0) lo = std::max(lo, a), hi = std::min(hi, b);
    else lo = std::max(lo, -b), hi = std::min(hi, -a);
  }
  if (!(lo <= hi)) return false;  // NaN: none
  k0 = std::max(static_cast<int>(std::ceil(lo)), -i);
  k1 = std::min(static_cast<int>(std::floor(hi)), nx_ - 1 - i);
  return k0 <= k1;
}

template <class F>
int AnchorMaker::largest(F&& ok, int guess, int cap, bool cap_first) const {
  const int limit = std::min(cap, nx_);
  guess = std::min(guess, limit);
  if (guess > 0) {
    const int more = std::min(limit, guess + guess / 4 + 1);
    if (ok(more)) return cap_first && more < limit && ok(limit) ? limit : more;
    if (ok(guess)) return guess;
  }
  if (!ok(0)) return -1;
  int good = 0, bad = -1;
  for (int k = 1; k <= limit; k *= 2) {
    if (!ok(k)) {
      bad = k;
      break;
    }
    good = k;
  }
  if (bad < 0) {
    if (ok(limit)) return limit;
    bad = limit + 1;
  }
  while (bad - good > 1) {
    const int mid = good + (bad - good) / 2;
    (ok(mid) ? good : bad) = mid;
  }
  return good;
}

inline bool AnchorMaker::certified(int kn, int kp, int ln, int lp) const {
  // Bounds hold in the piece's box; where the certificate reaches out of it (a voxel on or
  // next to a face) they are retried with every bound scaled by 1.01, valid as long as the
  // reach outside keeps the polynomial growth below that factor.
  if (norms_[1].valid && certified_with(kn, kp, ln, lp, 1.0, norms_[1]) > 0) return true;
  const int first = certified_with(kn, kp, ln, lp, 1.0, norms_[0]);
  return first > 0 || (first < 0 && certified_with(kn, kp, ln, lp, 1.01, norms_[0]) > 0);
}

int AnchorMaker::certified_with(int kn, int kp, int ln, int lp, double G, const Norm& nm) const {
  const Vec3& D = nm.scale;
  const auto& w = nm.w;
  const bool scaled = &nm != &norms_[0];
  const double K = std::max(kn, kp), L = std::max(ln, lp);
  const Vec3 a{std::abs(c0_[0]) + K * std::abs(dx_[0]) + L * std::abs(dy_[0]),
               std::abs(c0_[1]) + K * std::abs(dx_[1]) + L * std::abs(dy_[1]),
               std::abs(c0_[2]) + K * std::abs(dx_[2]) + L * std::abs(dy_[2])};
  const Vec3 as{D[0] * a[0], D[1] * a[1], D[2] * a[2]};  // in the scaled parameters
  const double s1 = as[0] + as[1] + as[2];
  const double omega = G * nm.omega;
  const double theta = omega * s1;
  if (!(theta <= 0.5)) return 0;
  const auto& B = b_->b2;
  const double e2 = G * (0.5 * (B[0][0] * a[0] * a[0] + B[1][1] * a[1] * a[1] + B[2][2] * a[2] * a[2]) +
                         B[0][1] * a[0] * a[1] + B[0][2] * a[0] * a[2] + B[1][2] * a[1] * a[2]);
  if (!(e2 <= max_residual_)) return 0;  // keeps the (u,v,w) reported meaningful
  const double eta = G * (0.5 * (w[0][0] * as[0] * as[0] + w[1][1] * as[1] * as[1] + w[2][2] * as[2] * as[2]) +
                          w[0][1] * as[0] * as[1] + w[0][2] * as[0] * as[2] + w[1][2] * as[1] * as[2]);
  const double beta = 1.0 / (1.0 - theta);  // |G_s'(t)^-1| <= 1 / (1 - |G_s'(t) - I|)
  const double h = beta * beta * sqrt3 * omega * eta;
  if (!(h <= 0.5)) return 0;
  // Kantorovich: the root lies within (1 - sqrt(1 - 2h)) / (beta L) = 2 beta eta / (1 + sqrt(1 - 2h))
  // of t in the scaled parameters' 2-norm, so within R / D_j of t_j.
  const double R = 2.0 * beta * eta / (1.0 + std::sqrt(1.0 - 2.0 * h));
  const Vec3 r{R / D[0], R / D[1], R / D[2]};
  // How far the parameters and the ball around them leave the piece's box, per direction.
  // Leaving it by delta puts the root t* of the piece's polynomial up to delta outside, where
  // its point is still within slope * delta of the cell: allowed while that stays below the
  // tolerance (the contract leaves such voxels either way), so that a layer through a face is
  // certified like any other. Outside the box a polynomial of degree n grows by at most the
  // Chebyshev factor T_n(1 + 2 delta / len) <= cosh(n sqrt(4 delta / len)).
  Vec3 out{};
  double off = 0.0;
  const double dkn = kn, dkp = kp, dln = ln, dlp = lp;
  for (std::size_t j = 0; j < 3; ++j) {
    // The extreme parameters over the rectangle: at its corners.
    const double base = e_->t[j] + c0_[j];
    const double xa = -dkn * dx_[j], xb = dkp * dx_[j], ya = -dln * dy_[j], yb = dlp * dy_[j];
    const double lo = base + std::min(xa, xb) + std::min(ya, yb), hi = base + std::max(xa, xb) + std::max(ya, yb);
    out[j] = std::max({0.0, hi + r[j] - b_->hi[j], b_->lo[j] - (lo - r[j])});
    off += b_->slope[j] * out[j];
  }
  if (off > 0.0) {
    if (scaled) return 0;  // out of the piece: the plain norm's proof alone
    // grow >= 1: too far out whatever the growth factor (and a larger G only reaches farther).
    if (!(off <= tol_)) return 0;
    double grow = 1.0;
    for (std::size_t j = 0; j < 3; ++j)
      if (out[j] > 0.0) grow *= std::cosh(b_->degree[j] * std::sqrt(4.0 * out[j] / (b_->hi[j] - b_->lo[j])));
    if (!(grow <= G)) return G > 1.0 ? 0 : -1;
    if (!(grow * off <= tol_)) return 0;
  }
  // |P(t*) - model| <= Taylor remainder + sum_d (largest dP/dt_d near t) |t*_d - t_d|, plus,
  // for t* outside the box, the change to the cell's nearest parameters.
  // The properties: the first-order model within the budget (its Taylor remainder and the
  // gradient term), or else exact at t up to the interpolation between samples (sample_step),
  // which gets the budget the gradient term leaves; that term may take at most half of it.
  const auto& P = b_->p2;
  double grad_term = 0.0;
  for (std::size_t d = 0; d < 3; ++d) {
    const double g = gmax_[d] + G * (P[d][0] * (a[0] + r[0]) + P[d][1] * (a[1] + r[1]) + P[d][2] * (a[2] + r[2]));
    grad_term += g * (r[d] + out[d]);
  }
  const double taylor = G * (0.5 * (P[0][0] * a[0] * a[0] + P[1][1] * a[1] * a[1] + P[2][2] * a[2] * a[2]) +
                             P[0][1] * a[0] * a[1] + P[0][2] * a[0] * a[2] + P[1][2] * a[1] * a[2]);
  if (!(grad_term <= 0.5 * prop_budget || grad_term + taylor <= prop_budget)) return 0;
  err_ = {grad_term, taylor};
  return 1;
}

}  // namespace trivox::slice::detail
