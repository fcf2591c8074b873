// vbd_math.h — one tet's share of a Vertex Block Descent step for one of
// its vertices: the gradient of the tet's elastic energy with respect to the
// vertex and its 3x3 Hessian block. Used by the CPU reference kernel
// (kernels/cpu/vbd_kernels.cpp) and the tests. Templates: float in the
// kernel, double in the tests' derivative checks.
//
// Anka He Chen, Ziheng Liu, Yin Yang, Cem Yuksel, "Vertex Block Descent",
// ACM TOG 43(4), SIGGRAPH 2024: per vertex, one Newton step on the
// implicit-Euler energy with every other vertex held, which needs only the
// gradient and the vertex's own 3x3 Hessian block of each incident element,
// that block made positive semi-definite.
//
// The energy is the one xPBD's FEM constraints stand for (fem_params.h,
// compile_fem.cpp): E = C_D^2 / (2 alpha_D) + C_H^2 / (2 alpha_H), alpha =
// 1 / (stiffness V) per tet, so both solvers simulate the same material.
// With F = Ds Dm^-1, F depends on vertex i's position linearly as
// F = ... + x_i b_i^T, b_i = row i - 1 of Dm^-1 (i = 1..3) and
// b_0 = -(b_1 + b_2 + b_3); so grad_i E = P b_i with P = dE/dF, and the
// block is H_i = (d^2 E / dF^2)[x b_i^T, x b_i^T].
//  - corotational, C_D = |F - R|, C_H = tr(R^T F) - 3:
//      P = (F - R) / alpha_D + C_H R / alpha_H (R's variation drops out, see
//      fem_math.h), and with R held fixed (the usual corotational
//      linearisation) H_i = |b_i|^2 / alpha_D I + (R b_i)(R b_i)^T / alpha_H:
//      positive semi-definite. (The exact block is softer in the tet's
//      rotation directions; the fixed-R block only shortens those steps.)
//  - neo_hookean, C_D = |F|, C_H = det F - gamma:
//      P = F / alpha_D + C_H cof F / alpha_H, and the block is exactly
//      H_i = |b_i|^2 / alpha_D I + (cof F b_i)(cof F b_i)^T / alpha_H:
//      det(F + u b_i^T) = det F (1 + b_i^T F^-1 u) is linear in u, so the
//      C_H d^2(det F) term of the Hessian vanishes in a vertex's own block,
//      and what is left is a sum of PSD terms (no projection needed).
#pragma once

#include "math/fem_math.h"

namespace sinew::kernels {
namespace vbd {

/// A vertex's accumulated step system: force f = -gradient [N] and the
/// symmetric Hessian [N/m] as (xx, yy, zz, xy, xz, yz).
template <class T>
struct VertexSystem {
  T f[3] = {T(0), T(0), T(0)};
  T h[6] = {T(0), T(0), T(0), T(0), T(0), T(0)};
};

/// b_i of corner `corner` (0..3) from Dm^-1 (see above).
template <class T>
inline void corner_weights(const fem::mat3<T>& dm_inv, int corner, T b[3]) {
  for (int k = 0; k < 3; ++k)
    b[k] = corner == 0 ? -(dm_inv.m[0][k] + dm_inv.m[1][k] + dm_inv.m[2][k]) : dm_inv.m[corner - 1][k];
}

/// Adds one tet's -grad_i E and H_i to `s`. [in] f: the tet's deformation
/// gradient; a: the matrix of the rank-one term (R for corotational, cof F
/// for neo_hookean); p: dE/dF [Pa m^3]; b: corner weights [1/m];
/// inv_alpha_d, inv_alpha_h: 1 / compliance [Pa m^3].
template <class T>
inline void add_tet(VertexSystem<T>& s, const fem::mat3<T>& a, const fem::mat3<T>& p, const T b[3], T inv_alpha_d,
                    T inv_alpha_h) {
  T ab[3], pb[3];
  for (int r = 0; r < 3; ++r) {
    ab[r] = a.m[r][0] * b[0] + a.m[r][1] * b[1] + a.m[r][2] * b[2];
    pb[r] = p.m[r][0] * b[0] + p.m[r][1] * b[1] + p.m[r][2] * b[2];
  }
  const T diagonal = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]) * inv_alpha_d;
  for (int r = 0; r < 3; ++r) s.f[r] -= pb[r];
  s.h[0] += diagonal + ab[0] * ab[0] * inv_alpha_h;
  s.h[1] += diagonal + ab[1] * ab[1] * inv_alpha_h;
  s.h[2] += diagonal + ab[2] * ab[2] * inv_alpha_h;
  s.h[3] += ab[0] * ab[1] * inv_alpha_h;
  s.h[4] += ab[0] * ab[2] * inv_alpha_h;
  s.h[5] += ab[1] * ab[2] * inv_alpha_h;
}

/// Corotational: P = (F - R) / alpha_D + (tr(R^T F) - h0) R / alpha_H.
template <class T>
inline fem::mat3<T> corotational_stress(const fem::mat3<T>& f, const fem::mat3<T>& r, T h0, T inv_alpha_d,
                                        T inv_alpha_h) {
  T trace = T(0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) trace += r.m[i][j] * f.m[i][j];
  const T c_h = (trace - h0) * inv_alpha_h;
  fem::mat3<T> p;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) p.m[i][j] = (f.m[i][j] - r.m[i][j]) * inv_alpha_d + c_h * r.m[i][j];
  return p;
}

/// Neo-Hookean: P = F / alpha_D + (det F - h0) cof F / alpha_H. [in] cof: cof F.
template <class T>
inline fem::mat3<T> neo_hookean_stress(const fem::mat3<T>& f, const fem::mat3<T>& cof, T h0, T inv_alpha_d,
                                       T inv_alpha_h) {
  const T c_h = (fem::determinant(f) - h0) * inv_alpha_h;
  fem::mat3<T> p;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) p.m[i][j] = f.m[i][j] * inv_alpha_d + c_h * cof.m[i][j];
  return p;
}

/// The step dx = H^-1 f by H's cofactors. Returns false (dx untouched) when
/// det H is not safely positive: H = m / h^2 I + PSD blocks is positive
/// definite in exact arithmetic, so that only happens when rounding or a
/// non-finite input broke it; the vertex then keeps its position (the
/// paper's skip of near-singular blocks) rather than take a wild step.
template <class T>
inline bool solve_step(const VertexSystem<T>& s, T dx[3]) {
  const T a = s.h[0], b = s.h[1], c = s.h[2], d = s.h[3], e = s.h[4], k = s.h[5];
  const T c00 = b * c - k * k, c01 = e * k - d * c, c02 = d * k - b * e;
  const T c11 = a * c - e * e, c12 = d * e - a * k, c22 = a * b - d * d;
  const T det = a * c00 + d * c01 + e * c02;
  // Relative to the product of the diagonal (>= det for an SPD matrix):
  // below 1e-10 of it the block is singular to float precision.
  if (!(det > T(1e-10) * a * b * c)) return false;
  const T inv_det = T(1) / det;
  const T x = (c00 * s.f[0] + c01 * s.f[1] + c02 * s.f[2]) * inv_det;
  const T y = (c01 * s.f[0] + c11 * s.f[1] + c12 * s.f[2]) * inv_det;
  const T z = (c02 * s.f[0] + c12 * s.f[1] + c22 * s.f[2]) * inv_det;
  if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z))) return false;
  dx[0] = x, dx[1] = y, dx[2] = z;
  return true;
}

}  // namespace vbd
}  // namespace sinew::kernels
