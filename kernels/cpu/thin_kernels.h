// thin_kernels.h — CPU reference kernels of thin bodies (triangle meshes)
// and threads: area, dihedral bending, line bending. Their constraint
// functions are in kernels/math/thin_math.h, which the scene compiler
// shares; data layouts and residuals in kernels/shared/thin_params.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "math/thin_math.h"

namespace sinew::kernels {

void xpbd_solve_area(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_dihedral(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_line_bending(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);

}  // namespace sinew::kernels
