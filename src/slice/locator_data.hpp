/// @file src/slice/locator_data.hpp
/// @brief (private to src/slice) The locator's implementation data (Locator::Data): per cell its
/// breakpoints and pieces, per Bezier piece its kernels, its net in one shared pool and its
/// bounds, the leaves and the BVH over their boxes, and the trimmed cells' conditions; with the
/// inline evaluations of a piece that Newton and the sampler call per iteration and per voxel.
/// Shared by the locator's files (locator.cpp, pieces.cpp, bvh.cpp, newton.cpp, step_bounds.cpp,
/// locator_eval.cpp, membership.cpp).
#pragma once
#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

#include "trivox/geom/closest_point.hpp"
#include "trivox/slice/locator.hpp"

#include "piece_kernels.hpp"

namespace trivox::slice {

namespace detail {
/// A flag for work done once, on first use, by whichever thread comes first: std::call_once
/// behind an acquire load, since libstdc++'s call_once sets up thread-local state on every call,
/// even long after the work is done (the sampler asks for bounds at every anchor).
struct Once {
  std::atomic<bool> done{false};
  std::once_flag flag;

  template <class F>
  void operator()(F&& f) {
    if (done.load(std::memory_order_acquire)) return;
    std::call_once(flag, [&] {
      f();
      done.store(true, std::memory_order_release);
    });
  }
};
}  // namespace detail

struct Locator::Data {
  struct Piece {
    int cell = 0;
    std::array<int, 3> order{};
    Vec3 lo{}, len{}, inv_len{};  ///< global parameter box of the piece
    int H = 3;                    ///< geometry coordinates: 3 polynomial, 4 rational (wx wy wz w)
    int nc = 3;                   ///< coordinates per control point: H + properties (times w)
    detail::Kernels k;
    std::size_t net = 0;  ///< offset into the pool
    Vec3 lipschitz{};     ///< bounds on |dX/dt_d| (global parameters); inf if rational
    /// Second-derivative bounds (polynomial pieces with all_first): computed on first use,
    /// under bounds_once (a job touches only some pieces; the values do not depend on which
    /// thread computes them).
    mutable StepBounds bounds;
  };
  struct Cell {
    std::array<std::vector<double>, 3> breaks;  ///< distinct knots inside the domain
    std::array<int, 3> spans{};
    int first_piece = 0;
    Vec3 lo{}, hi{};
  };
  struct Node {
    Vec3 lo{}, hi{};
    int left = -1, right = -1;  ///< children, or -1 for a leaf node
    int first = 0, count = 0;   ///< range of items for a leaf node
  };

  /// A trimmed cell's conditions (VCell::within, VCell::without), each a locator over its own
  /// cells; null for plain cells.
  struct Sub {
    vmodel::VModel model;
    std::unique_ptr<Locator> loc;
  };
  struct Trim {
    std::vector<std::unique_ptr<Sub>> within, without;
    vmodel::BlendRule blend = vmodel::BlendRule::first;
    double power = 1.0;
    /// BlendRule::distance: per blended value, its input's boundary (empty otherwise).
    std::vector<std::vector<geom::SurfaceDistance>> boundaries;
  };

  int m = 0;  ///< properties per point
  std::vector<std::unique_ptr<Trim>> trims;  ///< per cell
  bool any_trim = false;
  std::vector<Cell> cells;
  std::vector<Piece> pieces;
  std::unique_ptr<detail::Once[]> bounds_once;  ///< one per piece: its bounds computed
  std::vector<double> pool;  ///< every piece's net, control point after control point
  std::vector<LocatorLeaf> leaves;
  std::vector<Node> nodes;
  std::vector<int> items;  ///< leaf indices in BVH order

  const Piece& piece_at(int cell, const Vec3& t) const noexcept {
    const Cell& c = cells[static_cast<std::size_t>(cell)];
    int idx[3];
    for (int d = 0; d < 3; ++d) {
      const auto& br = c.breaks[static_cast<std::size_t>(d)];
      const int n = c.spans[static_cast<std::size_t>(d)];
      if (n == 1) {
        idx[d] = 0;
        continue;
      }
      const auto it = std::upper_bound(br.begin() + 1, br.begin() + n, t[static_cast<std::size_t>(d)]);
      idx[d] = static_cast<int>(it - br.begin()) - 1;
    }
    return pieces[static_cast<std::size_t>(c.first_piece + idx[0] + c.spans[0] * (idx[1] + c.spans[1] * idx[2]))];
  }

  static void local(const Piece& pc, const Vec3& t, double* s) noexcept {
    for (std::size_t d = 0; d < 3; ++d) s[d] = std::clamp((t[d] - pc.lo[d]) * pc.inv_len[d], 0.0, 1.0);
  }

  /// X (3) and, with J, the Jacobian columns J[d] = dX/dt_d (global parameters) at t.
  void eval_geom(const Piece& pc, const Vec3& t, double* X, double (*J)[3]) const noexcept {
    double s[3], f[16];
    local(pc, t, s);
    (J ? pc.k.first : pc.k.value)(pool.data() + pc.net, pc.nc, pc.order, s, f);
    if (pc.H == 3) {
      for (int h = 0; h < 3; ++h) X[h] = f[h];
      if (J)
        for (std::size_t d = 0; d < 3; ++d)
          for (std::size_t h = 0; h < 3; ++h) J[d][h] = f[3 * (d + 1) + h] * pc.inv_len[d];
      return;
    }
    const double iw = 1.0 / f[3];
    for (int h = 0; h < 3; ++h) X[h] = f[h] * iw;
    if (J)
      for (std::size_t d = 0; d < 3; ++d) {
        const double* fd = f + 4 * (d + 1);
        for (std::size_t h = 0; h < 3; ++h) J[d][h] = (fd[h] - X[h] * fd[3]) * iw * pc.inv_len[d];
      }
  }

  /// xyz (3) and the m properties of piece pc at t, in one pass over its net.
  /// @param buf  pc.nc values of scratch
  template <class T>
  void eval_all(const Piece& pc, const Vec3& t, double* buf, double* X, T* props) const noexcept {
    double s[3];
    local(pc, t, s);
    pc.k.all(pool.data() + pc.net, pc.nc, pc.order, s, buf);
    const double iw = pc.H == 4 ? 1.0 / buf[3] : 1.0;
    for (int h = 0; h < 3; ++h) X[h] = buf[h] * iw;
    if (props)
      for (int h = 0; h < m; ++h) props[h] = static_cast<T>(buf[pc.H + h] * iw);
  }
};

}  // namespace trivox::slice
