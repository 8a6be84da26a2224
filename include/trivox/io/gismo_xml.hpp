/// @file trivox/io/gismo_xml.hpp
/// @brief Import of G+Smo XML geometry files (single- and multi-patch) as a V-model.
///
/// Reads every `<Geometry>` child of the `<xml>` root, in file order:
///  - `TensorBSpline3` and `TensorNurbs3` become cells,
///  - `TensorBSpline2` and `TensorNurbs2` become free surfaces,
/// each named `patch<i>`, i being the geometry's position among all `<Geometry>` elements
/// (0-based; G+Smo ids need not be unique, so they are not used). `coefs geoDim="2"` is planar
/// geometry (z = 0); coordinates beyond the third become properties named `p0`, `p1`, ..., and
/// every geometry of a file must then carry the same number. Other elements (`MultiPatch`,
/// `boundaryConditions`, functions, ...) are ignored: a MultiPatch only lists the patches and
/// how they meet, which the geometry itself determines. Units are "mm" (G+Smo files carry none).
///
/// Errors name the file, the element path and line, e.g.
/// `cube.xml: Geometry[3] (id="1") / Basis type="TensorBSplineBasis3" / Basis index="1" /
/// KnotVector (line 81): knot 3 (0.5) is less than knot 2 (1); expected non-decreasing knots`.
///
/// Limits (trivox/limits.hpp): degrees (max_order - 1), control points per patch (max_points, from
/// the knot vectors before the coefficients are read), geometries (max_cells) and properties
/// (geoDim - 3, max_properties) are checked where the file declares them.
///
/// Cost: linear in the text size; pugixml holds the document tree while the model is built.
#pragma once
#include <string>
#include <string_view>

#include "trivox/limits.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::io {

/// Parses a G+Smo XML file.
/// @param text    the whole file (a comment may precede the XML declaration)
/// @param source  the file name, prefixed to every error message
/// @returns a model with units "mm", properties p0.. (geoDim - 3 of them, if any), one cell per
///          trivariate and one surface per surface patch
/// @throws trivox::Error (bad_input) on malformed XML (with its line and column), an unknown
///         geometry or basis type, bad knot vectors, a coefficient or weight count that does not
///         match the basis, non-finite numbers or differing geoDims, or a value over a limit
vmodel::VModel read_gismo_xml(std::string_view text, const std::string& source,
                              const Limits& limits = default_limits());

}  // namespace trivox::io
