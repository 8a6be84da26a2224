/// @file src/slice/run_writers.hpp
/// @brief (private to src/slice) Writing the properties of a run of voxels from a linear or a
/// quadratic model, as floats: kernels compiled for the property counts 1 to 4 (and any other
/// count read at run time), each with an AVX2 build chosen when the CPU has it (run_writers.cpp).
#pragma once

namespace trivox::slice::detail {

/// out[j m + h] = va[h] + j slope[h] for j < n, h < m: (out, n, m, va, slope).
using WriteLinear = void (*)(float*, int, int, const double*, const double*);
/// out[j m + h] = va[h] + j (slope[h] + j curv[h]) for j < n, h < m: (out, n, m, va, slope, curv).
using WriteQuadratic = void (*)(float*, int, int, const double*, const double*, const double*);

/// The writers for m properties, for the CPU that runs them (the same floats on every CPU).
WriteLinear pick_write(int m);
WriteQuadratic pick_write_quadratic(int m);

}  // namespace trivox::slice::detail
