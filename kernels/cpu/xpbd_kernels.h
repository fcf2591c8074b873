// xpbd_kernels.h — the CPU reference kernels of the xPBD solver and the
// constraint functions they share with the scene compiler (which computes
// rest values with the very same code, so a mesh at rest has C == 0 exactly).
//
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016; Macklin et al., "Small Steps in Physics
// Simulation", SCA 2019.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cpu/cpu_math.h"

namespace sinew::kernels {

/// Edge length |a - b| [m]; the distance constraint is C = |a - b| - rest.
template <class T>
inline T edge_length(vec4<T> a, vec4<T> b) {
  const vec4<T> d = a - b;
  return std::sqrt(dot3(d, d));
}

/// grad_a |a - b| = (a - b) / |a - b| (and grad_b = -grad_a).
/// [in] len: |a - b| > 0, as returned by edge_length.
template <class T>
inline vec4<T> edge_length_gradient(vec4<T> a, vec4<T> b, T len) {
  return (T(1) / len) * (a - b);
}

/// Signed tet volume V = dot(x1 - x0, cross(x2 - x0, x3 - x0)) / 6 [m^3];
/// the volume constraint is C = V - rest.
template <class T>
inline T tet_volume(vec4<T> x0, vec4<T> x1, vec4<T> x2, vec4<T> x3) {
  return dot3(x1 - x0, cross3(x2 - x0, x3 - x0)) * (T(1) / T(6));
}

/// [out] g[k] = grad_{x_k} V: (1/6) the cross product of the two other
/// edges from x0 (cyclic), and g[0] = -(g[1] + g[2] + g[3]).
template <class T>
inline void tet_volume_gradients(vec4<T> x0, vec4<T> x1, vec4<T> x2, vec4<T> x3, vec4<T> g[4]) {
  const vec4<T> e1 = x1 - x0, e2 = x2 - x0, e3 = x3 - x0;
  const T sixth = T(1) / T(6);
  g[1] = sixth * cross3(e2, e3);
  g[2] = sixth * cross3(e3, e1);
  g[3] = sixth * cross3(e1, e2);
  g[0] = vec4<T>{T(0), T(0), T(0), T(0)} - (g[1] + g[2] + g[3]);
}

/// Signature of every CPU kernel: parameters (the struct from
/// kernels/shared), the bound buffers in binding order, and the work items
/// [begin, end) to process.
using CpuKernelFn = void (*)(const void* params, std::byte* const* bindings, std::uint32_t begin,
                             std::uint32_t end);

void xpbd_predict(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_update_velocity(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_distance(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_volume(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);

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
