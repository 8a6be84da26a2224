// The point locator (locator.hpp; the slicing of Masalha et al. 2021, Sec. 8): built from a
// model cell after cell in batches and piece after piece in parallel (pieces.cpp, leaves.cpp),
// then the BVH over the leaves (bvh.cpp) and the trimmed cells' own locators (membership.cpp);
// locate() asks the BVH for the leaves near a point and inverts it in each (newton.cpp), from
// the hint first. Also the model's bounding box. Evaluation at given parameters is in
// locator_eval.cpp, the pieces' derivative bounds in step_bounds.cpp. Cost: construction
// O(pieces x leaves per piece x o^3 x dim), parallel over pieces; a query, a BVH descent plus a
// few Newton iterations of O(o^3) per candidate leaf.
#include "trivox/slice/locator.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/spline/extract.hpp"

#include "bvh.hpp"
#include "locator_data.hpp"
#include "membership.hpp"
#include "pieces.hpp"

namespace trivox::slice {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

using Data = Locator::Data;

}  // namespace

Locator::Locator(const vmodel::VModel& model, LocatorOptions opt) : model_(&model), opt_(opt), data_(std::make_unique<Data>()) {
  if (!(std::isfinite(opt.tolerance) && opt.tolerance > 0.0))
    throw Error("locator tolerance " + std::to_string(opt.tolerance) + "; expected a positive finite length");
  if (opt_.max_newton < 1) opt_.max_newton = 1;
  Data& D = *data_;
  D.m = static_cast<int>(model.properties.size());
  const int nc = static_cast<int>(model.cells.size());
  for (int c = 0; c < nc; ++c)
    if (model.cells[static_cast<std::size_t>(c)].volume.dim() != model.dim())
      throw Error("cell " + model.cells[static_cast<std::size_t>(c)].name + ": " +
                  std::to_string(model.cells[static_cast<std::size_t>(c)].volume.dim()) +
                  " coordinates per control point; expected " + std::to_string(model.dim()) + " (xyz and the model's properties)");
  // The pieces of each cell are known from its knots (one per non-empty span triple, each with
  // the cell's orders): every piece's slots are sized up front. Cells are then extracted and
  // built in batches of consecutive cells whose Bezier pieces take at most batch_bytes (a
  // thousand-span fillet cell alone makes 100k pieces, hundreds of MB as splines), each batch's
  // cells and then its pieces in parallel, and its pieces freed before the next batch; each
  // piece writes its own slots (its Piece, its part of the pool, its leaves), concatenated in
  // order afterwards: the same locator whatever the thread count.
  constexpr double batch_bytes = 64.0 * 1024 * 1024;
  std::vector<std::size_t> first_piece(static_cast<std::size_t>(nc) + 1, 0);
  std::vector<double> cell_bytes(static_cast<std::size_t>(nc), 0.0);
  std::vector<std::size_t> nets;  // pool offset per piece
  std::size_t size = 0;
  for (int c = 0; c < nc; ++c) {
    const auto& v = model.cells[static_cast<std::size_t>(c)].volume;
    std::size_t pieces = 1, per_piece = 1;
    for (int d = 0; d < 3; ++d) {
      pieces *= v.knots(d).breakpoints().size() - 1;
      per_piece *= static_cast<std::size_t>(v.knots(d).order());
    }
    const std::size_t values = per_piece * static_cast<std::size_t>((v.rational() ? 4 : 3) + D.m);
    for (std::size_t i = 0; i < pieces; ++i) {
      nets.push_back(size);
      size += values;
    }
    first_piece[static_cast<std::size_t>(c) + 1] = first_piece[static_cast<std::size_t>(c)] + pieces;
    cell_bytes[static_cast<std::size_t>(c)] = static_cast<double>(pieces) * static_cast<double>(per_piece * static_cast<std::size_t>(v.dim())) * 8.0;
  }
  D.pool.resize(size);
  D.pieces.resize(nets.size());
  D.cells.resize(static_cast<std::size_t>(nc));
  std::vector<std::vector<LocatorLeaf>> leaves(nets.size());
  for (int c0 = 0; c0 < nc;) {
    int c1 = c0 + 1;
    for (double bytes = cell_bytes[static_cast<std::size_t>(c0)]; c1 < nc && bytes + cell_bytes[static_cast<std::size_t>(c1)] <= batch_bytes; ++c1)
      bytes += cell_bytes[static_cast<std::size_t>(c1)];
    std::vector<detail::CellPieces> cells(static_cast<std::size_t>(c1 - c0));
    tbb::parallel_for(c0, c1, [&](int c) { cells[static_cast<std::size_t>(c - c0)] = detail::cell_pieces(model.cells[static_cast<std::size_t>(c)]); });
    for (int c = c0; c < c1; ++c)
      if (static_cast<std::size_t>(cells[static_cast<std::size_t>(c - c0)].pieces()) != first_piece[static_cast<std::size_t>(c) + 1] - first_piece[static_cast<std::size_t>(c)])
        throw Error("cell " + model.cells[static_cast<std::size_t>(c)].name + ": internal: Bezier extraction made " +
                        std::to_string(cells[static_cast<std::size_t>(c - c0)].pieces()) + " pieces; expected one per span",
                    ErrorKind::failed);
    tbb::parallel_for(first_piece[static_cast<std::size_t>(c0)], first_piece[static_cast<std::size_t>(c1)], [&](std::size_t i) {
      const int c = static_cast<int>(std::upper_bound(first_piece.begin(), first_piece.end(), i) - first_piece.begin()) - 1;
      const auto& cp = cells[static_cast<std::size_t>(c - c0)];
      D.pieces[i] = detail::build_piece(detail::PieceRef(cp, static_cast<int>(i - first_piece[static_cast<std::size_t>(c)])), cp.H, c, static_cast<int>(i), nets[i], D.m, opt_,
                                D.pool.data(), leaves[i]);
    });
    for (int c = c0; c < c1; ++c) {
      auto& cell = cells[static_cast<std::size_t>(c - c0)].cell;
      cell.first_piece = static_cast<int>(first_piece[static_cast<std::size_t>(c)]);
      D.cells[static_cast<std::size_t>(c)] = std::move(cell);
    }
    c0 = c1;
  }
  std::size_t total = 0;
  for (const auto& l : leaves) total += l.size();
  D.leaves.reserve(total);
  for (const auto& l : leaves) D.leaves.insert(D.leaves.end(), l.begin(), l.end());
  detail::build_bvh(D);
  D.bounds_once = std::make_unique<detail::Once[]>(D.pieces.size());
  // Booleans' trimming: one locator per condition, built recursively (their cells may be
  // trimmed too).
  detail::build_trims(D, model, opt_);
}

