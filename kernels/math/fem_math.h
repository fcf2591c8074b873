// fem_math.h — the constraint functions of the FEM tet materials, used by
// the CPU reference kernels (kernels/cpu/fem_kernels.cpp; GPU twin:
// kernels/gpu/fem_math.h) and the tests. Templates: the kernels run them in
// float, the tests differentiate them in double. Keep every operation and
// its order (the library compiles with -ffp-contract=off).
//
// Each tet carries two constraints on its deformation gradient F = Ds Dm^-1,
// a deviatoric C_D and a hydrostatic C_H (data layout:
// kernels/shared/fem_params.h; models and compliances:
// include/sinew/scene.h, TetMaterial):
//  - Macklin, Müller, "A Constraint-based Formulation of Stable Neo-Hookean
//    Materials", MIG 2021: C_D = |F|_F, C_H = det F - gamma;
//  - St. Venant-Kirchhoff: C_D = |E|_F, E = (F^T F - I) / 2, C_H = det F - 1;
//  - corotational linear (Müller, Gross, "Interactive Virtual Materials",
//    GI 2004; inversion: Irving, Teran, Fedkiw, "Invertible Finite Elements
//    for Robust Simulation of Large Deformation", SCA 2004):
//    C_D = |F - R|_F, C_H = tr(R^T F) - 3, with R the rotation (det R = +1)
//    that maximises tr(R^T F), i.e. the polar rotation of F, whose smallest
//    singular direction is flipped when det F < 0.
// A constraint's gradient with respect to a vertex is taken through F:
// with G = dC/dF (3x3), grad_{x_i} C = column i of G Dm^-T for i = 1..3, and
// grad_{x_0} C = -(grad_1 + grad_2 + grad_3).
#pragma once

#include <cmath>
#include <limits>

#include "fem_params.h"
#include "math/vec4.h"

