// fem_kernels.h — CPU reference kernels of the FEM tet materials. (Stage in progress: the kernels are stubs until it lands.)
#pragma once

#include <cstddef>
#include <cstdint>

namespace sinew::kernels {

void xpbd_solve_neo_hookean(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_stvk(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_corotational(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);

}  // namespace sinew::kernels
