// Sampling one block of image rows (block_sampler.hpp): the leaves that meet the block and each
// row's voxel intervals, then per cell (in file order) its rows from the middle outwards, each
// from left to right: certified runs from the anchors that cover them, claimed eight voxels at
// a time, and every other voxel visited once: a residual check, a new anchor at a prediction,
// a proof of exclusion beyond a face, or the slow path. Cost: a few multiply-adds per certified
// voxel, an expansion per anchor, a pass over the block's leaves per row.
#include "block_sampler.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace trivox::slice::detail {

namespace {

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

/// Whether t lies outside the box dom.
bool beyond(const Vec3& t, const std::array<Vec3, 2>& dom) {
  for (std::size_t d = 0; d < 3; ++d)
    if (t[d] < dom[0][d] || t[d] > dom[1][d]) return true;
  return false;
}

}  // namespace

void BlockSampler::run(int layer, int r0, int nr, BlockOut& out) {
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

void BlockSampler::walk_row(int cell, int l) {
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

int BlockSampler::claim_run(std::int32_t* owner, int i, int iend, int cell) {
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

void BlockSampler::visit(int cell, int l, int i, int span_end, const std::array<Vec3, 2>& dom, int& cur, Chain& chain, int& check_run,
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

}  // namespace trivox::slice::detail
