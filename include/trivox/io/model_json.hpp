/// @file trivox/io/model_json.hpp
/// @brief The trivox model file: a V-model as JSON, format version 1.
///
/// A model file holds the property names, the cells (each a trivariate in R^(3+m)) and any free
/// surfaces; `docs/model-format.md` is the user's reference. Reading validates every value
/// before it is used and reports the first problem as a `trivox::Error` (bad_input) reading
/// "<file>: <JSON pointer>: <what was found>; expected <what>", so that no input, however
/// malformed, gets past the reader or crashes it. A *scene* (a file with primitives or
/// operations, input of `trivox build`) is recognised and rejected with a pointer to `build`.
///
/// Writing produces the same format, one control point per line; every double is written in
/// its shortest round-trip form, so `read_model_json(write_model_json(m), ..) == m` bit for bit.
///
/// Reading first makes one streaming pass over the text (src/io/model_scan.hpp) that checks the
/// declared orders, control-point counts, cells, properties and names against the limits
/// (trivox/limits.hpp) and each spline's count of control points against its knot vectors, so a
/// file over a limit or with a wrong count is refused before its tree is built.
///
/// Cost: linear in the text size for both directions; reading holds the parsed JSON tree
/// (about 2.3 times the text) and the model at the same time.
#pragma once
#include <string>
#include <string_view>

#include "trivox/limits.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::io {

/// The model format version this build reads and writes (the top-level `"trivox"` key).
inline constexpr int model_format_version = 1;

/// True for the length units a model may declare: "um", "mm", "cm", "m", "in".
bool known_units(std::string_view units) noexcept;

/// Parses a model file.
/// @param text    the whole file, UTF-8 JSON
/// @param source  the file name, prefixed to every error message
/// @param limits  the limits the file must keep (max_file_bytes is load_model's to check)
/// @returns the model; cells keep their file order, points are copied verbatim
/// @throws trivox::Error (bad_input) naming `source`, the JSON pointer of the offending value
///         (or the line and column of a syntax error) and what was expected; a value over a
///         limit names the limit
vmodel::VModel read_model_json(std::string_view text, const std::string& source,
                               const Limits& limits = default_limits());

/// Formats a model as a version-1 model file (the `"surfaces"` key only when it has surfaces).
/// @throws trivox::Error (bad_input) when the model could not be read back: no cells and no
///         surfaces, empty or repeated names, unknown units, a cell whose control points do not
///         have model.dim() coordinates, or a non-finite value
std::string write_model_json(const vmodel::VModel& model);

}  // namespace trivox::io
