/// @file trivox/slice/piece_measures.hpp
/// @brief Exact measures of a Boolean's piece (a trimmed cell) from its trimmed boundary:
/// volume, centroid, boundary area and a tight bounding box, with self-checks.
///
/// Massarwi & Elber 2016, Sec. 5.1 measure trimmed entities by untrimming them into
/// tensor-product patches. Here the piece's boundary faces (slice::boundary_faces), each
/// untrimmed into Bezier patches and oriented outward, carry the volume integrals by the
/// divergence theorem: for the solid P with outward normal n and any point c,
///   V_i = int_dP (x_i - c_i) n_i dA = vol(P)            for each i = x, y, z,
///   int_P (x_i - c_i) dV = 1/2 int_dP (x_i - c_i)^2 n_i dA,
/// and on a patch X(s, t) n dA = X_s x X_t ds dt, so both integrands are polynomials of degree
/// 4p - 1 in a direction of degree p: a Gauss rule with 2p + 2 points per direction
/// (geom::gauss_legendre) integrates them exactly. The volume is therefore exact up to rounding
/// and to how closely the boundary faces meet (the intersection curves' tolerance). c is the
/// middle of the patches' control boxes, which keeps the sums well conditioned.
///
/// Self-checks (Massarwi & Elber's closed boundary): a closed, consistently oriented boundary
/// has int_dP n dA = 0 and V_x = V_y = V_z. `closure` = |int n dA| / area and `spread` =
/// max_i |V_i - V| / (area x diagonal) are reported, and above `check_tolerance` piece_measures
/// throws (a face missing or counted twice, such as coplanar faces of two inputs, which
/// boundary_faces classifies whole, or a wrong orientation). Where the faces meet only within
/// the intersection curves' accuracy both are small but not zero (about 1e-15 for planar cuts,
/// 1e-11 to 1e-10 where planes and the curved cells of construct's ball, cylinder and torus cut
/// one another, the faces' images of the parameter-space trimming curves lying within the
/// intersection tolerance, 1e-10, of the intersection); the volume's error is then of the order of
/// spread x area x diagonal.
///
/// The boundary area is the sum of the faces' areas (geom::area: a square root integrand, so
/// converged Gauss quadrature, not exact). The bounding box is that of the boundary patches,
/// found per coordinate by branch and bound on their Bezier coefficients (the coefficients
/// bound a patch, its corners lie on it; patches are halved by de Casteljau where the bound
/// exceeds the best corner by more than the tolerance): points of the boundary attain it, and
/// the exact box is at most `bbox_tolerance` x diagonal larger on each side.
///
/// Property integrals (mass per material, int_P rho dV) are slice::property_integrals'
/// (property_integrals.hpp): a property is a polynomial of the trivariate's parameters, not of x,
/// so the faces must be taken to the parameter space first; that is polynomial, and the integral
/// exact, for pieces of affine trivariates only (otherwise it needs the untrimming of trimmed
/// V-cells, Massarwi & Elber 2016, Sec. 7, which is not built).
///
/// Coplanar faces of the piece's trivariate and its direct conditions (planar control nets on one
/// plane, overlapping) are refused before any intersection: boundary_faces does not cut them.
///
/// Cost: that of boundary_faces (36 (1 + C)^2 surface intersections for C direct conditions,
/// then trimming and untrimming), plus per patch of degrees (p, q) (2p + 2)(2q + 2) evaluations
/// and the bounding box's subdivisions (at most `bbox_budget` per patch and coordinate).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "trivox/slice/boundary_faces.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::slice {

struct PieceMeasureOptions {
  BoundaryFaceOptions faces;
  /// Largest closure and spread accepted (relative, see the file comment); beyond it the
  /// boundary is not closed and piece_measures throws trivox::Error (failed).
  double check_tolerance = 1e-5;
  /// The bounding box's tolerance, relative to the diagonal of the patches' control boxes.
  double bbox_tolerance = 1e-9;
  /// Subdivisions per patch and coordinate before the bound is taken as it is (bbox_tight false).
  int bbox_budget = 4096;
  /// Most direct conditions accepted: boundary_faces intersects 36 (1 + C)^2 pairs of faces,
  /// 2,916 at 8. Beyond it piece_measures throws trivox::Error (failed) before intersecting.
  int max_conditions = 8;
};

struct PieceMeasures {
  int cell = -1;
  /// No boundary face: the conditions admit nothing, the piece is empty (volume and area 0,
  /// centroid and bbox zero).
  bool empty = true;
  double volume = 0.0;                     ///< (V_x + V_y + V_z) / 3
  std::array<double, 3> centroid{};        ///< int_P x dV / volume
  double area = 0.0;                       ///< boundary area
  std::array<std::array<double, 3>, 2> bbox{};  ///< {min, max} of the boundary's xyz
  /// Every extreme converged within the tolerance (false: some patch ran out of its
  /// subdivision budget and its coefficient bound was taken, still conservative).
  bool bbox_tight = true;
  double closure = 0.0;  ///< |int_dP n dA| / area
  double spread = 0.0;   ///< max_i |V_i - volume| / (area x diagonal)
  int faces = 0;
  std::int64_t patches = 0;
};

/// The measures of `model.cells[cell]` (a plain cell too: its six faces).
/// @throws trivox::Error (bad_input) for a cell out of range; (failed) when the cell's or a
///         direct condition's trivariate is rational (untrimming needs polynomial surfaces),
///         when two of their faces are coplanar and overlap, for more than max_conditions
///         direct conditions,
///         when the boundary does not close (closure or spread above check_tolerance) or the
///         volume is not positive; and as boundary_faces
PieceMeasures piece_measures(const vmodel::VModel& model, int cell, const PieceMeasureOptions& options = {});

/// The measures of a piece from its boundary faces (as boundary_faces returns them); `cell`
/// is copied to the result. Throws as above for a boundary that does not close.
PieceMeasures piece_measures(const std::vector<BoundaryFace>& faces, int cell, const PieceMeasureOptions& options = {});

}  // namespace trivox::slice