namespace sinew::kernels {
namespace fem {

/// A 3x3 matrix, m[row][column].
template <class T>
struct mat3 {
  T m[3][3];
};

template <class T>
inline T frobenius_norm(const mat3<T>& a) {
  T s = T(0);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) s += a.m[r][c] * a.m[r][c];
  return std::sqrt(s);
}

template <class T>
inline T determinant(const mat3<T>& a) {
  const auto& m = a.m;
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

/// The cofactor matrix cof F = d(det F)/dF: column k is the cross product
/// of the two other columns of F (cyclic), so that det F = f_k . cof_k.
template <class T>
inline mat3<T> cofactor(const mat3<T>& a) {
  const auto& m = a.m;
  mat3<T> c;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    // column k = f_i x f_j
    c.m[0][k] = m[1][i] * m[2][j] - m[2][i] * m[1][j];
    c.m[1][k] = m[2][i] * m[0][j] - m[0][i] * m[2][j];
    c.m[2][k] = m[0][i] * m[1][j] - m[1][i] * m[0][j];
  }
  return c;
}

/// F = Ds Dm^-1, Ds = [x1 - x0, x2 - x0, x3 - x0] (columns).
/// [in] dm_inv: the inverse of the rest edge matrix [1/m].
template <class T>
inline mat3<T> deformation_gradient(vec4<T> x0, vec4<T> x1, vec4<T> x2, vec4<T> x3, const mat3<T>& dm_inv) {
  const vec4<T> e1 = x1 - x0, e2 = x2 - x0, e3 = x3 - x0;
  const T ds[3][3] = {{e1.x, e2.x, e3.x}, {e1.y, e2.y, e3.y}, {e1.z, e2.z, e3.z}};
  mat3<T> f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      f.m[r][c] = ds[r][0] * dm_inv.m[0][c] + ds[r][1] * dm_inv.m[1][c] + ds[r][2] * dm_inv.m[2][c];
  return f;
}

/// [out] g[i] = grad_{x_i} C from G = dC/dF: column i of G Dm^-T
/// (component a: sum_b G[a][b] Dm^-1[i-1][b]), g[0] = -(g[1] + g[2] + g[3]).
template <class T>
inline void position_gradients(const mat3<T>& dc_df, const mat3<T>& dm_inv, vec4<T> g[4]) {
  for (int i = 1; i <= 3; ++i) {
    const T* d = dm_inv.m[i - 1];
    g[i] = vec4<T>{dc_df.m[0][0] * d[0] + dc_df.m[0][1] * d[1] + dc_df.m[0][2] * d[2],
                   dc_df.m[1][0] * d[0] + dc_df.m[1][1] * d[1] + dc_df.m[1][2] * d[2],
                   dc_df.m[2][0] * d[0] + dc_df.m[2][1] * d[1] + dc_df.m[2][2] * d[2], T(0)};
  }
  g[0] = vec4<T>{T(0), T(0), T(0), T(0)} - (g[1] + g[2] + g[3]);
}

/// A quaternion (w, x, y, z).
template <class T>
struct quat {
  T w, x, y, z;
};

/// The rotation R (det R = +1) maximising tr(R^T F) over all rotations:
/// the rotation of F's polar decomposition when det F > 0; when det F < 0,
/// the one whose R^T F = S is symmetric with its smallest-magnitude
/// eigenvalue negative (Irving et al. 2004), so C_H = tr S - 3 < 0 pushes
/// the tet back out. Horn, "Closed-form solution of absolute orientation
/// using unit quaternions", JOSA A 4(4), 1987: tr(R(q)^T F) = q^T N q for a
/// unit quaternion q and a symmetric 4x4 N built from F, so R is given by
/// N's eigenvector of largest eigenvalue, found here by cyclic Jacobi
/// (Golub, Van Loan, "Matrix Computations", 4th ed., section 8.5), which is
/// accurate to rounding even when F is singular. Ties (equal largest
/// eigenvalues, where R is not unique, e.g. F = 0 or a pure reflection) take
/// the first; F = 0 gives R = I. No allocation, a bounded number of sweeps.
template <class T>
inline quat<T> rotation_quaternion(const mat3<T>& f) {
  const auto& s = f.m;
  T n[4][4] = {
      {s[0][0] + s[1][1] + s[2][2], s[2][1] - s[1][2], s[0][2] - s[2][0], s[1][0] - s[0][1]},
      {s[2][1] - s[1][2], s[0][0] - s[1][1] - s[2][2], s[0][1] + s[1][0], s[0][2] + s[2][0]},
      {s[0][2] - s[2][0], s[0][1] + s[1][0], -s[0][0] + s[1][1] - s[2][2], s[1][2] + s[2][1]},
      {s[1][0] - s[0][1], s[0][2] + s[2][0], s[1][2] + s[2][1], -s[0][0] - s[1][1] + s[2][2]}};
  T v[4][4] = {{T(1), T(0), T(0), T(0)}, {T(0), T(1), T(0), T(0)}, {T(0), T(0), T(1), T(0)}, {T(0), T(0), T(0), T(1)}};
  const T eps = std::numeric_limits<T>::epsilon();
  for (int sweep = 0; sweep < 12; ++sweep) {
    T off = T(0), total = T(0);
    for (int p = 0; p < 4; ++p)
      for (int q = 0; q < 4; ++q) (p == q ? total : off) += n[p][q] * n[p][q];
    total += off;
    if (off <= eps * eps * total) break;  // also F = 0: total = 0
    for (int p = 0; p < 3; ++p)
      for (int q = p + 1; q < 4; ++q) {
        const T apq = n[p][q];
        if (apq == T(0)) continue;
        // The rotation J (c, s) with (J^T N J)[p][q] = 0: t = tan of its
        // angle, the smaller root of t^2 + 2 tau t - 1 = 0.
        const T tau = (n[q][q] - n[p][p]) / (T(2) * apq);
        const T t = (tau >= T(0) ? T(1) : T(-1)) / (std::abs(tau) + std::sqrt(T(1) + tau * tau));
        const T c = T(1) / std::sqrt(T(1) + t * t), sn = t * c;
        for (int k = 0; k < 4; ++k) {  // N J (columns p, q)
          const T kp = n[k][p], kq = n[k][q];
          n[k][p] = c * kp - sn * kq;
          n[k][q] = sn * kp + c * kq;
        }
        for (int k = 0; k < 4; ++k) {  // J^T (N J) (rows p, q)
          const T pk = n[p][k], qk = n[q][k];
          n[p][k] = c * pk - sn * qk;
          n[q][k] = sn * pk + c * qk;
        }
        n[p][q] = n[q][p] = T(0);
        for (int k = 0; k < 4; ++k) {  // V J
          const T kp = v[k][p], kq = v[k][q];
          v[k][p] = c * kp - sn * kq;
          v[k][q] = sn * kp + c * kq;
        }
      }
  }
  int best = 0;
  for (int k = 1; k < 4; ++k)
    if (n[k][k] > n[best][best]) best = k;
  T w = v[0][best], x = v[1][best], y = v[2][best], z = v[3][best];
  const T len = std::sqrt(w * w + x * x + y * y + z * z);  // 1 up to rounding
  w /= len, x /= len, y /= len, z /= len;
  return {w, x, y, z};
}

/// The rotation matrix of a unit quaternion (w, x, y, z).
template <class T>
inline mat3<T> quaternion_matrix(const quat<T>& q) {
  const T w = q.w, x = q.x, y = q.y, z = q.z;
  mat3<T> r;
  r.m[0][0] = T(1) - T(2) * (y * y + z * z);
  r.m[0][1] = T(2) * (x * y - w * z);
  r.m[0][2] = T(2) * (x * z + w * y);
  r.m[1][0] = T(2) * (x * y + w * z);
  r.m[1][1] = T(1) - T(2) * (x * x + z * z);
  r.m[1][2] = T(2) * (y * z - w * x);
  r.m[2][0] = T(2) * (x * z - w * y);
  r.m[2][1] = T(2) * (y * z + w * x);
  r.m[2][2] = T(1) - T(2) * (x * x + y * y);
  return r;
}

/// fem::rotation_quaternion as a matrix: the exact rotation (to rounding).
template <class T>
inline mat3<T> rotation_part(const mat3<T>& f) {
  return quaternion_matrix(rotation_quaternion(f));
}

/// Fixed iterations of the corotational rotation per solve (see refine_rotation).
inline constexpr int kRotationIterations = SINEW_FEM_ROTATION_ITERATIONS;

/// The rotation maximising tr(R^T F), refined from a guess q by Newton's
/// method on the rotation group, warm-started as in Müller, Bender,
/// Chentanez, Macklin, "A Robust Method to Extract the Rotational Part of
/// Deformations", MIG 2016. With S = R^T F, turning R by a small w (in R's
/// frame, R exp([w]x)) changes tr(R^T F) by g . w - w^T H w / 2 with
///   g = (S32 - S23, S13 - S31, S21 - S12),  H = tr(S) I - sym(S),
/// so each iteration turns by w = H^-1 g: quadratic convergence, where
/// Müller et al.'s step g / |tr S| converges linearly (by a factor ~1/3 per
/// iteration for an isotropic stretch; measured: 2 of their iterations
/// leave 2e-3 to 1e-2 rad behind a tet turning 0.01 rad per solve, one
/// Newton step 5e-7). Where H is not positive definite (far from the
/// maximiser, or an inverted tet with a large negative stretch) the step
/// falls back to Müller et al.'s. The turn is the quaternion (1, w / 2)
/// normalised, only +, -, *, /, sqrt, which every backend rounds alike.
/// Accuracy, measured in double against the exact rotation over 50 solves
/// of tets stretched by up to 50% and turning at a steady rate
/// (tests/fem_rotation_test.cpp checks these bounds): one iteration per
/// solve (kRotationIterations, the kernels' setting) lags 5e-7 rad behind
/// at 0.01 rad per solve, 5e-5 at 0.05, 3e-3 at 0.2; two iterations stay
/// within 1e-6 up to 0.2 rad per solve. A substep of 1 ms turning at
/// 10 rad/s is 0.01 rad per solve. An inverted tet follows its rotation
/// continuously, where the exact maximiser may jump (by pi when two of
/// its stretches swap). The guess must be a unit quaternion.
template <class T>
inline quat<T> refine_rotation(const mat3<T>& f, quat<T> q, int iterations) {
  for (int it = 0; it < iterations; ++it) {
    const mat3<T> r = quaternion_matrix(q);
    T s[3][3];  // R^T F
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s[i][j] = r.m[0][i] * f.m[0][j] + r.m[1][i] * f.m[1][j] + r.m[2][i] * f.m[2][j];
    const T gx = s[2][1] - s[1][2], gy = s[0][2] - s[2][0], gz = s[1][0] - s[0][1];
    const T tr = s[0][0] + s[1][1] + s[2][2];
    // H = [[a d e] [d b k] [e k c]], solved by its cofactors.
    const T a = tr - s[0][0], b = tr - s[1][1], c = tr - s[2][2];
    const T d = T(-0.5) * (s[0][1] + s[1][0]), e = T(-0.5) * (s[0][2] + s[2][0]), k = T(-0.5) * (s[1][2] + s[2][1]);
    const T c00 = b * c - k * k, c01 = e * k - d * c, c02 = d * k - b * e;
    const T c11 = a * c - e * e, c12 = d * e - a * k, c22 = a * b - d * d;
    const T det = a * c00 + d * c01 + e * c02;
    T wx, wy, wz;
    // Positive definite (Sylvester: a > 0, a b - d^2 > 0, det > 0), with
    // det well away from 0 relative to H's scale.
    if (a > T(0) && c22 > T(0) && det > T(1e-6) * a * c22 * (a + b + c)) {
      const T inv_det = T(1) / det;  // one division, not three (the cost is in the divisions)
      wx = (c00 * gx + c01 * gy + c02 * gz) * inv_det;
      wy = (c01 * gx + c11 * gy + c12 * gz) * inv_det;
      wz = (c02 * gx + c12 * gy + c22 * gz) * inv_det;
    } else {
      const T inv = T(1) / (std::abs(tr) + T(1e-9));
      wx = gx * inv, wy = gy * inv, wz = gz * inv;
    }
    const T hx = T(0.5) * wx, hy = T(0.5) * wy, hz = T(0.5) * wz;  // q * (1, w / 2)
    const T w = q.w - q.x * hx - q.y * hy - q.z * hz;
    const T x = q.x + q.w * hx + q.y * hz - q.z * hy;
    const T y = q.y + q.w * hy + q.z * hx - q.x * hz;
    const T z = q.z + q.w * hz + q.x * hy - q.y * hx;
    const T inv_len = T(1) / std::sqrt(w * w + x * x + y * y + z * z);
    q = {w * inv_len, x * inv_len, y * inv_len, z * inv_len};
  }
  return q;
}

/// The two constraints of a tet and their derivatives with respect to F.
template <class T>
struct TetConstraints {
  T c_d = T(0);  ///< deviatoric constraint value (dimensionless)
  T c_h = T(0);  ///< hydrostatic constraint value (dimensionless)
  mat3<T> dc_d;  ///< dC_D/dF (zero where C_D = 0 has no direction)
  mat3<T> dc_h;  ///< dC_H/dF
};

/// Stable Neo-Hookean: C_D = |F|_F, dC_D/dF = F / |F|_F (0 at F = 0);
/// C_H = det F - h0, dC_H/dF = cof F. [in] h0 = gamma = 1 + mu / lambda'.
template <class T>
inline TetConstraints<T> neo_hookean_constraints(const mat3<T>& f, T h0) {
  TetConstraints<T> c;
  c.c_d = frobenius_norm(f);
  const T inv = c.c_d > T(0) ? T(1) / c.c_d : T(0);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) c.dc_d.m[r][k] = f.m[r][k] * inv;
  c.c_h = determinant(f) - h0;
  c.dc_h = cofactor(f);
  return c;
}

