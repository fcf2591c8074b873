// neighbour_kernels.h — the AVX2 version of the neighbour query
// (neighbour_kernels_avx2.cpp); the scalar reference kernels are declared
// from the registry in cpu_kernels.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cpu/cpu_kernels.h"

namespace sinew::kernels {

/// nbr_query over points [begin, end), the same lists as the scalar
/// kernel, eight candidates at a time. [pre] cpu_has_avx2() (xpbd_kernels.h)
void nbr_query_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);

}  // namespace sinew::kernels
