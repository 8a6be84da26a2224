// A cell's Bezier pieces (pieces.hpp): the cell's breakpoints and Bezier form, and per piece its
// kernels, its net (geometry, homogeneous when rational, then the properties times the weight)
// written into the locator's pool, its hodograph bound and its nearly affine leaves (leaves.hpp).
// Cost per piece: O(o^3 (3 + m)) for the net plus the leaves' subdivision.
#include "pieces.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

#include "leaves.hpp"
#include "piece_kernels.hpp"
#include "step_bounds.hpp"

namespace trivox::slice::detail {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

using Data = Locator::Data;

}  // namespace

CellPieces cell_pieces(const vmodel::VCell& vc) {
  const auto& s = vc.volume;
  CellPieces cp;
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    if (s.knots(d).order() > max_order)
      throw Error("cell " + vc.name + ": order " + std::to_string(s.knots(d).order()) + " in direction " + "uvw"[d] +
                  "; expected at most " + std::to_string(max_order) + " for point location");
    for (const auto& br : s.knots(d).breakpoints()) cp.cell.breaks[dd].push_back(br.value);
    cp.cell.spans[dd] = static_cast<int>(cp.cell.breaks[dd].size()) - 1;
    cp.cell.lo[dd] = s.domain(d)[0];
    cp.cell.hi[dd] = s.domain(d)[1];
  }
  cp.bezier = spline::to_bezier_form(s);
  for (std::size_t d = 0; d < 3; ++d) {
    for (const auto& br : cp.bezier.knots(static_cast<int>(d)).breakpoints()) cp.breaks[d].push_back(br.value);
    cp.spans[d] = static_cast<int>(cp.breaks[d].size()) - 1;
  }
  cp.H = s.rational() ? 4 : 3;
  return cp;
}

Data::Piece build_piece(const PieceRef& bp, int H, int cell_index, int piece_index, std::size_t net, int m,
                        const LocatorOptions& opt, double* pool, std::vector<LocatorLeaf>& leaves) {
  Data::Piece pc;
  pc.cell = cell_index;
  pc.order = bp.order;
  pc.H = H;
  pc.nc = H + m;
  pc.net = net;
  pc.k = H == 3 ? pick_kernels<3>(pc.order, pc.nc) : pick_kernels<4>(pc.order, pc.nc);
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    pc.lo[dd] = bp.dom[dd][0];
    pc.len[dd] = bp.dom[dd][1] - bp.dom[dd][0];
    pc.inv_len[dd] = 1.0 / pc.len[dd];
  }
  const int n = bp.size();
  std::vector<double> g(static_cast<std::size_t>(n * H));
  double* all = pool + net;
  for (int i = 0; i < n; ++i) {
    const int row = bp.row(i);
    const auto q = bp.b->point(row);
    const double w = H == 4 ? bp.b->weights()[static_cast<std::size_t>(row)] : 1.0;
    for (int h = 0; h < 3; ++h) g[static_cast<std::size_t>(i * H + h)] = w * q[static_cast<std::size_t>(h)];
    if (H == 4) g[static_cast<std::size_t>(i * H + 3)] = w;
    for (int h = 0; h < H; ++h) all[i * pc.nc + h] = g[static_cast<std::size_t>(i * H + h)];
    for (int h = 0; h < m; ++h) all[i * pc.nc + H + h] = w * q[static_cast<std::size_t>(3 + h)];
  }
  pc.lipschitz = H == 4 ? Vec3{inf, inf, inf} : hodograph_bounds(g.data(), pc, H);
  std::vector<LeafBox> lv;
  const double min_diag = 100.0 * opt.tolerance;
  build_leaves(g.data(), pc.order, H, min_diag, opt.leaf_deviation, opt.fine_leaf_deviation, opt.fine_leaf_factor, opt.max_leaves_per_piece, lv);
  leaves.reserve(lv.size());
  for (const auto& [lo, hi, fl] : lv) {
    LocatorLeaf leaf;
    leaf.cell = cell_index;
    leaf.piece = piece_index;
    for (int d = 0; d < 3; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      // The piece's own end knots at the ends, so leaves tile the domain without gaps.
      leaf.lo[dd] = lo[dd] <= 0.0 ? bp.dom[static_cast<std::size_t>(d)][0] : pc.lo[dd] + lo[dd] * pc.len[dd];
      leaf.hi[dd] = hi[dd] >= 1.0 ? bp.dom[static_cast<std::size_t>(d)][1] : pc.lo[dd] + hi[dd] * pc.len[dd];
    }
    leaf.box_lo = fl.box_lo;
    leaf.box_hi = fl.box_hi;
    leaf.frame_origin = fl.origin;
    leaf.frame = fl.frame;
    leaf.frame_lo = fl.frame_lo;
    leaf.frame_hi = fl.frame_hi;
    for (std::size_t k = 0; k < 3; ++k)
      leaf.frame_scale[k] = std::sqrt(fl.frame[k][0] * fl.frame[k][0] + fl.frame[k][1] * fl.frame[k][1] + fl.frame[k][2] * fl.frame[k][2]);
    leaves.push_back(leaf);
  }
  return pc;
}

}  // namespace trivox::slice::detail
