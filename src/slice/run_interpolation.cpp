// The properties of a certified run (block_sampler.hpp, Anchor in anchor.hpp): the anchor's
// first-order model, or the piece's own polynomial evaluated exactly every `step` voxels
// (Locator::piece_properties, eight points per vector pass) and interpolated between the
// samples, linearly, or quadratically through the ends and the middle of segments of at most
// 2 step voxels (Newton's divided differences); the run writers (run_writers.hpp) step the
// values. Cost: O(o^3 m) per sample plus O(m) per voxel.
#include <algorithm>
#include <cstddef>

#include "block_sampler.hpp"

namespace trivox::slice::detail {

void BlockSampler::fill(const Anchor& a, int l, int i0, int i1, float* props, double* uvw) {
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

void BlockSampler::fill_quadratic(const Anchor& a, int l, int i0, int n, float* out) {
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

}  // namespace trivox::slice::detail
