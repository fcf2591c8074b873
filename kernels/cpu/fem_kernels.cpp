// fem_kernels.cpp — CPU reference kernels of the FEM tet materials. (Stage in progress.)
#include "cpu/fem_kernels.h"

namespace sinew::kernels {

void xpbd_solve_neo_hookean(const void*, std::byte* const*, std::uint32_t, std::uint32_t) {}
void xpbd_solve_stvk(const void*, std::byte* const*, std::uint32_t, std::uint32_t) {}
void xpbd_solve_corotational(const void*, std::byte* const*, std::uint32_t, std::uint32_t) {}

}  // namespace sinew::kernels
