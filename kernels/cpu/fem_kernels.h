// fem_kernels.h — CPU reference kernels of the FEM tet materials (stable
// Neo-Hookean, St. Venant-Kirchhoff, corotational linear). The models'
// constraints and their derivatives are in kernels/math/fem_math.h; the
// per-tet data layout in kernels/shared/fem_params.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "math/fem_math.h"

namespace sinew::kernels {

void xpbd_solve_neo_hookean(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_stvk(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_corotational(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);

}  // namespace sinew::kernels