/// St. Venant-Kirchhoff: C_D = |E|_F with E = (F^T F - I) / 2,
/// dC_D/dF = F E / |E|_F (0 at E = 0); C_H = det F - h0 (h0 = 1),
/// dC_H/dF = cof F.
template <class T>
inline TetConstraints<T> stvk_constraints(const mat3<T>& f, T h0) {
  TetConstraints<T> c;
  mat3<T> e;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      e.m[i][j] = T(0.5) * (f.m[0][i] * f.m[0][j] + f.m[1][i] * f.m[1][j] + f.m[2][i] * f.m[2][j] -
                            (i == j ? T(1) : T(0)));
  c.c_d = frobenius_norm(e);
  const T inv = c.c_d > T(0) ? T(1) / c.c_d : T(0);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      c.dc_d.m[r][k] = (f.m[r][0] * e.m[0][k] + f.m[r][1] * e.m[1][k] + f.m[r][2] * e.m[2][k]) * inv;
  c.c_h = determinant(f) - h0;
  c.dc_h = cofactor(f);
  return c;
}

/// Corotational linear with the rotation R of F (rotation_part, or
/// refine_rotation's in the kernels): C_D = |F - R|_F,
/// dC_D/dF = (F - R) / |F - R|_F (0 at F = R); C_H = tr(R^T F) - h0 (h0 = 3),
/// dC_H/dF = R. R's own variation drops out of both derivatives: R^T dR is
/// skew and R^T F symmetric (R maximises tr(R^T F)).
template <class T>
inline TetConstraints<T> corotational_constraints(const mat3<T>& f, const mat3<T>& r, T h0) {
  TetConstraints<T> c;
  mat3<T> d;
  T trace = T(0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      d.m[i][j] = f.m[i][j] - r.m[i][j];
      trace += r.m[i][j] * f.m[i][j];
    }
  c.c_d = frobenius_norm(d);
  const T inv = c.c_d > T(0) ? T(1) / c.c_d : T(0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.dc_d.m[i][j] = d.m[i][j] * inv;
  c.c_h = trace - h0;
  c.dc_h = r;
  return c;
}

/// Corotational linear with the exact rotation (rotation_part).
template <class T>
inline TetConstraints<T> corotational_constraints(const mat3<T>& f, T h0) {
  return corotational_constraints(f, rotation_part(f), h0);
}

}  // namespace fem
}  // namespace sinew::kernels
