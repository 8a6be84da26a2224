/// @file trivox/fillet/shepard.hpp
/// @brief Euclidean-distance (Shepard) property blending of fillets: the least-squares encoding
/// of the exact blend f (vmodel/shepard_field.hpp) into a fillet half's control points.
///
/// Masalha, Cirillo & Elber 2021, Sec. 7.2.
///
/// Encoding (Sec. 7.2: "evaluating f in a user-controlled number of sampled points in the domain
/// of T, and solving a least-square-fitting problem ... fix ... the points at the boundaries"):
/// the half's properties become G + R, G(u, v) its own properties on the face w = 0 (S^_i with
/// g_i, copied along w) and R a tensor-product spline in a fit space (the half's u and v spaces,
/// or for many control points order 4 on at most `max_spans` of its breakpoints; v with knots
/// graded towards both ends, one of them C, where f turns fastest; along w order 4 with `w_spans`
/// spans graded towards w = 0) whose control points at w = 0 are pinned to zero, fitted by
/// least squares to f - G at Gauss points of every span (a full tensor grid, so the least
/// squares solution is the Kronecker product of the three 1-D pseudo-inverses). Half and R are
/// then brought into one space (spline::make_compatible); the control points of the face w = 0
/// are the half's own, bit for bit, so the encoded properties equal g_i exactly on S^_i.
///
/// Cost: one f per sample, about (2 n_u) x (2 n_v) x (2 n_w) samples for a fit space of
/// n_u x n_v x n_w, and as many again at midpoints for the check, in parallel.
#pragma once
#include <array>
#include <cstdint>

#include "trivox/spline/tensor_spline.hpp"
#include "trivox/vmodel/shepard_field.hpp"

namespace trivox::fillet {


struct ShepardOptions {
  int power = 2;       ///< q, 1..16
  int w_spans = 4;     ///< spans of the fit space along w, graded towards w = 0: 2^-k (1..16)
  int grade = 2;       ///< v: knots 1/2, 2^-k and 1 - 2^-k for k = 2..grade + 1 added (0: none)
  int w_order = 4;     ///< order of the fit space along w (2..8)
  int max_spans = 64;  ///< u or v: at most this many spans of the half's breakpoints in the fit
  int max_direct = 24; ///< u or v with at most this many control points: the half's own space
};

/// The encoded half and how well it reproduces f.
struct ShepardEncoding {
  spline::Trivariate half;   ///< the half, its properties G + R (geometry unchanged, w refined)
  double max_error = 0.0;    ///< max |encoded - f| over the samples, all properties
  double rms_error = 0.0;    ///< root mean square of the same
  double check_error = 0.0;  ///< max |encoded - f| at the midpoints between samples (a check)
  std::int64_t samples = 0;  ///< points where f was evaluated for the fit
  std::array<int, 3> fit_counts{};  ///< control points of R per direction (w's first pinned)
  double seconds = 0.0;
};

/// Encodes f into a fillet half by least squares, the half's face w = 0 pinned (file comment).
/// @param half     a fillet half (ruled_fillet.hpp) in R^(3+m): w = 0 on S^_i, w = 1 on S_b
/// @param field    f, over the same properties
/// @throws Error (bad_input) for a rational half, other dimensions or options out of range
ShepardEncoding encode_shepard(const spline::Trivariate& half, const vmodel::ShepardField& field,
                               const ShepardOptions& options = {});

}  // namespace trivox::fillet
