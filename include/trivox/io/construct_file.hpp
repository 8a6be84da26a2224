/// @file trivox/io/construct_file.hpp
/// @brief The input and output files of `trivox construct`: one constructor applied to given
/// curves or surfaces (docs/architecture.md, command-line contract; docs/cli.md is the user's reference).
///
/// Input: {"trivox": 1, "op": NAME, "curves": [...]} or {"trivox": 1, "op": NAME,
/// "surfaces": [...]}, each curve or surface {"orders", "knots", "points", "weights"} as in the
/// model format, every control point with the same number of coordinates (2 for planar
/// construction, 3 for spatial, more for properties), plus the operation's own fields:
///   - "boolean_sum": 4 curves [bottom, top, left, right] or 6 surfaces [u0, u1, v0, v1, w0, w1];
///   - "half_boolean_sum": 2 curves, or 2 or 3 surfaces;
///   - "ruled": 2 curves or surfaces [bottom, top]; "ruling_order" (default 3,
/// Fadila et al. 2023, Sec. 5.1);
///   - "extrude": 1 curve or surface and "vector" [x, y, (z, ...)];
///   - "revolve": 1 curve or surface, "axis" [x, y, z], optional "origin", "angle" (degrees,
///     default 360), "tolerance" (relative, default 1e-6);
///   - "sweep": 2 or more sections, optional "params" (one per section) and "order" (default 4);
///   - "tolerance" (any op): how far shared boundaries may be apart (default 1e-9).
/// Output: {"trivox": 1, "surfaces": [{"orders", "knots", "points", "weights"}]} (or
/// "trivariates"), written atomically.
#pragma once
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/construct/constructors.hpp"

namespace trivox::io {

/// The constructor names `trivox construct` knows.
inline constexpr const char* construct_ops[] = {"boolean_sum", "half_boolean_sum", "ruled", "extrude", "revolve",
                                                 "sweep"};

struct ConstructInput {
  std::string op;
  std::vector<spline::Curve> curves;      ///< set when the input gives "curves"
  std::vector<spline::Surface> surfaces;  ///< set when the input gives "surfaces"
  int dim = 0;                            ///< coordinates per control point
  construct::MatchOptions match;
  int ruling_order = 3;
  std::vector<double> vector;             ///< extrude
  construct::Revolution revolution;       ///< revolve
  std::vector<double> params;             ///< sweep (empty: chord length)
  int order = 4;                          ///< sweep
};

/// Parses a constructor input file.
/// @throws trivox::Error (bad_input) "<source>: <JSON pointer>: <found>; expected <what>",
///         e.g. an unknown op (listing the known ones), a wrong number of curves for the op,
///         curves with different coordinate counts
ConstructInput read_construct_input(std::string_view text, const std::string& source);

/// The output file text for a constructed surface or trivariate.
std::string write_construct_output(const spline::Surface& s);
std::string write_construct_output(const spline::Trivariate& t);

}  // namespace trivox::io
