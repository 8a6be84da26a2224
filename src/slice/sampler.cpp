#include "trivox/slice/sampler.hpp"

#include "trivox/slice/trim.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cassert>
#include <cstring>
#include <type_traits>
#include <cmath>
#include <limits>
#include <span>
#include <string>

#include "trivox/error.hpp"

namespace trivox::slice {

namespace {

constexpr double sqrt3 = 1.7320508075688772;
/// Property error the stepping certifies: the contract's 1/512 less 5% for rounding (the float
/// stored is within 1e-7 of the double computed).
constexpr double prop_budget = 0.95 / 512.0;

LocatorOptions options_for(const VoxelGrid& grid) {
  const double pmin = std::min({grid.pitch[0], grid.pitch[1], grid.pitch[2]});
  if (!(std::isfinite(pmin) && pmin > 0.0))
    throw Error("voxel pitch " + std::to_string(pmin) + " mm; expected positive finite pitches");
  LocatorOptions o;
  o.tolerance = 1e-3 * pmin;
  // Leaves hugging the cells to within about a voxel: little empty space left to invert.
  o.leaf_deviation = 1.0 * std::max({grid.pitch[0], grid.pitch[1], grid.pitch[2]});
  // Then on towards a quarter of that, within 4 times the leaves per piece.
  o.fine_leaf_deviation = 0.25 * o.leaf_deviation;
  o.fine_leaf_factor = 4;
  return o;
}

/// First voxel index whose centre is >= x (clamped to [0, n]).
int first_at_or_after(double x, double origin, double pitch, int n) {
  const double f = std::ceil((x - origin) / pitch - 0.5);
  return static_cast<int>(std::clamp(f, 0.0, static_cast<double>(n)));
}
/// Last voxel index whose centre is <= x (clamped to [-1, n - 1]).
int last_at_or_before(double x, double origin, double pitch, int n) {
  const double f = std::floor((x - origin) / pitch - 0.5);
  return static_cast<int>(std::clamp(f, -1.0, static_cast<double>(n - 1)));
}

/// The inverse of J (given by columns), as rows; false when singular.
bool invert(const std::array<Vec3, 3>& J, std::array<Vec3, 3>& inv) {
  auto cross = [](const Vec3& a, const Vec3& b) {
    return Vec3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  const Vec3 c0 = cross(J[1], J[2]), c1 = cross(J[2], J[0]), c2 = cross(J[0], J[1]);
  const double det = J[0][0] * c0[0] + J[0][1] * c0[1] + J[0][2] * c0[2];
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return false;
  for (std::size_t k = 0; k < 3; ++k) {
    inv[0][k] = c0[k] / det;
    inv[1][k] = c1[k] / det;
    inv[2][k] = c2[k] / det;
  }
  return true;
}

inline Vec3 mul(const std::array<Vec3, 3>& rows, const Vec3& v) {
  return {rows[0][0] * v[0] + rows[0][1] * v[1] + rows[0][2] * v[2], rows[1][0] * v[0] + rows[1][1] * v[1] + rows[1][2] * v[2],
          rows[2][0] * v[0] + rows[2][1] * v[1] + rows[2][2] * v[2]};
}

/// Whether t lies outside the box dom.
bool beyond(const Vec3& t, const std::array<Vec3, 2>& dom) {
  for (std::size_t d = 0; d < 3; ++d)
    if (t[d] < dom[0][d] || t[d] > dom[1][d]) return true;
  return false;
}

/// A leaf met by the current row: its voxel interval and warm-start state.
struct RowLeaf {
  int leaf, cell;
  int i0, i1;   ///< voxels whose centres lie in the leaf's regions (grown by the tolerance)
  int last_i;   ///< the voxel this leaf last solved, or -2
  Vec3 last_t;  ///< where that Newton run ended
};

/// Rows of a layer processed together: anchors certify rectangles of voxels spanning them.
/// Blocks are aligned on multiples of this in image rows, and a band always computes whole
/// blocks, so results never depend on the banding.
constexpr int block_rows = LayerSampler::block_rows;

/// Certified first-order stepping from an anchor (an Expansion at voxel (ia, la) of a block):
/// voxel (ia + k, la + l) gets t = t0 + J0^-1 (p - X0) = t0 + c0 + k dx + l dy, accepted only
/// when rigorous bounds show (Newton-Kantorovich, in Deuflhard's affine-covariant form, see
/// AnchorMaker::certified) that the exact preimage t* of its centre lies within r of t inside the
/// anchor's piece (or outside it by less than the tolerance) and that its properties are within
/// 0.95/512 of P(t*). With properties (Anchor::step > 0), the piece's own polynomial is evaluated
/// exactly at the t of every `step`-th voxel of a run and interpolated linearly in between: the
/// error is the gradient times |t* - t| (at most half the budget, from the certificate) plus the
/// interpolation's step^2 / 8 max |d^2 P / dk^2| (the rest; the second partials' bounds seen
/// along dx). So an anchor's rectangle is limited by the geometry and the piece alone, not by
/// how fast the properties vary, as with the first-order property model P0 + G0 (t - t0), which
/// is kept (step 0) where its Taylor remainder fits the budget. The bounds use the piece's
/// bounds on second partials (StepBounds). Bounding |t_j - t0_j| by |c0_j| + |k| |dx_j| +
/// |l| |dy_j| makes every bound grow with |k| and |l|, and the margin to the piece's box is
/// affine in (k, l), so certifying the extreme |k|, |l| and the four corners certifies a whole
/// rectangle: found once per anchor by doubling and bisection, after which a voxel costs a few
/// multiply-adds.
struct Anchor {
  int ia = 0, la = 0;                 ///< voxel column and block row of the expansion
  std::array<int, block_rows> lo{}, hi{};  ///< certified columns per block row (lo > hi: none)
  Vec3 tb{}, dx{}, dy{};              ///< t(k, l) = tb + k dx + l dy
  int piece = -1;                     ///< the expansion's piece
  std::array<double, Expansion::max_props> pb{}, pdx{}, pdy{};  ///< P(k, l) likewise (step 0)
  int step = 0;                       ///< properties exact every step columns (0: P(k, l))
  bool quad = false;                  ///< between the exact ones quadratic, not linear (fill)

  bool covers(int l, int i) const { return lo[static_cast<std::size_t>(l)] <= i && i <= hi[static_cast<std::size_t>(l)]; }
  /// Whether it certifies some voxels in each of the block's `rows` rows.
  bool spans_block(int rows) const {
    for (std::size_t r = 0; r < static_cast<std::size_t>(rows); ++r)
      if (lo[r] > hi[r]) return false;
    return true;
  }
  Vec3 at(int l, int i) const {
    const double k = i - ia, dl = l - la;
    return {tb[0] + k * dx[0] + dl * dy[0], tb[1] + k * dx[1] + dl * dy[1], tb[2] + k * dx[2] + dl * dy[2]};
  }
};

/// Builds anchors from expansions: the certification of the struct comment above.
class AnchorMaker {
public:
  /// A norm of the parameters for the certificate: s_j = scale_j t_j, with w and omega the
  /// bounds of make() seen in it. norms_[0]: plain (scale 1); norms_[1]: D_j = |dX/dt_j| at the
  /// anchor (invalid where a column of J0 vanishes).
  struct Norm {
    Vec3 scale{1.0, 1.0, 1.0};
    std::array<Vec3, 3> w{};
    double omega = 0.0;
    bool valid = true;
  };

  AnchorMaker(const Locator& loc, const VoxelGrid& grid, int m, int rows, double max_residual)
      : loc_(loc), m_(m), rows_(rows), px_(grid.pitch[0]), py_(grid.pitch[1]), max_residual_(max_residual),
        tol_(loc.options().tolerance), nx_(grid.count[0]) {}

  /// An anchor at voxel (i, l) with centre p from the expansion e; false when nothing (not even
  /// the voxel itself) is certified. With `shift` > 0 the anchor must reach `shift` columns to
  /// its left (the first voxel not yet covered lies there: the anchor sits ahead of it, so that
  /// its rectangle does not overlap the previous one) and spans the whole block, else false.
  bool make(const Expansion& e, int i, int l, const Vec3& p, Anchor& a, int shift = 0) {
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

private:
  /// The property errors of a certified rectangle (certified_with): the gradient term and the
  /// first-order model's Taylor remainder.
  struct Errors {
    double grad = 0.0, taylor = 0.0;
  };

  /// How a certified rectangle with errors `err` gets its properties (Anchor's comment): 0, the
  /// first-order model, when its remainder fits the budget too (no evaluations); else the spacing
  /// s of exact evaluations along its rows, with the interpolation's error within the budget the
  /// gradient term leaves, `room`. Along a row the properties are the polynomial f(k) = P(t0 +
  /// k dx): linear interpolation between samples s apart errs by at most s^2 / 8 Q2, Q2 >= |f''|
  /// = |dx^T (d^2 P / dt^2) dx| from the piece's second-partial bounds; quadratic interpolation
  /// through three samples at most s apart (fill) by |f'''| / 6 max |(k - a)(k - b)(k - c)| <=
  /// Q3 / 6 * s^3 / 2 (on [a, b]: (k - a)(b - k) <= s^2 / 4 and c - k <= 2 s; on [b, c] alike),
  /// Q3 >= |f'''| = |sum d^3 P / dt_d dt_e dt_f dx_d dx_e dx_f| from the third-partial bounds.
  /// Both bounds times the 1.01 of a certificate reaching out of the piece. Quadratic where it
  /// spaces the samples farther (stepped by forward differences, it costs one add per value more
  /// than linear: less than the exact samples it saves).
  int sample_step(const Errors& err, bool& quad) const {
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

  /// The largest k for which the rectangle of columns -kn .. k (kn < 0: -k .. k) and rows -ln ..
  /// lp keeps its linear-model parameters inside the bounds' box grown by the certificate's
  /// reach out of it (tol / slope per direction; at most nx, at least 0): no larger k is
  /// certified, and where the box binds (a cell's face, the piece's edge) it is the anchor's
  /// width, found without a search (room_lo_, room_hi_, inv_dx_ from make()).
  int box_cap(int kn, int ln, int lp) const {
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

  /// The columns k0..k1 (relative to the anchor's column i, within the row and within -reach ..
  /// reach) of the block row dr rows from the anchor's where its linear-model parameters stay
  /// inside the bounds' box grown by the certificate's reach out of it (box_cap's terms);
  /// false when there are none. A first guess for certified(): the certificate decides.
  bool row_columns(int dr, int reach, int i, int& k0, int& k1) const {
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

  /// The largest k in [0, cap] with ok(k) (ok is monotone: true up to some k), or -1: a little
  /// more than `guess` first (neighbouring anchors are alike), and then cap itself when the last
  /// anchor of its kind reached its cap (`cap_first`: the box binds there); else doubling and
  /// bisection.
  template <class F>
  int largest(F&& ok, int guess, int cap, bool cap_first) const {
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

  /// Whether every voxel (ia + k, la + l), -kn <= k <= kp, -ln <= l <= lp, is certified.
  /// Newton-Kantorovich for G(t) = J0^-1 (X(t) - p) from the voxel's linear-model parameters t
  /// (d = t - t0, |d_j| <= a_j): |G(t)| <= eta = 1/2 sum w_de a_d a_e (Taylor); G' = J0^-1 J moves
  /// by at most theta = omega |d|_1 <= 1/2 from the identity, so |G'(t)^-1| <= beta = 1/(1 - theta)
  /// (Neumann series); G' is Lipschitz with L = sqrt3 omega in the 2-norm; then Kantorovich's
  /// h = beta^2 L eta <= 1/2 puts the root within r = (1 - sqrt(1 - 2h)) / (beta L)
  /// = 2 beta eta / (1 + sqrt(1 - 2h)) of t (about eta when h is small, 4 eta at worst).
  /// The bounds are those of the anchor's piece (Locator::step_bounds); leaving it is handled
  /// below.
  bool certified(int kn, int kp, int ln, int lp) const {
    // Bounds hold in the piece's box; where the certificate reaches out of it (a voxel on or
    // next to a face) they are retried with every bound scaled by 1.01, valid as long as the
    // reach outside keeps the polynomial growth below that factor.
    if (norms_[1].valid && certified_with(kn, kp, ln, lp, 1.0, norms_[1]) > 0) return true;
    const int first = certified_with(kn, kp, ln, lp, 1.0, norms_[0]);
    return first > 0 || (first < 0 && certified_with(kn, kp, ln, lp, 1.01, norms_[0]) > 0);
  }

  /// 1: certified; 0: not; -1: the certificate leaves the box (retry with a growth factor G).
  int certified_with(int kn, int kp, int ln, int lp, double G, const Norm& nm) const {
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

  const Locator& loc_;
  int m_, rows_;
  double px_, py_, max_residual_, tol_;
  int nx_;
  const StepBounds* b_ = nullptr;
  const Expansion* e_ = nullptr;
  Vec3 c0_{}, dx_{}, dy_{};
  Vec3 gmax_{};                 ///< largest |dP_h/dt_d| at the anchor
  std::array<Norm, 2> norms_{};
  Vec3 room_lo_{}, room_hi_{}, inv_dx_{};  ///< box_cap's terms (0 in inv_dx_: unbounded)
  mutable Errors err_;          ///< the property errors of the last rectangle certified
  std::array<int, 3> guess_{-1, -1, -1};
  std::array<bool, 4> capped_{};  ///< per kind (the three shapes, shifted), the last anchor reached its cap
};

/// A proof that points beyond a face of a cell are not in the leaves of one Bezier piece near
/// that face, from one expansion at a point tb on the face (where the voxels' linear-model
/// parameters leave the domain), without Newton. With c = J0^-1 (p - X(tb)) and the piece's
/// bounds on second partials (StepBounds::b2v, seen through |J0^-1| entrywise: W_j bounds the
/// j-th component of J0^-1 d^2X / dt_d dt_e summed over d, e), a root t* of X(t) = p at
/// s = |t* - tb|_inf satisfies s <= |c|_inf + W s^2 / 2 (Taylor along the segment from tb, which
/// stays where the bounds hold), so s <= s1 = 2 |c| / (1 + sqrt(1 - 2 W |c|)) or s >= s2 =
/// (1 + sqrt(1 - 2 W |c|)) / W. A leaf of the piece within the bounds' box and closer to tb
/// than s2 (in every direction) can hold a root only within s1 of tb, and there
/// t*_j - tb_j >= c_j - W_j s1^2 / 2 (or <= c_j + W_j s1^2 / 2): when that puts t*_j beyond the
/// domain's face that tb lies on, the leaf holds no root, and p is not in it.
struct Exclusion {
  int piece = -1;               ///< -1: unused
  Vec3 tb{}, xb{};              ///< the expansion point and X(tb)
  std::array<Vec3, 3> inv{};    ///< J0^-1, rows
  std::array<int, 3> side{};    ///< +1: tb on the domain's upper face along j; -1 lower; 0 neither
  Vec3 wj{};                    ///< W_j
  double w = 0.0;               ///< max_j W_j
  Vec3 lo{}, hi{};              ///< where the bounds hold
  double margin = 0.0;          ///< parameter margin beyond the face (rounding)

  /// From an expansion at tb = e.t (t clamped to the domain `dom`, the prediction t beyond it).
  bool set(const Locator& loc, const Expansion& e, const std::array<Vec3, 2>& dom) {
    piece = -1;
    bool any = false;
    for (std::size_t j = 0; j < 3; ++j) {
      side[j] = e.t[j] >= dom[1][j] ? 1 : e.t[j] <= dom[0][j] ? -1 : 0;
      any = any || side[j] != 0;
    }
    if (!any || !invert(e.jac, inv)) return false;
    const StepBounds& b = loc.step_bounds(e.piece);
    if (!b.valid) return false;
    w = 0.0;
    for (std::size_t j = 0; j < 3; ++j) {
      double sum = 0.0;
      for (std::size_t d = 0; d < 3; ++d)
        for (std::size_t f = 0; f < 3; ++f)
          sum += std::abs(inv[j][0]) * b.b2v[d][f][0] + std::abs(inv[j][1]) * b.b2v[d][f][1] + std::abs(inv[j][2]) * b.b2v[d][f][2];
      wj[j] = sum * (1.0 + 1e-12);
      w = std::max(w, wj[j]);
    }
    if (!std::isfinite(w)) return false;
    lo = b.lo;
    hi = b.hi;
    margin = 0.0;
    for (std::size_t j = 0; j < 3; ++j) margin = std::max(margin, 1e-12 * (std::abs(dom[0][j]) + std::abs(dom[1][j])));
    tb = e.t;
    xb = e.x;
    piece = e.piece;
    return true;
  }

  /// Whether p lies in none of the leaves [lb, le) that hold voxel i (their row intervals).
  bool proves(const Vec3& p, int i, const RowLeaf* lb, const RowLeaf* le, std::span<const LocatorLeaf> leaves) const {
    if (piece < 0) return false;
    const Vec3 r{p[0] - xb[0], p[1] - xb[1], p[2] - xb[2]};
    const Vec3 c = mul(inv, r);
    const double cn = std::max({std::abs(c[0]), std::abs(c[1]), std::abs(c[2])});
    const double disc = 1.0 - 2.0 * w * cn;
    if (!(disc > 0.0)) return false;
    const double sq = std::sqrt(disc);
    const double s1 = 2.0 * cn / (1.0 + sq);
    const double s2 = w > 0.0 ? (1.0 + sq) / w : std::numeric_limits<double>::infinity();
    bool beyond = false;
    for (std::size_t j = 0; j < 3 && !beyond; ++j) {
      const double q = 0.5 * wj[j] * s1 * s1 + margin;
      beyond = (side[j] > 0 && c[j] > q) || (side[j] < 0 && c[j] < -q);
    }
    if (!beyond) return false;
    for (const RowLeaf* rl = lb; rl != le; ++rl) {
      if (i < rl->i0 || i > rl->i1) continue;
      const LocatorLeaf& lf = leaves[static_cast<std::size_t>(rl->leaf)];
      if (lf.piece != piece) return false;
      for (std::size_t j = 0; j < 3; ++j)
        if (lf.lo[j] < lo[j] - margin || lf.hi[j] > hi[j] + margin || !(std::max(lf.hi[j] - tb[j], tb[j] - lf.lo[j]) < s2)) return false;
    }
    return true;
  }
};

/// The last converged voxels of a run in one cell, for extrapolating the next voxel's (u,v,w)
/// where stepping does not apply (rational cells, many properties): their uvw corrected to well
/// below the tolerance (extrapolation amplifies errors), and the inverse Jacobian of the last
/// Newton run for those corrections.
struct Chain {
  Vec3 uvw[3] = {};
  int n = 0;
  std::array<Vec3, 3> inv{};
  bool have_inv = false;

  /// Quadratic (linear, constant) extrapolation; false when it leaves the domain.
  bool predict(const std::array<Vec3, 2>& dom, Vec3& t) const {
    for (std::size_t d = 0; d < 3; ++d) {
      t[d] = n == 1 ? uvw[0][d] : n == 2 ? 2.0 * uvw[0][d] - uvw[1][d] : 3.0 * uvw[0][d] - 3.0 * uvw[1][d] + uvw[2][d];
      if (t[d] < dom[0][d] || t[d] > dom[1][d]) return false;
    }
    return true;
  }
  void push(const Vec3& t) {
    uvw[2] = uvw[1];
    uvw[1] = uvw[0];
    uvw[0] = t;
    n = std::min(n + 1, 3);
  }
  /// A voxel accepted at t with residual r = p - X(t): a quasi-Newton step with the last
  /// Jacobian (a few voxels away, so close) before remembering it.
  void push_checked(Vec3 t, const Vec3& r, const std::array<Vec3, 2>& dom) {
    if (have_inv) {
      const Vec3 c = mul(inv, r);
      for (std::size_t d = 0; d < 3; ++d) t[d] = std::clamp(t[d] + c[d], dom[0][d], dom[1][d]);
    }
    push(t);
  }
  void push_solved(const NewtonResult& res) {
    have_inv = invert(res.jacobian, inv);
    push(res.polished);
  }
  void set_jacobian(const std::array<Vec3, 3>& jac) { have_inv = invert(jac, inv); }
};

enum class Outcome { inside, guessed, outside };

/// The slow path for one voxel: Newton over the cell from a prediction (when there is one), then
/// the leaves whose intervals hold the voxel, each warm-started from its own answer at the
/// previous voxel (Locator::solve_in_leaf, with its subdivision fallback).
/// @param start        a prediction, or null
Outcome solve_voxel(const Locator& loc, const VoxelGrid& grid, int cell, int i, const Vec3& p, const Vec3* start,
                    Chain& chain, Vec3& t, RowLeaf* leaves_begin, RowLeaf* leaves_end, const std::array<Vec3, 2>& dom,
                    std::int64_t& failures) {
  NewtonResult res;
  if (start) res = loc.newton(cell, p, *start, dom[0], dom[1], 6);
  if (!start || res.status != NewtonStatus::converged) {
    const Vec3 from = res.uvw;
    NewtonResult best;
    best.residual = std::numeric_limits<double>::infinity();
    bool failed = false, found = false;
    for (RowLeaf* rl = leaves_begin; rl != leaves_end; ++rl) {
      if (i < rl->i0 || i > rl->i1) continue;
      const Vec3* warm = rl->last_i == i - 1 ? &rl->last_t : start ? &from : nullptr;
      const NewtonResult lr = loc.solve_in_leaf(rl->leaf, p, warm);
      rl->last_i = i;
      rl->last_t = lr.polished;
      if (lr.status == NewtonStatus::converged) {
        res = lr;
        found = true;
        break;
      }
      if (lr.status == NewtonStatus::failed) {
        failed = true;
        if (lr.residual < best.residual) best = lr;
      }
    }
    if (!found) {
      chain.n = 0;
      if (!failed) return Outcome::outside;
      ++failures;
      // Best guess: inside when the best iterate's image is within half the smallest pitch.
      const double guess = 0.5 * std::min({grid.pitch[0], grid.pitch[1], grid.pitch[2]});
      if (!(best.residual < guess)) return Outcome::outside;
      t = best.uvw;
      return Outcome::guessed;
    }
  }
  t = res.uvw;
  chain.push_solved(res);
  return Outcome::inside;
}

/// Four doubles and four floats as vectors (GCC and Clang vector extensions; the same IEEE
/// operations lane by lane on any target).
using V4d = double __attribute__((vector_size(32)));
using V4f = float __attribute__((vector_size(16)));

/// The blocks of a run (write_linear_body, write_quadratic_body): `blocks` blocks of w = 4 M
/// values from base, stepped by one add each per block (by step, and step by step2 when Q);
/// then the values after the last block, of the rest of the run (`rest` of them). The rounding
/// this accumulates over a run of a few hundred voxels is some 1e-14 of the values, far below
/// the floats written. With M known, the values are M vectors of four, kept in registers.
template <int M, bool Q>
[[gnu::always_inline]] inline void step_blocks(float* o, int blocks, int w, int rest, double* base, double* step,
                                               const double* step2) {
  if constexpr (M > 0) {
    V4d bv[M], sv[M], s2[M];
    std::memcpy(bv, base, sizeof bv);
    std::memcpy(sv, step, sizeof sv);
    if constexpr (Q) std::memcpy(s2, step2, sizeof s2);
    for (int b = 0; b < blocks; ++b, o += w)
      for (int i = 0; i < M; ++i) {
        const V4f f = __builtin_convertvector(bv[i], V4f);
        std::memcpy(o + 4 * i, &f, sizeof f);
        bv[i] += sv[i];
        if constexpr (Q) sv[i] += s2[i];
      }
    std::memcpy(base, bv, sizeof bv);
  } else {
    for (int b = 0; b < blocks; ++b, o += w)
      for (int k = 0; k < w; ++k) {
        o[k] = static_cast<float>(base[k]);
        base[k] += step[k];
        if constexpr (Q) step[k] += step2[k];
      }
  }
  for (int k = 0; k < rest; ++k) o[k] = static_cast<float>(base[k]);
}

/// out[j m + h] = va[h] + j slope[h] for j < n, h < m (a run of voxels' properties from a linear
/// model): four voxels' m values at a time, as one flat run of 4m floats (base, stepped by delta per block),
/// which vectorises. M: m known at compile time (-1: m).
template <int M>
[[gnu::always_inline]] inline void write_linear_body(float* out, int n, int m, const double* va, const double* slope) {
  const int um = M >= 0 ? M : m;
  if (n < 8) {  // short runs (curved cells, boundaries): no set-up
    for (int j = 0; j < n; ++j)
      for (int h = 0; h < um; ++h) out[j * um + h] = static_cast<float>(va[h] + j * slope[h]);
    return;
  }
  constexpr int W = 4 * (M >= 0 ? M : Expansion::max_props);
  double base[W > 0 ? W : 1], delta[W > 0 ? W : 1];
  const int w = 4 * um;
  for (int h = 0; h < um; ++h)
    for (int v = 0; v < 4; ++v) {
      base[v * um + h] = va[h] + v * slope[h];
      delta[v * um + h] = 4.0 * slope[h];
    }
  const int blocks = n / 4;
  step_blocks<M, false>(out, blocks, w, (n - 4 * blocks) * um, base, delta, nullptr);
}

template <int M>
void write_linear(float* out, int n, int m, const double* va, const double* slope) {
  write_linear_body<M>(out, n, m, va, slope);
}
#if defined(__x86_64__)
/// The same operations on AVX registers (no contraction: the same floats).
template <int M>
[[gnu::target("avx2")]] void write_linear_avx2(float* out, int n, int m, const double* va, const double* slope) {
  write_linear_body<M>(out, n, m, va, slope);
}
#endif

using WriteLinear = void (*)(float*, int, int, const double*, const double*);

/// out[j m + h] = va[h] + j (slope[h] + j curv[h]) for j < n, h < m (a run of voxels' properties
/// from a quadratic): four voxels at a time as one flat run of 4m values, voxel 4 b + v being
/// g(b) = (va + v slope + v^2 curv) + b (4 slope + 8 v curv) + b^2 (16 curv), stepped from block
/// to block by forward differences (g(b + 1) - g(b) = 4 slope + 8 v curv + (2 b + 1) 16 curv).
/// M as write_linear_body's.
template <int M>
[[gnu::always_inline]] inline void write_quadratic_body(float* out, int n, int m, const double* va, const double* slope,
                                                        const double* curv) {
  const int um = M >= 0 ? M : m;
  constexpr int W = 4 * (M >= 0 ? M : Expansion::max_props);
  double base[W > 0 ? W : 1], step[W > 0 ? W : 1], step2[W > 0 ? W : 1];
  const int w = 4 * um;
  for (int h = 0; h < um; ++h)
    for (int v = 0; v < 4; ++v) {
      base[v * um + h] = va[h] + v * (slope[h] + v * curv[h]);
      step[v * um + h] = 4.0 * slope[h] + 8.0 * v * curv[h] + 16.0 * curv[h];
      step2[v * um + h] = 32.0 * curv[h];
    }
  const int blocks = n / 4;
  step_blocks<M, true>(out, blocks, w, (n - 4 * blocks) * um, base, step, step2);
}

template <int M>
void write_quadratic(float* out, int n, int m, const double* va, const double* slope, const double* curv) {
  write_quadratic_body<M>(out, n, m, va, slope, curv);
}
#if defined(__x86_64__)
template <int M>
[[gnu::target("avx2")]] void write_quadratic_avx2(float* out, int n, int m, const double* va, const double* slope,
                                                  const double* curv) {
  write_quadratic_body<M>(out, n, m, va, slope, curv);
}
#endif

using WriteQuadratic = void (*)(float*, int, int, const double*, const double*, const double*);

/// Whether the CPU runs the AVX2 builds of the kernels.
bool cpu_has_avx2() {
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
#else
  return false;
#endif
}

/// get(std::integral_constant<int, M>) for the property count m: M = m up to 4, else -1 (the
/// kernels' run-time count).
template <class Get>
auto by_props(int m, Get get) {
  switch (m) {
    case 1: return get(std::integral_constant<int, 1>{});
    case 2: return get(std::integral_constant<int, 2>{});
    case 3: return get(std::integral_constant<int, 3>{});
    case 4: return get(std::integral_constant<int, 4>{});
    default: return get(std::integral_constant<int, -1>{});
  }
}

WriteLinear pick_write(int m) {
  return by_props(m, [](auto k) -> WriteLinear {
#if defined(__x86_64__)
    if (cpu_has_avx2()) return write_linear_avx2<decltype(k)::value>;
#endif
    return write_linear<decltype(k)::value>;
  });
}

WriteQuadratic pick_write_quadratic(int m) {
  return by_props(m, [](auto k) -> WriteQuadratic {
#if defined(__x86_64__)
    if (cpu_has_avx2()) return write_quadratic_avx2<decltype(k)::value>;
#endif
    return write_quadratic<decltype(k)::value>;
  });
}

/// Where a block's results go: rows of nx voxels, straight into the caller's band when the block
/// lies inside it, else into scratch.
struct BlockOut {
  std::int32_t* owner = nullptr;  ///< rows x nx
  float* props = nullptr;         ///< rows x nx x m
  double* uvw = nullptr;          ///< rows x nx x 3, or null
  bool zero_props = true;         ///< clear props first (else void voxels' are left as they are)
  std::array<std::int64_t, block_rows> failures{}, inverted{};
};

/// Samples image rows [r0, r0 + nr) of layer `layer` (one block) into `out`.
class BlockSampler {
public:
  BlockSampler(const Locator& loc, const VoxelGrid& grid)
      : loc_(loc), grid_(grid), m_(static_cast<int>(loc.model().properties.size())), write_(pick_write(m_)),
        write_quad_(pick_write_quadratic(m_)) {}

  void run(int layer, int r0, int nr, BlockOut& out) {
    const int nx = grid_.count[0], ny = grid_.count[1];
    const auto unx = static_cast<std::size_t>(nx), um = static_cast<std::size_t>(m_);
    std::fill_n(out.owner, static_cast<std::size_t>(nr) * unx, -1);
    if (out.zero_props) std::fill_n(out.props, static_cast<std::size_t>(nr) * unx * um, 0.0f);
    if (out.uvw) std::fill_n(out.uvw, static_cast<std::size_t>(nr) * unx * 3, 0.0);
    out.failures.fill(0);
    out.inverted.fill(0);
    out_ = &out;
    nr_ = nr;
    tol_ = loc_.options().tolerance;
    z_ = grid_.origin[2] + (layer + 0.5) * grid_.pitch[2];
    for (int l = 0; l < nr; ++l) y_[static_cast<std::size_t>(l)] = grid_.origin[1] + (ny - 1 - (r0 + l) + 0.5) * grid_.pitch[1];
    const double inf = std::numeric_limits<double>::infinity();

    // Leaves meeting the block (in leaf order = cell order), and each row's voxel intervals.
    cand_.clear();
    loc_.for_each_leaf_in_box({-inf, y_[static_cast<std::size_t>(nr - 1)], z_}, {inf, y_[0], z_}, tol_,
                              [&](int l) { cand_.push_back(l); });
    if (cand_.empty()) return;
    const auto leaves = loc_.leaves();
    for (int l = 0; l < nr; ++l) {
      auto& act = act_[static_cast<std::size_t>(l)];
      act.clear();
      for (int c : cand_) {
        const auto& lf = leaves[static_cast<std::size_t>(c)];
        double x0, x1;
        if (!lf.row_range(y_[static_cast<std::size_t>(l)], z_, tol_, x0, x1)) continue;
        const int i0 = first_at_or_after(x0, grid_.origin[0], grid_.pitch[0], nx);
        const int i1 = last_at_or_before(x1, grid_.origin[0], grid_.pitch[0], nx);
        if (i0 <= i1) act.push_back({c, lf.cell, i0, i1, -2, {}});
      }
      std::sort(act.begin(), act.end(), [](const RowLeaf& a, const RowLeaf& b) {
        return a.cell < b.cell || (a.cell == b.cell && (a.i0 < b.i0 || (a.i0 == b.i0 && a.leaf < b.leaf)));
      });
      pos_[static_cast<std::size_t>(l)] = 0;
    }
    // Rows from the middle outwards, so the first anchors sit mid-block and serve every row.
    int order[block_rows], n = 0;
    for (int d = 0; n < nr; ++d) {
      if (nr / 2 - d >= 0 && n < nr) order[n++] = nr / 2 - d;
      if (d > 0 && nr / 2 + d < nr && n < nr) order[n++] = nr / 2 + d;
    }
    AnchorMaker maker(loc_, grid_, m_, nr, 0.5 * std::min({grid_.pitch[0], grid_.pitch[1], grid_.pitch[2]}));
    maker_ = &maker;
    for (std::size_t ci = 0; ci < cand_.size();) {
      const int cell = leaves[static_cast<std::size_t>(cand_[ci])].cell;
      while (ci < cand_.size() && leaves[static_cast<std::size_t>(cand_[ci])].cell == cell) ++ci;
      anchors_.clear();
      for (auto& x : excl_) x.piece = -1;
      for (int o = 0; o < nr; ++o) walk_row(cell, order[o]);
    }
  }

private:
  /// The voxels of row l that cell `cell`'s leaves reach, in x order.
  void walk_row(int cell, int l) {
    const auto ul = static_cast<std::size_t>(l);
    auto& act = act_[ul];
    std::size_t g0 = pos_[ul];
    while (g0 < act.size() && act[g0].cell < cell) ++g0;
    std::size_t g1 = g0;
    while (g1 < act.size() && act[g1].cell == cell) ++g1;
    pos_[ul] = g1;
    if (g0 == g1) return;
    const auto unx = static_cast<std::size_t>(grid_.count[0]), um = static_cast<std::size_t>(m_);
    std::int32_t* owner = out_->owner + ul * unx;
    float* props = out_->props + ul * unx * um;
    double* uvw = out_->uvw ? out_->uvw + ul * unx * 3 : nullptr;
    const auto dom = loc_.domain(cell);
    // Anchors made in earlier rows that cover this one, by first column.
    cover_.clear();
    for (std::size_t k = 0; k < anchors_.size(); ++k)
      if (anchors_[k].lo[ul] <= anchors_[k].hi[ul]) cover_.push_back(static_cast<int>(k));
    std::sort(cover_.begin(), cover_.end(), [&](int a, int b) { return anchors_[static_cast<std::size_t>(a)].lo[ul] < anchors_[static_cast<std::size_t>(b)].lo[ul]; });
    std::size_t cp = 0;
    int cur = -1;  // the anchor stepping now (index into anchors_)
    Chain chain;
    int check_run = 0;
    int prev_i = -2;
    std::size_t next = g0;  // first leaf of the group not yet opened
    int span_end = -1;
    int i = act[g0].i0;
    while (true) {
      if (i > span_end) {
        if (next >= g1) break;
        if (act[next].i0 > i) i = act[next].i0;
      }
      while (next < g1 && act[next].i0 <= i) span_end = std::max(span_end, act[next++].i1);
      // A run claimed up to span_end + 1 can leave i past every leaf opened so far (and past the
      // row's last voxel: i = nx); those leaves end before i, so look at the next ones.
      if (i > span_end) continue;
      assert(i <= span_end && span_end < grid_.count[0]);  // owner[i], props, uvw within the row
      if (i != prev_i + 1) chain.n = check_run = 0;
      // 1. Certified stepping: a run of voxels without any evaluation.
      if (cur < 0 || !anchors_[static_cast<std::size_t>(cur)].covers(l, i)) {
        while (cp < cover_.size() && anchors_[static_cast<std::size_t>(cover_[cp])].hi[ul] < i) ++cp;
        for (std::size_t q = cp; q < cover_.size() && anchors_[static_cast<std::size_t>(cover_[q])].lo[ul] <= i; ++q)
          if (anchors_[static_cast<std::size_t>(cover_[q])].covers(l, i)) {
            cur = cover_[q];
            break;
          }
      }
      if (cur >= 0 && anchors_[static_cast<std::size_t>(cur)].covers(l, i)) {
        const Anchor& a = anchors_[static_cast<std::size_t>(cur)];
        const int iend = std::min(a.hi[ul], span_end);
        // The run: certified and not taken (by an earlier cell), claimed as it is found.
        const int j = claim_run(owner, i, iend, cell);
        fill(a, l, i, j, props, uvw);
        out_->inverted[ul] += j - i;
        chain.n = 0;
        if (j > i) {
          prev_i = j - 1;
          i = j;
          continue;
        }
      }
      prev_i = i;
      if (owner[i] >= 0) {  // taken by an earlier cell
        chain.n = 0;
        ++i;
        continue;
      }
      ++out_->inverted[ul];
      visit(cell, l, i, span_end, dom, cur, chain, check_run, act.data() + g0, act.data() + next, owner[i], props + static_cast<std::size_t>(i) * um,
            uvw ? uvw + static_cast<std::size_t>(i) * 3 : nullptr);
      ++i;
    }
  }

  /// Gives `cell` the voxels i, i + 1, ... up to iend that no earlier cell took (owner -1), and
  /// returns the first one it did not give (a taken voxel, or iend + 1): eight at a time, as the
  /// AND of their owners is negative exactly when all eight are -1.
  static int claim_run(std::int32_t* owner, int i, int iend, int cell) {
    int j = i;
#if defined(__SSE2__)
    const __m128i c = _mm_set1_epi32(cell);
    for (; j + 8 <= iend + 1; j += 8) {
      __m128i* o = reinterpret_cast<__m128i*>(owner + j);
      const __m128i all = _mm_and_si128(_mm_loadu_si128(o), _mm_loadu_si128(o + 1));
      if (_mm_movemask_ps(_mm_castsi128_ps(all)) != 0xF) break;
      _mm_storeu_si128(o, c);
      _mm_storeu_si128(o + 1, c);
    }
#endif
    for (; j <= iend && owner[j] < 0; ++j) owner[j] = cell;
    return j;
  }

  /// Voxels i0 .. i1 - 1 of block row l from anchor a (their owners set by claim_run): uvw and
  /// properties (Anchor's comment): from the first-order model, or exact at the run's first and
  /// last voxels and every a.step-th between and linear in between.
  void fill(const Anchor& a, int l, int i0, int i1, float* props, double* uvw) {
    const int n = i1 - i0;
    if (n <= 0) return;
    if (uvw)
      for (int j = i0; j < i1; ++j) {
        const Vec3 t = a.at(l, j);
        std::copy(t.begin(), t.end(), uvw + static_cast<std::ptrdiff_t>(j) * 3);
      }
    if (m_ == 0) return;
    const auto um = static_cast<std::size_t>(m_);
    float* out = props + static_cast<std::size_t>(i0) * um;
    if (a.step == 0) {  // the first-order model
      double va[Expansion::max_props];
      const double k0 = i0 - a.ia, dl = l - a.la;
      for (std::size_t h = 0; h < um; ++h) va[h] = a.pb[h] + k0 * a.pdx[h] + dl * a.pdy[h];
      write_(out, n, m_, va, a.pdx.data());
      return;
    }
    const int step = a.step;
    if (a.quad) {
      fill_quadratic(a, l, i0, n, out);
      return;
    }
    const int count = n == 1 ? 1 : (n - 2) / step + 2;  // samples at 0, step, 2 step, ..., n - 1
    pts_.resize(static_cast<std::size_t>(count));
    vals_.resize(static_cast<std::size_t>(count) * um);
    for (int q = 0; q < count; ++q) pts_[static_cast<std::size_t>(q)] = a.at(l, i0 + std::min(q * step, n - 1));
    loc_.piece_properties(a.piece, pts_.data(), count, vals_.data());
    const double inv_step = 1.0 / step;
    for (int q = 0; q + 1 < count; ++q) {
      const int ja = q * step, jb = std::min(ja + step, n - 1);
      const double* va = vals_.data() + static_cast<std::size_t>(q) * um;
      const double* vb = va + um;
      const double inv = jb - ja == step ? inv_step : 1.0 / (jb - ja);
      double slope[Expansion::max_props];
      for (std::size_t h = 0; h < um; ++h) slope[h] = (vb[h] - va[h]) * inv;
      write_(out + static_cast<std::size_t>(ja) * um, jb - ja, m_, va, slope);
    }
    const double* vl = vals_.data() + static_cast<std::size_t>(count - 1) * um;
    for (std::size_t h = 0; h < um; ++h) out[static_cast<std::size_t>(n - 1) * um + h] = static_cast<float>(vl[h]);
  }

  /// fill's quadratic form (Anchor::quad): the n voxels from i0 in segments of at most 2 step
  /// voxels, each with exact samples at its ends and at its middle (so both halves are at most
  /// step long, as sample_step's bound needs), the quadratic through the three in between; a
  /// segment of one voxel takes its two ends alone. The last voxel is its exact sample.
  void fill_quadratic(const Anchor& a, int l, int i0, int n, float* out) {
    const auto um = static_cast<std::size_t>(m_);
    const int step = a.step;
    // The segments from `start`: len voxels, a middle sample where len >= 2.
    auto seg_len = [&](int start) { return std::min(2 * step, n - 1 - start); };
    // Sample offsets: 0, then per segment its middle (when it has one) and its end.
    offs_.clear();
    offs_.push_back(0);
    for (int start = 0; start < n - 1; start += seg_len(start)) {
      const int len = seg_len(start);
      if (len >= 2) offs_.push_back(start + len / 2);
      offs_.push_back(start + len);
    }
    const auto count = offs_.size();
    pts_.resize(count);
    vals_.resize(count * um);
    for (std::size_t q = 0; q < count; ++q) pts_[q] = a.at(l, i0 + offs_[q]);
    loc_.piece_properties(a.piece, pts_.data(), static_cast<int>(count), vals_.data());
    std::size_t q = 0;  // the segment's first sample
    for (int start = 0; start < n - 1; start += seg_len(start)) {
      const int len = seg_len(start);
      const double* va = vals_.data() + q * um;
      const double* vb = va + um;
      double slope[Expansion::max_props], curv[Expansion::max_props];
      if (len >= 2) {
        // Newton's form through (0, f0), (h1, f1), (h1 + h2, f2): f0 + x d1 + x (x - h1) d2.
        const double h1 = len / 2, h2 = len - len / 2;
        const double* vc = vb + um;
        for (std::size_t h = 0; h < um; ++h) {
          const double d1 = (vb[h] - va[h]) / h1, d2 = ((vc[h] - vb[h]) / h2 - d1) / (h1 + h2);
          slope[h] = d1 - h1 * d2;
          curv[h] = d2;
        }
        write_quad_(out + static_cast<std::size_t>(start) * um, len, m_, va, slope, curv);
        q += 2;
      } else {  // one voxel: its sample
        for (std::size_t h = 0; h < um; ++h) slope[h] = vb[h] - va[h];
        write_(out + static_cast<std::size_t>(start) * um, len, m_, va, slope);
        q += 1;
      }
    }
    const double* vl = vals_.data() + (count - 1) * um;
    for (std::size_t h = 0; h < um; ++h) out[static_cast<std::size_t>(n - 1) * um + h] = static_cast<float>(vl[h]);
  }

  /// One voxel off the stepping runs: an anchor at a prediction (its certification covers the
  /// voxel, or its exact residual does), else the slow path (then an anchor at the answer).
  /// @param span_end   the last voxel of the row's current run of leaf intervals
  /// @param check_run  voxels left to try by a residual check alone (along a boundary, where
  ///                   anchors certify nothing)
  void visit(int cell, int l, int i, int span_end, const std::array<Vec3, 2>& dom, int& cur, Chain& chain, int& check_run,
             RowLeaf* lb, RowLeaf* le, std::int32_t& owner, float* vp, double* vt) {
    const auto ul = static_cast<std::size_t>(l);
    const Vec3 p = {grid_.origin[0] + (i + 0.5) * grid_.pitch[0], y_[ul], z_};
    auto accept = [&](const Vec3& t) {
      owner = cell;
      if (vt) std::copy(t.begin(), t.end(), vt);
    };
    // Proved outside: a residual check above may have written properties there.
    auto outside = [&] { std::fill(vp, vp + m_, 0.0f); };
    if (check_run > 0) {
      Vec3 tc, rv;
      if (chain.n > 0 && chain.predict(dom, tc) && loc_.check(cell, p, tc, vp, &rv)) {
        accept(tc);
        chain.push_checked(tc, rv, dom);
        --check_run;
        return;
      }
      check_run = 0;
    }
    // Stepping from a fresh anchor at voxel (i + shift, l), reaching back to voxel i.
    auto anchored = [&](int shift = 0) {
      Anchor a;
      const Vec3 pa = {grid_.origin[0] + (i + shift + 0.5) * grid_.pitch[0], y_[ul], z_};
      if (!maker_->make(exp_, i + shift, l, shift ? pa : p, a, shift)) return false;
      anchors_.push_back(a);
      cur = static_cast<int>(anchors_.size()) - 1;
      if (!a.covers(l, i)) return false;
      const Vec3 t = a.at(l, i);
      if (a.step > 0) {
        double v[Expansion::max_props];
        loc_.piece_properties(a.piece, &t, 1, v);
        for (int h = 0; h < m_; ++h) vp[h] = static_cast<float>(v[h]);
      } else {
        const double k = i - a.ia, dl = l - a.la;
        for (std::size_t h = 0; h < static_cast<std::size_t>(m_); ++h) vp[h] = static_cast<float>(a.pb[h] + k * a.pdx[h] + dl * a.pdy[h]);
      }
      accept(t);
      return true;
    };
    Vec3 t;
    bool predicted = false;
    if (cur >= 0) {
      // The next anchor ahead of voxel i by the reach of the last one (an anchor at i itself
      // would spend half its rectangle on voxels already covered), at the last one's prediction;
      // only after an anchor that spanned the whole block, as the shifted one must (after a
      // narrower one, near a boundary, it failed 12 times in 13 on the twisted column).
      const Anchor& last = anchors_[static_cast<std::size_t>(cur)];
      t = last.at(l, i);
      predicted = true;
      const int shift = std::min(last.hi[ul] - last.ia, span_end - i);
      if (shift >= 2 && last.spans_block(nr_) && !beyond(t, dom) && loc_.expand(cell, last.at(l, i + shift), exp_) &&
          anchored(shift))
        return;
    } else if (chain.n > 0) {
      predicted = chain.predict(dom, t);
    } else if (!anchors_.empty()) {
      // A run starts: the nearest anchor of the block (this cell) predicts it, closely enough for
      // an anchor at the prediction (its certificate allows for the offset J0^-1 (p - X(t)) of a
      // point off the voxel's preimage), or else for Newton. (Newton first, and the anchor at its
      // answer, cost 2.4 % more of the sampler's instructions on the twisted column, for the
      // same stack.)
      const double ry = grid_.pitch[1] / grid_.pitch[0];
      std::size_t best = 0;
      double bd = std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < anchors_.size(); ++k) {
        const double d = std::abs(anchors_[k].ia - i) + ry * std::abs(anchors_[k].la - l);
        if (d < bd) bd = d, best = k;
      }
      t = anchors_[best].at(l, i);
      predicted = true;
    }
    cur = -1;
    // Predicted beyond a face of the domain: probably outside, which an exclusion (one of the
    // last few, or a new one from an expansion at the face) may prove without Newton.
    bool expanded = false;
    if (predicted && beyond(t, dom)) {
      const auto leaves = loc_.leaves();
      for (const Exclusion& x : excl_)
        if (x.proves(p, i, lb, le, leaves)) return outside();
      if (loc_.expand(cell, t, exp_)) {
        expanded = true;
        Exclusion& x = excl_[excl_next_];
        excl_next_ = (excl_next_ + 1) % excl_.size();
        if (x.set(loc_, exp_, dom) && x.proves(p, i, lb, le, leaves)) return outside();
      }
    }
    if (predicted && (expanded || loc_.expand(cell, t, exp_))) {
      if (anchored()) {
        // An anchor certifying little more than its own voxel sits on a boundary (a layer
        // through a face between cells, say): residual checks are cheaper for the next voxels.
        const Anchor& a = anchors_[static_cast<std::size_t>(cur)];
        if (a.hi[ul] - i < 2) {
          chain.set_jacobian(exp_.jac);
          chain.push(a.at(l, i));
          check_run = 16;
        }
        return;
      }
      const Vec3 rv{p[0] - exp_.x[0], p[1] - exp_.x[1], p[2] - exp_.x[2]};
      if (rv[0] * rv[0] + rv[1] * rv[1] + rv[2] * rv[2] < tol_ * tol_) {
        // Within the tolerance of the cell but nothing certified: on or near its boundary, as
        // the next voxels probably are too (a layer through a face between cells, say). Cheap
        // residual checks for a while before the next anchor.
        for (int h = 0; h < m_; ++h) vp[h] = static_cast<float>(exp_.props[static_cast<std::size_t>(h)]);
        accept(exp_.t);
        chain.set_jacobian(exp_.jac);
        chain.push_checked(exp_.t, rv, dom);
        check_run = 16;
        return;
      }
      t = exp_.t;
    } else if (predicted) {
      Vec3 rv;
      if (loc_.check(cell, p, t, vp, &rv)) {
        accept(t);
        chain.push_checked(t, rv, dom);
        return;
      }
    }
    // The slow path: Newton, then the leaves.
    const Outcome o = solve_voxel(loc_, grid_, cell, i, p, predicted ? &t : nullptr, chain, t, lb, le, dom, out_->failures[ul]);
    if (o == Outcome::outside) {
      std::fill(vp, vp + m_, 0.0f);  // an evaluation above may have written there
      cur = -1;
      return;
    }
    if (o == Outcome::inside && loc_.expand(cell, chain.uvw[0], exp_) && anchored()) return;
    accept(t);
    loc_.eval_properties(cell, t, vp);
  }

  const Locator& loc_;
  const VoxelGrid& grid_;
  int m_;
  WriteLinear write_;
  WriteQuadratic write_quad_;
  BlockOut* out_ = nullptr;
  double tol_ = 0.0, z_ = 0.0;
  int nr_ = 0;  ///< the block's rows
  std::array<double, block_rows> y_{};
  std::vector<int> cand_;
  std::array<std::vector<RowLeaf>, block_rows> act_;
  std::array<std::size_t, block_rows> pos_{};
  std::vector<Anchor> anchors_;
  std::array<Exclusion, 4> excl_;  ///< the last few made for this cell and block
  std::size_t excl_next_ = 0;
  std::vector<int> cover_;
  AnchorMaker* maker_ = nullptr;
  Expansion exp_;
  std::vector<Vec3> pts_;      ///< fill's sample points
  std::vector<int> offs_;      ///< fill_quadratic's sample offsets in the run
  std::vector<double> vals_;   ///< and their properties
};

}  // namespace

const char* property_blend_name(PropertyBlend b) noexcept { return b == PropertyBlend::shepard ? "shepard" : "encoded"; }

bool property_blend_from_name(std::string_view name, PropertyBlend& out) noexcept {
  if (name == "encoded") out = PropertyBlend::encoded;
  else if (name == "shepard") out = PropertyBlend::shepard;
  else return false;
  return true;
}

LayerSampler::LayerSampler(const vmodel::VModel& model, const VoxelGrid& grid, SamplerOptions opt)
    : grid_(grid), opt_(opt), locator_(model, options_for(grid)) {
  if (grid.count[0] < 1 || grid.count[1] < 1 || grid.count[2] < 1)
    throw Error("voxel grid of " + std::to_string(grid.count[0]) + " x " + std::to_string(grid.count[1]) + " x " +
                std::to_string(grid.count[2]) + " voxels; expected at least one along each axis");
  if (opt_.blend != PropertyBlend::shepard || model.properties.empty()) return;
  shepard_of_.assign(model.cells.size(), -1);
  std::vector<const vmodel::ShepardData*> data;
  for (std::size_t c = 0; c < model.cells.size(); ++c) {
    const auto& sd = model.cells[c].shepard;
    if (!sd) continue;
    std::size_t k = 0;
    while (k < data.size() && !(*data[k] == *sd)) ++k;
    if (k == data.size()) {
      data.push_back(&*sd);
      try {
        shepard_.push_back(std::make_unique<vmodel::ShepardField>(*sd));
      } catch (const Error& e) {
        throw e.within("cell " + model.cells[c].name);
      }
    }
    shepard_of_[c] = static_cast<int>(k);
  }
  if (shepard_.empty()) shepard_of_.clear();
}

void LayerSampler::apply_shepard(int layer, int r0, int nr, std::int32_t* owner, float* props) const {
  const int nx = grid_.count[0], ny = grid_.count[1];
  const auto m = static_cast<std::size_t>(locator_.model().properties.size());
  // Per field a few walks, each the state at its last point: a voxel starts from the walk whose
  // last point is nearest (the previous voxel of the row, or the voxel above it in the previous
  // row, or the other side of a gap), a new walk (cold) when none is within `reach`. All state
  // is local to the block, so a voxel's value depends only on its block.
  constexpr std::size_t slots = 4;
  const double reach = 8.0 * std::max({grid_.pitch[0], grid_.pitch[1], grid_.pitch[2]});
  std::vector<std::array<vmodel::ShepardWalk, slots>> walks(shepard_.size());
  std::vector<std::int64_t> used(shepard_.size() * slots, 0);  // last use of each walk, per field
  std::vector<double> f(m);
  std::int64_t voxels = 0, warm = 0;
  for (int r = 0; r < nr; ++r) {
    const int j = ny - 1 - (r0 + r);  // image row -> grid row (grid.hpp)
    for (int i = 0; i < nx; ++i) {
      const std::size_t v = static_cast<std::size_t>(r) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i);
      const int c = owner[v];
      if (c < 0) continue;
      const int k = shepard_of_[static_cast<std::size_t>(c)];
      if (k < 0) continue;
      const auto p = grid_.centre(i, j, layer);
      auto& ws = walks[static_cast<std::size_t>(k)];
      std::int64_t* age = used.data() + static_cast<std::size_t>(k) * slots;
      std::size_t best = slots, oldest = 0;
      double bd = reach;
      for (std::size_t s = 0; s < slots; ++s) {
        if (age[s] < age[oldest]) oldest = s;
        if (!ws[s].valid) continue;
        const double d = std::hypot(p[0] - ws[s].p[0], p[1] - ws[s].p[1], p[2] - ws[s].p[2]);
        if (d < bd) bd = d, best = s;
      }
      if (best == slots) {  // cold, in the least recently used slot
        best = oldest;
        ws[best].valid = false;
      }
      age[best] = ++voxels;
      shepard_[static_cast<std::size_t>(k)]->eval(p, f.data(), &ws[best]);
      std::transform(f.begin(), f.end(), props + v * m, [](double x) { return static_cast<float>(x); });
    }
  }
  for (const auto& ws : walks)
    for (const auto& w : ws) warm += w.warm;
  shepard_voxels_ += voxels;
  shepard_warm_ += warm;
}

void LayerSampler::sample(int layer, int row0, int rows, RowBand& out) const {
  const int nx = grid_.count[0], ny = grid_.count[1], nz = grid_.count[2];
  if (layer < 0 || layer >= nz)
    throw Error("layer " + std::to_string(layer) + "; expected 0 <= layer < " + std::to_string(nz));
  if (row0 < 0 || rows < 0 || row0 > ny || rows > ny - row0)
    throw Error("image rows [" + std::to_string(row0) + ", " + std::to_string(static_cast<long long>(row0) + rows) +
                "); expected a range within [0, " + std::to_string(ny) + ")");
  const int m = static_cast<int>(locator_.model().properties.size());
  const auto unx = static_cast<std::size_t>(nx), um = static_cast<std::size_t>(m);
  out.layer = layer;
  out.row0 = row0;
  out.rows = rows;
  out.nx = nx;
  out.nprops = m;
  out.cell.resize(static_cast<std::size_t>(rows) * unx);
  out.props.resize(static_cast<std::size_t>(rows) * unx * um);
  if (opt_.keep_uvw)
    out.uvw.resize(static_cast<std::size_t>(rows) * unx * 3);
  else
    out.uvw.clear();
  out.failures = 0;
  out.inverted = 0;
  if (rows == 0) return;
  BlockSampler bs(locator_, grid_);
  std::vector<std::int32_t> owner;
  std::vector<float> props;
  std::vector<double> uvw;
  for (int b = row0 / block_rows; b * block_rows < row0 + rows; ++b) {
    const int r0 = b * block_rows, nr = std::min(block_rows, ny - r0);
    const int from = std::max(r0, row0), to = std::min(r0 + nr, row0 + rows);
    BlockOut blk;
    blk.zero_props = opt_.zero_void_props;
    const bool direct = from == r0 && to == r0 + nr;  // the whole block is in the band
    if (direct) {
      const auto dst = static_cast<std::size_t>(r0 - row0);
      blk.owner = out.cell.data() + dst * unx;
      blk.props = out.props.data() + dst * unx * um;
      blk.uvw = opt_.keep_uvw ? out.uvw.data() + dst * unx * 3 : nullptr;
    } else {
      owner.resize(static_cast<std::size_t>(nr) * unx);
      props.resize(static_cast<std::size_t>(nr) * unx * um);
      if (opt_.keep_uvw) uvw.resize(static_cast<std::size_t>(nr) * unx * 3);
      blk.owner = owner.data();
      blk.props = props.data();
      blk.uvw = opt_.keep_uvw ? uvw.data() : nullptr;
    }
    bs.run(layer, r0, nr, blk);
    if (!shepard_.empty()) apply_shepard(layer, r0, nr, blk.owner, blk.props);
    for (int r = from; r < to; ++r) {
      const auto src = static_cast<std::size_t>(r - r0), dst = static_cast<std::size_t>(r - row0);
      if (!direct) {
        std::copy_n(owner.data() + src * unx, unx, out.cell.data() + dst * unx);
        std::copy_n(props.data() + src * unx * um, unx * um, out.props.data() + dst * unx * um);
        if (opt_.keep_uvw) std::copy_n(uvw.data() + src * unx * 3, unx * 3, out.uvw.data() + dst * unx * 3);
      }
      out.failures += blk.failures[src];
      out.inverted += blk.inverted[src];
    }
  }
  // Cells of Booleans: the first cell whose trivariate holds a voxel took it above; the trimming
  // pass gives it to the cell whose conditions admit it (or to none) and blends properties.
  if (locator_.has_trims()) apply_trimming(locator_, grid_, out);
}

}  // namespace trivox::slice
