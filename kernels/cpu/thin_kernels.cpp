// thin_kernels.cpp — CPU reference kernels of thin bodies and threads. (Stage in progress.)
#include "cpu/thin_kernels.h"

namespace sinew::kernels {

void xpbd_solve_area(const void*, std::byte* const*, std::uint32_t, std::uint32_t) {}
void xpbd_solve_dihedral(const void*, std::byte* const*, std::uint32_t, std::uint32_t) {}
void xpbd_solve_line_bending(const void*, std::byte* const*, std::uint32_t, std::uint32_t) {}

}  // namespace sinew::kernels
