// sph_kernels.h — the AVX2 versions of the fluid's density and step
// (sph_kernels_avx2.cpp); the scalar reference kernels are declared from
// the registry in cpu_kernels.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cpu/cpu_kernels.h"

namespace sinew::kernels {

/// sph_density over sorted particles [begin, end), bitwise the scalar
/// kernel's, eight candidates' terms at a time. [pre] cpu_has_avx2()
void sph_density_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
/// sph_step likewise.
void sph_step_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
/// sph_boundary_force likewise.
void sph_boundary_force_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);

}  // namespace sinew::kernels
