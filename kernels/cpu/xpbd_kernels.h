// xpbd_kernels.h — the CPU reference kernels of the xPBD solver. Their
// constraint functions (edge length, tet volume and gradients) are in
// kernels/math/xpbd_math.h, which the scene compiler shares.
//
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016; Macklin et al., "Small Steps in Physics
// Simulation", SCA 2019.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cpu/cpu_kernels.h"  // the kernel entry points, declared from the registry
#include "math/xpbd_math.h"

namespace sinew::kernels {

/// True when this CPU runs AVX2 (checked once by the CPU backend).
bool cpu_has_avx2();

/// AVX2 versions of the two solves, bitwise equal to the scalar ones. They
/// process whole groups of eight items from `begin` and return the first
/// item not done; the scalar kernel finishes [returned, end).
/// [pre] cpu_has_avx2()
std::uint32_t xpbd_solve_distance_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                       std::uint32_t end);
std::uint32_t xpbd_solve_volume_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                     std::uint32_t end);

}  // namespace sinew::kernels
