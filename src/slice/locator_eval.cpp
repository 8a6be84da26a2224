// Evaluating a cell at given parameters (locator.hpp): the point and its properties in one pass
// over the piece's net (eval, eval_properties, and check, which compares the point with a voxel
// centre), every coordinate with its first partials (expand: the sampler's anchors), and a
// piece's properties at many parameters, eight per vector pass (piece_properties: the sampler's
// samples along a run). Cost: O(o^3 nc) per point, nc = 3 + m coordinates (4 + m rational).
#include "trivox/slice/locator.hpp"

#include <algorithm>
#include <cstddef>
#include <vector>

#include "locator_data.hpp"

namespace trivox::slice {

namespace {

/// Scratch for Data::eval_all: on the stack for up to 64 coordinates.
class Scratch {
public:
  explicit Scratch(int n) {
    if (n > 64) heap_.resize(static_cast<std::size_t>(n));
  }
  double* data() noexcept { return heap_.empty() ? stack_ : heap_.data(); }

private:
  double stack_[64];
  std::vector<double> heap_;
};

}  // namespace

void Locator::eval(int cell, const Vec3& uvw, double* xyz, double* props) const {
  const auto& pc = data_->piece_at(cell, uvw);
  Scratch buf(pc.nc);
  data_->eval_all(pc, uvw, buf.data(), xyz, props);
}

void Locator::eval_properties(int cell, const Vec3& uvw, float* props) const {
  const auto& pc = data_->piece_at(cell, uvw);
  Scratch buf(pc.nc);
  double x[3];
  data_->eval_all(pc, uvw, buf.data(), x, props);
}

bool Locator::check(int cell, const Vec3& p, const Vec3& uvw, float* props, Vec3* residual) const {
  const Data& D = *data_;
  const auto& pc = D.piece_at(cell, uvw);
  double x[3];
  if (pc.nc <= 64) {
    double buf[64];
    D.eval_all(pc, uvw, buf, x, props);
  } else {
    std::vector<double> buf(static_cast<std::size_t>(pc.nc));
    D.eval_all(pc, uvw, buf.data(), x, props);
  }
  const Vec3 r{p[0] - x[0], p[1] - x[1], p[2] - x[2]};
  if (residual) *residual = r;
  return r[0] * r[0] + r[1] * r[1] + r[2] * r[2] < opt_.tolerance * opt_.tolerance;
}

bool Locator::expand(int cell, const Vec3& t, Expansion& out) const {
  const Data& D = *data_;
  const auto& pc = D.piece_at(cell, t);
  if (!pc.k.all_first || D.m > Expansion::max_props) return false;
  const auto dom = domain(cell);
  Vec3 tc;
  for (std::size_t d = 0; d < 3; ++d) tc[d] = std::clamp(t[d], dom[0][d], dom[1][d]);
  double s[3], f[4 * 10];
  Data::local(pc, tc, s);
  pc.k.all_first(D.pool.data() + pc.net, pc.nc, pc.order, s, f);
  const int nc = pc.nc;
  out.piece = static_cast<int>(&pc - D.pieces.data());
  out.t = tc;
  for (std::size_t h = 0; h < 3; ++h) {
    out.x[h] = f[h];
    for (std::size_t d = 0; d < 3; ++d) out.jac[d][h] = f[static_cast<std::size_t>(nc) * (d + 1) + h] * pc.inv_len[d];
  }
  for (int h = 0; h < D.m; ++h) {
    const auto uh = static_cast<std::size_t>(h);
    out.props[uh] = f[3 + uh];
    for (std::size_t d = 0; d < 3; ++d) out.grad[uh][d] = f[static_cast<std::size_t>(nc) * (d + 1) + 3 + uh] * pc.inv_len[d];
  }
  return true;
}

void Locator::piece_properties(int piece, const Vec3* t, int n, double* out) const {
  const Data& D = *data_;
  const auto& pc = D.pieces[static_cast<std::size_t>(piece)];
  if (D.m == 0 || n <= 0) return;
  if (pc.H != 3) {  // rational: not one polynomial; each point evaluated (clamped) instead
    Scratch buf(pc.nc);
    double x[3];
    for (int j = 0; j < n; ++j) D.eval_all(pc, t[j], buf.data(), x, out + static_cast<std::size_t>(j) * static_cast<std::size_t>(D.m));
    return;
  }
  const detail::Props8 kernel = pc.k.props, kernel4 = pc.k.props4;
  const double* net = D.pool.data() + pc.net;
  const auto um = static_cast<std::size_t>(D.m);
  double s[3][8], buf[8 * Expansion::max_props];
  std::vector<double> heap;
  double* vals = buf;
  if (D.m > Expansion::max_props) {
    heap.resize(8 * um);
    vals = heap.data();
  }
  for (int j0 = 0; j0 < n; j0 += 8) {
    const int k = std::min(8, n - j0);
    for (int l = 0; l < 8; ++l) {
      const Vec3& p = t[j0 + std::min(l, k - 1)];  // spare lanes repeat the last point
      for (std::size_t d = 0; d < 3; ++d) s[d][l] = (p[d] - pc.lo[d]) * pc.inv_len[d];
    }
    (k <= 4 && kernel4 ? kernel4 : kernel)(net, pc.nc, pc.H, D.m, pc.order, s, vals);  // a short chunk: half the lanes
    std::copy_n(vals, static_cast<std::size_t>(k) * um, out + static_cast<std::size_t>(j0) * um);
  }
}

}  // namespace trivox::slice
