// thin_kernels.h — CPU reference kernels of thin bodies and threads. (Stage in progress: the kernels are stubs until it lands.)
#pragma once

#include <cstddef>
#include <cstdint>

namespace sinew::kernels {

void xpbd_solve_area(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_dihedral(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_line_bending(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);

}  // namespace sinew::kernels
