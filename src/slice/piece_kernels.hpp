/// @file src/slice/piece_kernels.hpp
/// @brief (private to src/slice) The kernels that evaluate a Bezier piece's net in Bernstein
/// form, chosen once per piece by its orders and coordinates (pick_kernels) and called through
/// function pointers by the locator: the geometry with or without first partials (Newton), every
/// coordinate's value (a point and its properties), every coordinate with first partials (the
/// sampler's anchors), and the properties at eight or four points at once (the sampler's
/// samples along a run). Defined in piece_kernels.cpp.
#pragma once
#include <array>

namespace trivox::slice::detail {

/// The largest order per direction a piece may have (the kernels' stack arrays are this long).
inline constexpr int max_order = 32;  // fillets composed from bicubic faces have order 19

/// A net contracted with the Bernstein basis at one point: (net, coordinates per control point,
/// orders, the local parameters s (3 values in [0,1]), out).
using Kernel = void (*)(const double*, int, const std::array<int, 3>&, const double*, double*);
/// The properties of a polynomial net at eight points: (net, coordinates per control point nc,
/// geometry coordinates H, properties m, orders, s[d][lane], out[lane * m + h]).
using Props8 = void (*)(const double*, int, int, int, const std::array<int, 3>&, const double (*)[8], double*);

struct Kernels {
  Kernel first = nullptr;      ///< geometry with first partials
  Kernel value = nullptr;      ///< geometry value
  Kernel all = nullptr;        ///< every coordinate's value
  Kernel all_first = nullptr;  ///< every coordinate with first partials (polynomial, nc <= 10)
  Props8 props = nullptr;      ///< the properties at eight points (polynomial)
  Props8 props4 = nullptr;     ///< the same at four points (AVX2; else null)
};

/// Kernels with the orders fixed at compile time for the common pieces: uniform orders 2 to 4,
/// and the shells and tubes the scenes build (cubic faces swept linearly, (4, 4, 2); linear
/// sections swept along a cubic, (2, 2, 4)); any other orders read them at run time.
/// H: 3 (polynomial) or 4 (rational) geometry coordinates per control point; nc: coordinates per
/// control point (H and the properties).
template <int H>
Kernels pick_kernels(const std::array<int, 3>& ord, int nc);
extern template Kernels pick_kernels<3>(const std::array<int, 3>& ord, int nc);
extern template Kernels pick_kernels<4>(const std::array<int, 3>& ord, int nc);

}  // namespace trivox::slice::detail
