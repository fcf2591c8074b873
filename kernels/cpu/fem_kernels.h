// fem_kernels.h — CPU reference kernels of the FEM tet materials (stable
// Neo-Hookean, St. Venant-Kirchhoff, corotational linear). The models'
// constraints and their derivatives are in kernels/math/fem_math.h; the
// per-tet data layout in kernels/shared/fem_params.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cpu/cpu_kernels.h"  // the kernel entry points, declared from the registry
#include "math/fem_math.h"


namespace sinew::kernels {

/// The neo_hookean, stvk and corotational solves eight tets at a time with
/// AVX2 (corotational: groups holding a tet on its first solve run the
/// scalar kernel), bitwise equal to the scalar kernels
/// (fem_kernels_avx2.cpp). They do whole groups of eight from `begin` and
/// return the first item not done, for the scalar kernel to finish
/// [it, end). [pre] cpu_has_avx2()
std::uint32_t xpbd_solve_neo_hookean_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                          std::uint32_t end);
std::uint32_t xpbd_solve_stvk_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                   std::uint32_t end);
std::uint32_t xpbd_solve_corotational_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                           std::uint32_t end);

}  // namespace sinew::kernels
