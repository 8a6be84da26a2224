/// @file trivox/limits.hpp
/// @brief Input limits: how large a model file, its orders, control-point counts, cells, names
/// and properties may be before trivox refuses it, so that the cost of reading and examining a
/// model is bounded before any expensive step (docs/limits.md has the table and the reasons).
///
/// Every reader (io::load_model, io::read_model, io::read_model_json, io::read_gismo_xml) takes
/// a `Limits` argument whose default is the process's default limits: the documented defaults
/// below unless set_default_limits changed them (the command line does, from `--limit NAME=N`
/// and `TRIVOX_LIMITS`). The readers check each limit where the file declares the quantity,
/// before allocating for it: the file size by stat before reading, a JSON model's orders, counts,
/// names and array lengths in a streaming pass before its document tree is built. geom's
/// quadrature and validity check a cell's orders against the default limits before allocating.
/// A value over its limit is a trivox::Error (bad_input) reading "<file>: <place>: <found>;
/// expected <what> of at most <limit> (limit NAME; raise it with --limit NAME=N)".
///
/// Cost: constant; set_default_limits and default_limits take a lock (call them per file, not
/// per point).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace trivox {

/// The limits one read obeys. Every field is a whole number >= 1.
struct Limits {
  /// Bytes of a model file, checked by stat before it is read. Reading holds the text and its
  /// parsed tree, about 3.3 times the file's size in all.
  std::int64_t max_file_bytes = std::int64_t{1} << 30;
  /// Order (degree + 1) per direction of a cell, surface or curve. Quadrature takes about
  /// 3/2 x order Gauss points per direction (3 x order for rational cells), validity a
  /// determinant of order about 3 x order per direction.
  std::int64_t max_order = 32;
  /// Control points of one cell, surface or curve (the product of its counts).
  std::int64_t max_points = 10'000'000;
  /// Cells and surfaces in a model, the trimming cells of Booleans included.
  std::int64_t max_cells = 100'000;
  /// Bytes of a cell, surface or property name.
  std::int64_t max_name_bytes = 256;
  /// Properties per control point (the model's dimension is 3 + this).
  std::int64_t max_properties = 256;
};

/// One limit as the command line and the documentation name it.
struct LimitInfo {
  const char* name;                 ///< "max_order"
  std::int64_t Limits::*field;      ///< the member it sets
  const char* bounds;               ///< what it bounds, for `--help` and messages
};

/// Every limit, in the order of docs/limits.md.
std::span<const LimitInfo> limit_table() noexcept;

/// " (limit NAME; raise it with --limit NAME=N)": the tail of every refusal.
std::string limit_hint(std::string_view name);

/// Applies one "NAME=VALUE" assignment (VALUE a whole number 1 to 1e18, written plainly or as
/// `1e9`) to `limits`.
/// @param source  where the text came from ("--limit", "TRIVOX_LIMITS"), for the message
/// @throws trivox::Error (bad_input) for an unknown name or a malformed value, naming the text
void set_limit(Limits& limits, std::string_view assignment, const std::string& source);

/// Applies a comma-separated list of assignments ("max_order=64,max_cells=1e6"; empty: none).
/// @throws trivox::Error (bad_input) as set_limit
void set_limits(Limits& limits, std::string_view list, const std::string& source);

/// Refuses an order above `limits.max_order`.
/// @param what  what has the order, for the message ("cell of orders (20000, 2, 2)")
/// @throws trivox::Error (bad_input) "<what>: order N; expected an order of at most M (limit
///         max_order; raise it with --limit max_order=N)"
void check_order(std::int64_t order, const Limits& limits, const std::string& what);

/// The process's default limits: the documented defaults unless set_default_limits was called.
/// Thread-safe.
Limits default_limits();

/// Replaces the process's default limits (the command line calls it once, before any model is
/// read). Thread-safe.
void set_default_limits(const Limits& limits);

}  // namespace trivox
