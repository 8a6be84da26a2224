/// @file src/slice/pieces.hpp
/// @brief (private to src/slice) A cell's Bezier pieces as the locator builds them: the cell in
/// Bezier form (spline::to_bezier_form), each piece read in place from it (PieceRef), and each
/// piece's record, net and leaves (build_piece). Defined in pieces.cpp.
#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

#include "locator_data.hpp"

namespace trivox::slice::detail {

/// A cell's Bezier pieces, before they are built.
struct CellPieces {
  Locator::Data::Cell cell;
  /// The cell in Bezier form: its pieces are disjoint blocks of `order` points per span and
  /// direction, read in place (PieceRef) rather than copied into a spline each, as
  /// spline::bezier_pieces does (the filleted teapot: 350k pieces, four allocations each).
  spline::TensorSpline<3> bezier;
  std::array<int, 3> spans{};
  std::array<std::vector<double>, 3> breaks;  ///< the Bezier form's breakpoints
  int H = 3;  ///< geometry coordinates: 4 for a rational cell

  int pieces() const noexcept { return spans[0] * spans[1] * spans[2]; }
};

/// Piece e (u fastest) of a cell's Bezier form: bezier_pieces(s)[e] without the copy, the same
/// domain, points and weights.
struct PieceRef {
  const spline::TensorSpline<3>* b = nullptr;
  std::array<int, 3> el{}, order{};
  std::array<std::array<double, 2>, 3> dom{};

  PieceRef(const CellPieces& cp, int e) : b(&cp.bezier), order(cp.bezier.orders()) {
    for (std::size_t d = 0; d < 3; ++d) {
      el[d] = e % cp.spans[d];
      e /= cp.spans[d];
      dom[d] = {cp.breaks[d][static_cast<std::size_t>(el[d])], cp.breaks[d][static_cast<std::size_t>(el[d]) + 1]};
    }
  }
  int size() const noexcept { return order[0] * order[1] * order[2]; }
  /// The Bezier form's row of the piece's local point i (u fastest).
  int row(int i) const noexcept {
    std::array<int, 3> src{};
    for (std::size_t d = 0; d < 3; ++d) {
      src[d] = el[d] * order[d] + i % order[d];
      i /= order[d];
    }
    return b->row(src);
  }
};

/// The cell's domain, breakpoints and Bezier pieces.
CellPieces cell_pieces(const vmodel::VCell& vc);

/// Builds one Bezier piece: its Piece record, its net (written to `pool`, pc.net values on) and
/// its leaves (appended to `leaves`). The whole-piece StepBounds are left to first use.
/// @param piece_index  the piece's index among all pieces of the locator
/// @param H            the cell's geometry coordinates (CellPieces::H)
Locator::Data::Piece build_piece(const PieceRef& bp, int H, int cell_index, int piece_index, std::size_t net, int m,
                                 const LocatorOptions& opt, double* pool, std::vector<LocatorLeaf>& leaves);

}  // namespace trivox::slice::detail
