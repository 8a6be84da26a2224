/// @file trivox/geom/validity.hpp
/// @brief Whether a trivariate (or a planar surface) is a valid parametrisation: its Jacobian
/// determinant keeps one strict sign over the whole domain.
///
/// Massarwi & Elber 2016 (Sec. 3.3) and Fadila, Hong & Elber (Sec. 2): the
/// determinant det[dX/du, dX/dv, dX/dw] of a polynomial cell is itself a B-spline
/// (spline::jacobian_determinant, from derivative and product splines). In Bezier form its
/// coefficients bound it (convex hull) and its corner coefficients are its values there. So a
/// Bezier piece whose coefficients all have the sign of the cell's orientation is valid; one with
/// a corner (or centre) value of the other sign, or zero, proves the cell invalid there; anything
/// else is split in two along its longest parameter direction and examined again, depth first in
/// a fixed order (so the first invalid location found is deterministic). A piece narrower than
/// `min_width` that is still undecided leaves the cell undecided: its determinant comes within
/// the reported bounds of 0 without being seen to reach it.
///
/// Cost: one determinant spline (degree about 3p - 1 per direction), then O(pieces examined *
/// coefficients); pieces double only where the determinant nears zero.
#pragma once
#include <array>
#include <optional>
#include <string>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::geom {

enum class Validity {
  valid,      ///< det J has one strict sign everywhere
  invalid,    ///< det J is zero somewhere, or takes both signs (see ValidityReport::invalid_at)
  undecided,  ///< subdivision reached min_width with det J within the bounds of 0
  /// det J has one strict sign in the open domain and is 0 (within zero_tolerance) on part of its
  /// boundary (ValidityReport::degenerate_at): a valid parametrisation of the open cell whose
  /// boundary collapses there (see the file comment)
  degenerate
};

/// "valid", "invalid", "undecided" or "degenerate".
const char* validity_name(Validity v) noexcept;

template <int P>
struct ValidityReport {
  Validity verdict = Validity::undecided;
  /// -1 when det J < 0 (a left-handed parametrisation: valid, but with inward normals), +1 when
  /// positive; the sign that the cell's centre has (0 when det J is 0 there).
  int orientation = 0;
  double min_bound = 0.0;   ///< rigorous lower bound of det J over the domain
  double max_bound = 0.0;   ///< rigorous upper bound
  double min_seen = 0.0;    ///< smallest det J evaluated (at piece corners and centres)
  double max_seen = 0.0;    ///< largest
  /// For an invalid cell: a parameter point where det J is 0 or has the sign opposite to the
  /// orientation; det_at_invalid is its value there.
  std::optional<std::array<double, P>> invalid_at;
  double det_at_invalid = 0.0;
  /// For a degenerate cell: a boundary point where det J is 0 within zero_tolerance (the centre of
  /// the first such face, edge or corner of a Bezier piece found, in the fixed order).
  std::optional<std::array<double, P>> degenerate_at;
  /// |det J| at or below this counts as 0 on the boundary, and coefficients down to -this as
  /// non-negative: 1e-10 times the largest |coefficient| of det J's spline.
  double zero_tolerance = 0.0;
  int pieces = 0;           ///< Bezier pieces examined
};

struct ValidityOptions {
  /// Stop splitting a piece narrower than this fraction of the domain in every direction.
  double min_width = 1.0 / 4096.0;
  int max_pieces = 200000;  ///< beyond this many pieces, what remains is undecided
};

/// The validity of a polynomial trivariate's xyz parametrisation (coordinates 0..2).
/// @throws trivox::Error (bad_input) for a rational cell, fewer than 3 coordinates, or an order
///         above the process's default max_order (trivox/limits.hpp), checked first
ValidityReport<3> check_validity(const spline::Trivariate& cell, const ValidityOptions& options = {});

/// The same for a planar surface (coordinates 0..1: x and y).
/// @throws trivox::Error (bad_input) for a rational surface, fewer than 2 coordinates, or an
///         order above the process's default max_order
ValidityReport<2> check_validity(const spline::Surface& surface, const ValidityOptions& options = {});

}  // namespace trivox::geom
