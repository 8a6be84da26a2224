/// @file src/slice/anchor.hpp
/// @brief (private to src/slice) Certified first-order stepping: an anchor (one expansion of a
/// cell at a voxel, Locator::expand) and the rectangle of voxels of its block around it whose
/// parameters and properties follow from its linear model with a proof (the Newton-Kantorovich
/// theorem in Deuflhard's affine-covariant form, Deuflhard 2004), built by AnchorMaker
/// (anchor.cpp). Anchor's inline members are what the block sampler asks per voxel.
#pragma once
#include <array>

#include "trivox/slice/grid.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/sampler.hpp"

namespace trivox::slice::detail {

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
  bool make(const Expansion& e, int i, int l, const Vec3& p, Anchor& a, int shift = 0);

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
  int sample_step(const Errors& err, bool& quad) const;

  /// The largest k for which the rectangle of columns -kn .. k (kn < 0: -k .. k) and rows -ln ..
  /// lp keeps its linear-model parameters inside the bounds' box grown by the certificate's
  /// reach out of it (tol / slope per direction; at most nx, at least 0): no larger k is
  /// certified, and where the box binds (a cell's face, the piece's edge) it is the anchor's
  /// width, found without a search (room_lo_, room_hi_, inv_dx_ from make()).
  int box_cap(int kn, int ln, int lp) const;

  /// The columns k0..k1 (relative to the anchor's column i, within the row and within -reach ..
  /// reach) of the block row dr rows from the anchor's where its linear-model parameters stay
  /// inside the bounds' box grown by the certificate's reach out of it (box_cap's terms);
  /// false when there are none. A first guess for certified(): the certificate decides.
  bool row_columns(int dr, int reach, int i, int& k0, int& k1) const;

  /// The largest k in [0, cap] with ok(k) (ok is monotone: true up to some k), or -1: a little
  /// more than `guess` first (neighbouring anchors are alike), and then cap itself when the last
  /// anchor of its kind reached its cap (`cap_first`: the box binds there); else doubling and
  /// bisection.
  template <class F>
  int largest(F&& ok, int guess, int cap, bool cap_first) const;

  /// Whether every voxel (ia + k, la + l), -kn <= k <= kp, -ln <= l <= lp, is certified.
  /// Newton-Kantorovich for G(t) = J0^-1 (X(t) - p) from the voxel's linear-model parameters t
  /// (d = t - t0, |d_j| <= a_j): |G(t)| <= eta = 1/2 sum w_de a_d a_e (Taylor); G' = J0^-1 J moves
  /// by at most theta = omega |d|_1 <= 1/2 from the identity, so |G'(t)^-1| <= beta = 1/(1 - theta)
  /// (Neumann series); G' is Lipschitz with L = sqrt3 omega in the 2-norm; then Kantorovich's
  /// h = beta^2 L eta <= 1/2 puts the root within r = (1 - sqrt(1 - 2h)) / (beta L)
  /// = 2 beta eta / (1 + sqrt(1 - 2h)) of t (about eta when h is small, 4 eta at worst).
  /// The bounds are those of the anchor's piece (Locator::step_bounds); leaving it is handled
  /// below.
  bool certified(int kn, int kp, int ln, int lp) const;

  /// 1: certified; 0: not; -1: the certificate leaves the box (retry with a growth factor G).
  int certified_with(int kn, int kp, int ln, int lp, double G, const Norm& nm) const;

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

}  // namespace trivox::slice::detail
