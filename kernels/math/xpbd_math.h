// xpbd_math.h — the distance and volume constraints of the xPBD solver,
// shared by the CPU reference kernels (kernels/cpu/xpbd_kernels.cpp) and
// the scene compiler, which computes rest lengths and volumes with the very
// same code, so a mesh at rest has C == 0 exactly. Templates: the kernels
// run them in float, the tests differentiate them in double. Keep every
// operation and its order: the rest values and the kernels must round
// alike (the library compiles with -ffp-contract=off).
//
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016.
#pragma once

#include <cmath>

#include "math/vec4.h"

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

}  // namespace sinew::kernels
