// Bounds on a polynomial Bezier piece's derivatives (step_bounds.hpp, StepBounds in locator.hpp):
// every partial of a Bezier polynomial is a Bezier polynomial whose control points are scaled
// differences of the net's, so the largest of those bounds it everywhere in the piece (convex
// hull property). First partials (the hodograph), second partials of the geometry (Euclidean
// and per coordinate) and of the properties, third partials of the properties: what the
// sampler's certified stepping needs (sampler.hpp). Cost: O(o^3 nc) per order of derivative and
// pair or triple of directions, once per piece, on first use.
#include "step_bounds.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "mat3.hpp"

namespace trivox::slice {

namespace detail {

namespace {

using Data = Locator::Data;

/// Bounds on the second partials of a polynomial piece (net: nc = 3 + m coordinates per point):
/// d^2/dt_d dt_e is a Bezier polynomial with control points (scaled) second differences of the
/// net, so their largest norm bounds it (convex hull property). The largest squared norm is
/// kept and its root taken once (the root is monotonic: the same bound).
StepBounds second_derivative_bounds(const double* net, const Data::Piece& pc) {
  StepBounds b;
  b.valid = true;
  for (std::size_t d = 0; d < 3; ++d) {
    b.lo[d] = pc.lo[d];
    b.hi[d] = pc.lo[d] + pc.len[d];
  }
  const auto& o = pc.order;
  const int nc = pc.nc;
  const int stride[3] = {1, o[0], o[0] * o[1]};
  for (int d = 0; d < 3; ++d)
    for (int e = d; e < 3; ++e) {
      const auto ud = static_cast<std::size_t>(d), ue = static_cast<std::size_t>(e);
      const double factor = d == e ? (o[ud] - 1.0) * (o[ud] - 2.0) * pc.inv_len[ud] * pc.inv_len[ud]
                                   : (o[ud] - 1.0) * (o[ue] - 1.0) * pc.inv_len[ud] * pc.inv_len[ue];
      double bx2 = 0.0, bp = 0.0, bv[3] = {0.0, 0.0, 0.0};
      // The second difference at point i, over the points where it exists: d == e: P_i -
      // 2 P_i+s + P_i+2s; d != e: P_i - P_i+sd - P_i+se + P_i+sd+se (in this order; only their
      // magnitudes are used).
      std::array<int, 3> lim = o;
      std::ptrdiff_t o1, o2, o3 = 0;
      if (d == e) {
        lim[ud] -= 2;
        o1 = static_cast<std::ptrdiff_t>(stride[d]) * nc;
        o2 = 2 * o1;
      } else {
        lim[ud] -= 1;
        lim[ue] -= 1;
        o1 = static_cast<std::ptrdiff_t>(stride[d]) * nc;
        o2 = static_cast<std::ptrdiff_t>(stride[e]) * nc;
        o3 = o1 + o2;
      }
      if (factor != 0.0)
        for (int c = 0; c < lim[2]; ++c)
          for (int bb = 0; bb < lim[1]; ++bb) {
            const double* p = net + static_cast<std::ptrdiff_t>(o[0] * (bb + o[1] * c)) * nc;
            for (int a = 0; a < lim[0]; ++a, p += nc) {
              double v[3];
              if (d == e)
                for (int h = 0; h < 3; ++h) v[h] = p[h] + -2.0 * p[o1 + h] + p[o2 + h];
              else
                for (int h = 0; h < 3; ++h) v[h] = p[h] - p[o1 + h] - p[o2 + h] + p[o3 + h];
              double x2 = 0.0;
              for (int h = 0; h < 3; ++h) {
                x2 += v[h] * v[h];
                bv[h] = std::max(bv[h], std::abs(v[h]));
              }
              bx2 = std::max(bx2, x2);
              if (d == e)
                for (int h = 3; h < nc; ++h) bp = std::max(bp, std::abs(p[h] + -2.0 * p[o1 + h] + p[o2 + h]));
              else
                for (int h = 3; h < nc; ++h) bp = std::max(bp, std::abs(p[h] - p[o1 + h] - p[o2 + h] + p[o3 + h]));
            }
          }
      const double bx = std::sqrt(bx2);
      // Rounding in the differences is far below these bounds' slack; 1e-12 relative covers it.
      b.b2[ud][ue] = b.b2[ue][ud] = bx * factor * (1.0 + 1e-12);
      for (std::size_t k = 0; k < 3; ++k) b.b2v[ud][ue][k] = b.b2v[ue][ud][k] = bv[k] * factor * (1.0 + 1e-12);
      b.p2[ud][ue] = b.p2[ue][ud] = bp * factor * (1.0 + 1e-12);
    }
  for (std::size_t d = 0; d < 3; ++d)
    b.lip = std::max(b.lip, std::sqrt(b.b2[d][0] * b.b2[d][0] + b.b2[d][1] * b.b2[d][1] + b.b2[d][2] * b.b2[d][2]));
  return b;
}

/// Bounds on the properties' third partials (coordinates 3 .. nc - 1 of a polynomial net), from
/// the convex hull of their third differences: for c_d derivatives along each direction d
/// (c_u + c_v + c_w = 3) the partial is a Bezier polynomial of degrees n_d - c_d whose
/// coefficients are the mixed differences prod_d Delta_d^{c_d} of the control points times
/// prod_d n_d! / (n_d - c_d)! / len_d^{c_d} (n_d = order_d - 1), so their largest magnitude
/// bounds it (zero where some c_d exceeds n_d).
void third_partial_bounds(const double* net, const Data::Piece& pc, StepBounds& b) {
  const auto& o = pc.order;
  const int nc = pc.nc;
  const std::ptrdiff_t stride[3] = {nc, static_cast<std::ptrdiff_t>(o[0]) * nc, static_cast<std::ptrdiff_t>(o[0] * o[1]) * nc};
  for (int d = 0; d < 3; ++d)
    for (int e = d; e < 3; ++e)
      for (int f = e; f < 3; ++f) {
        int c[3] = {0, 0, 0};
        ++c[d], ++c[e], ++c[f];
        double factor = 1.0;
        std::array<int, 3> lim = o;
        for (std::size_t k = 0; k < 3; ++k) {
          const int n = o[k] - 1;
          for (int j = 0; j < c[k]; ++j) factor *= (n - j) * pc.inv_len[k];
          lim[k] -= c[k];
        }
        double bp = 0.0;
        if (factor != 0.0 && lim[0] > 0 && lim[1] > 0 && lim[2] > 0) {
          // The offsets and signs of the mixed difference: prod_k sum_j (-1)^(c_k - j) C(c_k, j) at +j along k.
          std::vector<std::pair<std::ptrdiff_t, double>> terms{{0, 1.0}};
          for (std::size_t k = 0; k < 3; ++k)
            for (int r = 0; r < c[k]; ++r) {  // one more first difference along k: x(+1) - x
              std::vector<std::pair<std::ptrdiff_t, double>> next;
              for (const auto& [off, w] : terms) {
                next.push_back({off + stride[k], w});
                next.push_back({off, -w});
              }
              terms = std::move(next);
            }
          for (int cw = 0; cw < lim[2]; ++cw)
            for (int cv = 0; cv < lim[1]; ++cv)
              for (int cu = 0; cu < lim[0]; ++cu) {
                const double* p = net + cu * stride[0] + cv * stride[1] + cw * stride[2];
                for (int h = 3; h < nc; ++h) {
                  double v = 0.0;
                  for (const auto& [off, w] : terms) v += w * p[off + h];
                  bp = std::max(bp, std::abs(v));
                }
              }
        }
        const double bound = bp * std::abs(factor) * (1.0 + 1e-12);
        const int idx[3] = {d, e, f};
        // Every ordering of (d, e, f).
        for (int x = 0; x < 3; ++x)
          for (int y = 0; y < 3; ++y)
            for (int z = 0; z < 3; ++z)
              if (x != y && y != z && x != z)
                b.p3[static_cast<std::size_t>(idx[x])][static_cast<std::size_t>(idx[y])][static_cast<std::size_t>(idx[z])] = bound;
      }
}

}  // namespace

Vec3 hodograph_bounds(const double* net, const Data::Piece& pc, int stride) {
  Vec3 out{};
  const auto& o = pc.order;
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    if (o[dd] < 2) continue;
    const std::ptrdiff_t step = static_cast<std::ptrdiff_t>(d == 0 ? 1 : d == 1 ? o[0] : o[0] * o[1]) * stride;
    std::array<int, 3> lim = o;
    lim[dd] -= 1;
    double mx2 = 0.0;  // the largest squared norm (one root at the end: the same maximum)
    for (int c = 0; c < lim[2]; ++c)
      for (int b = 0; b < lim[1]; ++b) {
        const double* p = net + static_cast<std::ptrdiff_t>(o[0] * (b + o[1] * c)) * stride;
        for (int a = 0; a < lim[0]; ++a, p += stride) {
          const double diff[3] = {p[step] - p[0], p[step + 1] - p[1], p[step + 2] - p[2]};
          mx2 = std::max(mx2, dot3(diff, diff));
        }
      }
    // The same 1e-12 relative slack as the second-derivative bounds, for rounding.
    out[dd] = (o[dd] - 1) * std::sqrt(mx2) * pc.inv_len[dd] * (1.0 + 1e-12);
  }
  return out;
}

namespace {

/// Everything the sampler's certificates need of a polynomial piece (or part of one: `pc` gives
/// the parameter box of `net`, nc = 3 + m coordinates per point).
StepBounds step_bounds_of(const double* net, const Data::Piece& pc) {
  StepBounds b = second_derivative_bounds(net, pc);
  third_partial_bounds(net, pc, b);
  b.slope = hodograph_bounds(net, pc, pc.nc);
  for (std::size_t d = 0; d < 3; ++d) b.degree[d] = pc.order[d] - 1;
  return b;
}

}  // namespace

}  // namespace detail

const StepBounds& Locator::step_bounds(int piece) const noexcept {
  const auto& pc = data_->pieces[static_cast<std::size_t>(piece)];
  if (!pc.k.all_first) return pc.bounds;  // not valid
  data_->bounds_once[static_cast<std::size_t>(piece)]([&] { pc.bounds = detail::step_bounds_of(data_->pool.data() + pc.net, pc); });
  return pc.bounds;
}

}  // namespace trivox::slice
