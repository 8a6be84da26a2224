/// @file src/io/model_scan.hpp
/// @brief Private to trivox_core: the streaming first pass over a JSON model file, which checks
/// what the file declares against the limits (trivox/limits.hpp) before the document tree is
/// built, so that a hostile file costs one pass over its text and no memory in proportion to it.
///
/// In file order it refuses an order above max_order (any number in an "orders" array), a spline
/// whose knot vectors or "points" array ask for more than max_points control points, more than
/// max_cells cells and surfaces (objects with a "trivariate" or "surface"), more than
/// max_properties properties, and a name ("name" values, property names) longer than
/// max_name_bytes. It also compares each spline's "points" count with the count its orders and
/// knot vectors give, when those are well formed (whole orders, non-decreasing numeric knots, at
/// least 2 x order of them, no run of equal knots longer than the order), with the reader's
/// message: a file with a wrong count is refused before it is parsed whole. Anything else,
/// malformed JSON included, is left to the reader: the pass stops where it cannot follow.
///
/// Cost: one pass over the text, about 2 ns per byte (0.16 to 0.2 s for a 93.5 MB model); memory
/// proportional to the nesting depth.
#pragma once
#include <string>
#include <string_view>

#include "trivox/limits.hpp"

namespace trivox::io {

/// Checks `text` (a JSON model) against `limits` as the file comment says.
/// @param source  the file name, prefixed to every message
/// @returns true when the pass followed the text to its end (false: malformed, left to the reader)
/// @throws trivox::Error (bad_input) "<source>: <JSON pointer>: <found>; expected <what> (limit
///         NAME; raise it with --limit NAME=N)", or the reader's count mismatch message
bool scan_model_json(std::string_view text, const std::string& source, const Limits& limits);

}  // namespace trivox::io