Locator::~Locator() = default;
Locator::Locator(Locator&&) noexcept = default;
Locator& Locator::operator=(Locator&&) noexcept = default;

const vmodel::VModel& Locator::model() const noexcept { return *model_; }
const LocatorOptions& Locator::options() const noexcept { return opt_; }
std::span<const LocatorLeaf> Locator::leaves() const noexcept { return data_->leaves; }

std::array<Vec3, 2> Locator::domain(int cell) const noexcept {
  const auto& c = data_->cells[static_cast<std::size_t>(cell)];
  return {c.lo, c.hi};
}

LocateResult Locator::locate(const Vec3& p, const LocateResult* hint) const {
  if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) return {false, -1, {}, false};
  std::vector<int> cand;
  query(p, p, opt_.tolerance, cand);
  LocateResult out;
  const double guess = 500.0 * opt_.tolerance;
  std::size_t k = 0;
  while (k < cand.size()) {
    const int cell = data_->leaves[static_cast<std::size_t>(cand[k])].cell;
    std::size_t e = k;
    while (e < cand.size() && data_->leaves[static_cast<std::size_t>(cand[e])].cell == cell) ++e;
    if (hint && hint->inside && hint->cell == cell) {
      const auto dom = domain(cell);
      const auto r = newton(cell, p, hint->uvw, dom[0], dom[1]);
      if (r.status == NewtonStatus::converged) {
        if (admits(cell, p)) return {true, cell, r.uvw, out.converged};
        k = e;  // inside the trivariate but trimmed away: the next cell
        continue;
      }
    }
    NewtonResult best;
    best.residual = inf;
    bool failed = false;
    for (std::size_t i = k; i < e; ++i) {
      if (!data_->leaves[static_cast<std::size_t>(cand[i])].may_contain(p, opt_.tolerance)) continue;
      const auto r = solve_in_leaf(cand[i], p);
      if (r.status == NewtonStatus::converged) {
        if (admits(cell, p)) return {true, cell, r.uvw, out.converged};
        failed = false;
        break;
      }
      if (r.status == NewtonStatus::failed) {
        failed = true;
        if (r.residual < best.residual) best = r;
      }
    }
    if (failed) {
      out.converged = false;
      if (best.residual < guess && admits(cell, p)) return {true, cell, best.uvw, false};
    }
    k = e;
  }
  return out;
}

std::array<Vec3, 2> model_bounds(const vmodel::VModel& model) {
  if (model.cells.empty()) throw Error("the model has no cells; expected at least one volumetric cell to slice");
  // Cells in parallel (a thousand-span cell's Bezier form takes a while), combined in cell order.
  std::vector<std::array<std::vector<double>, 2>> boxes(model.cells.size());
  tbb::parallel_for(std::size_t{0}, boxes.size(), [&](std::size_t c) { boxes[c] = spline::bounding_box(model.cells[c].volume, 3); });
  std::array<Vec3, 2> b{Vec3{inf, inf, inf}, Vec3{-inf, -inf, -inf}};
  for (const auto& bb : boxes) {
    for (std::size_t d = 0; d < 3; ++d) {
      b[0][d] = std::min(b[0][d], bb[0][d]);
      b[1][d] = std::max(b[1][d], bb[1][d]);
    }
  }
  return b;
}

double model_diagonal(const vmodel::VModel& model) {
  const auto b = model_bounds(model);
  return std::max(std::numeric_limits<double>::min(), std::hypot(b[1][0] - b[0][0], b[1][1] - b[0][1], b[1][2] - b[0][2]));
}

}  // namespace trivox::slice
