/// @file trivox/construct/tube_solid.hpp
/// @brief The solid inside a tube surface (a surface closed around in u), as five non-singular
/// cells, each the volumetric Boolean sum of its six faces.
///
/// A single tensor-product cell whose sleeve is a smooth tube is singular: splitting the closed
/// cross-section into the four sides of a Coons patch puts angles of pi at its corners, where
/// det J vanishes. Massarwi & Elber 2016, Sec. 3.2.3 (Fig. 9 a) avoid that for the
/// cylinder by a 5-cell disk; here the same disk is swept along any tube S(u, v) (u around, v
/// along): with Q_k(v) = S(k/4, v), the centre c(v) = (Q_0 + Q_1 + Q_2 + Q_3) / 4 and the core's
/// corners K_k(v) = c + core (Q_k - c),
///  - `core`: the cell (s, t, v) bilinear in the corners K_0 (s = t = 0), K_1, K_2, K_3 (s = 0,
///    t = 1), its w direction the tube's v;
///  - `s0` .. `s3`: cell k between the core's side K_k K_{k+1} (w = 0) and the quarter of the tube
///    S(u, v), u in [k/4, (k+1)/4] (w = 1); (s, v, w): s around, v along, w outward.
/// Each cell is construct::boolean_sum (Massarwi & Elber 2016, Sec. 3.2.2 item 4) of its six faces,
/// all ruled surfaces or quarters of S, so the cells are exactly the ruled constructions and glue
/// along shared faces (the core's t = 1 and s = 0 sides run backwards against s2's and s3's w = 0).
/// Where S's cross-sections are convex and advance along v (each cross-section planar or nearly,
/// the tube's axis transverse to them), det J keeps one sign; the cells are oriented positively
/// (u of S is reversed when the core's det J at its centre is negative).
///
/// Cost: five Boolean sums of the tube's quarters (the size of S each, times 7 terms).
#pragma once
#include <array>
#include <string>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::construct {

struct TubeCell {
  std::string part;            ///< "core", "s0", "s1", "s2", "s3"
  spline::Trivariate volume;   ///< xyz (and properties, if S carries any)
};

/// The five cells filling the tube s.
/// @param s     a polynomial surface, u closed (S(u_min, v) = S(u_max, v) within `tolerance`)
/// @param core  the core's size relative to the cross-section, in (0, 1) (0.5: half way)
/// @throws Error (bad_input) for a rational or non-3D surface, a u not closed, a core out of range
std::vector<TubeCell> tube_solid(const spline::Surface& s, double core = 0.5, double tolerance = 1e-9);

}  // namespace trivox::construct
