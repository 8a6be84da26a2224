/// @file src/fillet/corner_glue.cpp
/// @brief The C0 glue where a bridging fillet meets its neighbours (Masalha et al. 2021,
/// Sec. 6.1), where two clipped pieces are stitched (Sec. 6), and at a seam: the largest
/// distance between two end faces at the same parameters (xyz and properties), the bridge's
/// singular rows made exactly equal in every layer, and the pinning of one cell pair's end face
/// onto another's in a common (v, w) function space, so that the two faces are one function.
///
/// Cost: face_gaps evaluates both faces at 13 x 13 points; pin_end brings each pair of cells into
/// one space by knot insertion and degree raising (linear in their control points per inserted
/// knot) and copies an end layer; exact_singular_rows copies O(control points).
#include <algorithm>
#include <cmath>

#include "corner_util.hpp"
#include "fillet_util.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet::detail {

using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using spline::Trivariate;

std::array<double, 2> face_gaps(const Surface& a, const Surface& b) {
  std::array<double, 2> worst{};
  constexpr int n = 12;
  const auto au = a.domain(0), av = a.domain(1), bu = b.domain(0), bv = b.domain(1);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double s = static_cast<double>(i) / n, t = static_cast<double>(j) / n;
      const auto x = a.eval({au[0] + (au[1] - au[0]) * s, av[0] + (av[1] - av[0]) * t});
      const auto y = b.eval({bu[0] + (bu[1] - bu[0]) * s, bv[0] + (bv[1] - bv[0]) * t});
      worst[0] = std::max(worst[0], norm(sub(xyz(x), xyz(y))));
      for (std::size_t c = 3; c < x.size() && c < y.size(); ++c) worst[1] = std::max(worst[1], std::abs(x[c] - y[c]));
    }
  return worst;
}

namespace {

/// The bridge's singular rows (corners.hpp), control point (v index a, w index b) of half
/// `half` (nv points along v): in the fan half (on S_g, half gs) the collapsed C edge (v at C,
/// w = 0), all o; in the segment half the face w = 0 (the edge segment o r, the same in every
/// layer along phi) and the rail face (v at the rail), all r.
bool singular_row(std::size_t half, std::size_t gs, int a, int b, int nv) {
  const int c_side = half == 0 ? nv - 1 : 0, rail_side = nv - 1 - c_side;
  if (half == gs) return a == c_side && b == 0;
  return b == 0 || a == rail_side;
}

}  // namespace

void exact_singular_rows(std::array<Trivariate, 2>& cells, std::size_t gs) {
  for (std::size_t c = 0; c < 2; ++c) {
    Trivariate& h = cells[c];
    const int nu = h.count(0), nv = h.count(1), nw = h.count(2), mid = nu / 2;
    const std::size_t k = static_cast<std::size_t>(h.dim());
    for (int b = 0; b < nw; ++b)
      for (int a = 0; a < nv; ++a)
        if (singular_row(c, gs, a, b, nv))
          for (int i = 0; i < nu; ++i)
            if (i != mid) std::copy_n(h.point(h.row({mid, a, b})).data(), k, h.point(h.row({i, a, b})).data());
  }
}

void pin_end(std::span<Trivariate> cells, int gs, spline::Face end, std::span<Trivariate> nb, spline::Face nb_end) {
  if (cells.size() != 2 || nb.size() != 2) throw Error("fillet corner: expected two ruled halves", ErrorKind::failed);
  for (std::size_t c = 0; c < 2; ++c) {
    Trivariate& cell = cells[c];
    Trivariate& n = nb[c];
    if (cell.rational() || n.rational() || !cell.knots(0).clamped() || !n.knots(0).clamped() || cell.count(0) < 2)
      throw Error("fillet corner: cannot pin a rational or unclamped cell", ErrorKind::failed);
    for (int d = 1; d < 3; ++d) n = spline::reparametrize(n, d, cell.domain(d)[0], cell.domain(d)[1]);
    const auto [ca, cb] = spline::make_compatible(spline::boundary_face(cell, end), spline::boundary_face(n, nb_end));
    for (int d = 0; d < 2; ++d) {
      cell = spline::to_space(cell, d + 1, ca.knots(d));
      n = spline::to_space(n, d + 1, ca.knots(d));
    }
    const int i = end == spline::Face::u0 ? 0 : cell.count(0) - 1, inner = i == 0 ? 1 : i - 1;
    const int in = nb_end == spline::Face::u0 ? 0 : n.count(0) - 1;
    const std::size_t k = static_cast<std::size_t>(cell.dim());
    for (int b = 0; b < cell.count(2); ++b)
      for (int a = 0; a < cell.count(1); ++a) {
        double* src = n.point(n.row({in, a, b})).data();
        if (gs >= 0 && singular_row(c, static_cast<std::size_t>(gs), a, b, cell.count(1))) std::copy_n(cell.point(cell.row({inner, a, b})).data(), k, src);
        std::copy_n(src, k, cell.point(cell.row({i, a, b})).data());
      }
  }
}

}  // namespace trivox::fillet::detail
