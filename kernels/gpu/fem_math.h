/* fem_math.h — GPU twin of kernels/math/fem_math.h: the 3x3 matrix
 * helpers and the constraint functions of the FEM tet materials, and the
 * coupled 2x2 xPBD tet solve of kernels/cpu/fem_kernels.cpp (solve_tets),
 * shared by xpbd_solve_neo_hookean.gpu, xpbd_solve_stvk.gpu and
 * xpbd_solve_corotational.gpu.
 *  - Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of
 *    Compliant Constrained Dynamics", MIG 2016;
 *  - Macklin, Müller, "A Constraint-based Formulation of Stable Neo-Hookean
 *    Materials", MIG 2021: C_D = |F|_F, C_H = det F - gamma;
 *  - St. Venant-Kirchhoff: C_D = |E|_F, E = (F^T F - I) / 2, C_H = det F - 1;
 *  - corotational linear (Müller, Gross, "Interactive Virtual Materials",
 *    GI 2004; inversion: Irving, Teran, Fedkiw, "Invertible Finite Elements
 *    for Robust Simulation of Large Deformation", SCA 2004), with the
 *    rotation of Horn, "Closed-form solution of absolute orientation using
 *    unit quaternions", JOSA A 4(4), 1987, by cyclic Jacobi (Golub, Van
 *    Loan, "Matrix Computations", 4th ed., section 8.5).
 * Every operation in the CPU code's order and every arithmetic result
 * PRECISE (no fused multiply-add, and in GLSL no inexact rewrites such as
 * 1 / sqrt -> inversesqrt); sqrt and division correctly rounded as the
 * CPU's, so that the results are bitwise those of the CPU kernels. Matrices
 * are m[row][column] like fem::mat3 (not GLSL's column-major mat3).
 *
 * fem_solve_tet takes one tet's values and returns what to store: the
 * kernels read and write their buffers (helpers cannot reach them). */
#ifndef SINEW_FEM_MATH_H
#define SINEW_FEM_MATH_H

#include "vec_math.h"
#include "sinew_lang.h"
#include "fem_params.h"

SINEW_STRUCT_BEGIN(FemMat3)
  float m[3][3];
SINEW_STRUCT_END(FemMat3)

/* The two constraints of a tet and their derivatives with respect to F. */
SINEW_STRUCT_BEGIN(FemConstraints)
  float c_d;     /* deviatoric constraint value */
  float c_h;     /* hydrostatic constraint value */
  FemMat3 dc_d;  /* dC_D/dF */
  FemMat3 dc_h;  /* dC_H/dF */
SINEW_STRUCT_END(FemConstraints)

/* The gradients of one constraint with respect to the tet's four particles. */
SINEW_STRUCT_BEGIN(FemGradients)
  float3 g[4];
SINEW_STRUCT_END(FemGradients)

/* A quaternion (w, x, y, z). */
SINEW_STRUCT_BEGIN(FemQuat)
  float w;
  float x;
  float y;
  float z;
SINEW_STRUCT_END(FemQuat)

/* What one tet's solve stores: the residual (measuring pass), or the new
 * multipliers and, where moved, the new positions of the movable
 * particles (x[k] is set only where xs[k].w > 0), and for corotational
 * tets the rotation to keep (fem_params.h). */
SINEW_STRUCT_BEGIN(FemTetStep)
  float residual;
  float lambda_d;
  float lambda_h;
  bool moved;
  float4 x[4];
  FemQuat rotation;  /* corotational: the tet's rotation to keep */
SINEW_STRUCT_END(FemTetStep)

PRECISE float fem_frobenius_norm(FemMat3 a) {
  PRECISE float s = 0.0f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) s += a.m[r][c] * a.m[r][c];
  PRECISE float norm = sqrt(s);
  return norm;
}

PRECISE float fem_determinant(FemMat3 a) {
  return a.m[0][0] * (a.m[1][1] * a.m[2][2] - a.m[1][2] * a.m[2][1]) -
         a.m[0][1] * (a.m[1][0] * a.m[2][2] - a.m[1][2] * a.m[2][0]) +
         a.m[0][2] * (a.m[1][0] * a.m[2][1] - a.m[1][1] * a.m[2][0]);
}

/* cof F = d(det F)/dF: column k is the cross product of the two other
 * columns of F (cyclic). */
FemMat3 fem_cofactor(FemMat3 a) {
  PRECISE FemMat3 c;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    c.m[0][k] = a.m[1][i] * a.m[2][j] - a.m[2][i] * a.m[1][j];
    c.m[1][k] = a.m[2][i] * a.m[0][j] - a.m[0][i] * a.m[2][j];
    c.m[2][k] = a.m[0][i] * a.m[1][j] - a.m[1][i] * a.m[0][j];
  }
  return c;
}

/* F = Ds Dm^-1, Ds = [x1 - x0, x2 - x0, x3 - x0] (columns). */
FemMat3 fem_deformation_gradient(float4 x0, float4 x1, float4 x2, float4 x3, FemMat3 dm_inv) {
  PRECISE float3 e1 = x1.xyz - x0.xyz, e2 = x2.xyz - x0.xyz, e3 = x3.xyz - x0.xyz;
  const float ds[3][3] = {{e1.x, e2.x, e3.x}, {e1.y, e2.y, e3.y}, {e1.z, e2.z, e3.z}};
  PRECISE FemMat3 f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      f.m[r][c] = ds[r][0] * dm_inv.m[0][c] + ds[r][1] * dm_inv.m[1][c] + ds[r][2] * dm_inv.m[2][c];
  return f;
}

/* g[i] = grad_{x_i} C from G = dC/dF: column i of G Dm^-T,
 * g[0] = -(g[1] + g[2] + g[3]). */
FemGradients fem_position_gradients(FemMat3 g_f, FemMat3 dm_inv) {
  PRECISE float3 r[4];
  for (int i = 1; i <= 3; ++i) {
    const float d0 = dm_inv.m[i - 1][0], d1 = dm_inv.m[i - 1][1], d2 = dm_inv.m[i - 1][2];
    r[i] = make_float3(g_f.m[0][0] * d0 + g_f.m[0][1] * d1 + g_f.m[0][2] * d2,
                       g_f.m[1][0] * d0 + g_f.m[1][1] * d1 + g_f.m[1][2] * d2,
                       g_f.m[2][0] * d0 + g_f.m[2][1] * d1 + g_f.m[2][2] * d2);
  }
  r[0] = make_float3(0.0f, 0.0f, 0.0f) - (r[1] + r[2] + r[3]);
  FemGradients g;
  for (int i = 0; i < 4; ++i) g.g[i] = r[i];
  return g;
}

/* No rotation kept (neo_hookean and stvk tets keep none). */
FemQuat fem_no_rotation() {
  FemQuat q;
  q.w = 0.0f;
  q.x = 0.0f;
  q.y = 0.0f;
  q.z = 0.0f;
  return q;
}

/* The rotation R (det R = +1) maximising tr(R^T F): Horn's quaternion
 * matrix N, whose eigenvector of largest eigenvalue is R's quaternion, by
 * cyclic Jacobi (at most 12 sweeps); ties take the first; F = 0 gives I.
 * Twin of fem::rotation_quaternion. */
FemQuat fem_rotation_quaternion(FemMat3 f) {
  PRECISE float n[4][4];
  n[0][0] = f.m[0][0] + f.m[1][1] + f.m[2][2];
  n[0][1] = f.m[2][1] - f.m[1][2];
  n[0][2] = f.m[0][2] - f.m[2][0];
  n[0][3] = f.m[1][0] - f.m[0][1];
  n[1][0] = f.m[2][1] - f.m[1][2];
  n[1][1] = f.m[0][0] - f.m[1][1] - f.m[2][2];
  n[1][2] = f.m[0][1] + f.m[1][0];
  n[1][3] = f.m[0][2] + f.m[2][0];
  n[2][0] = f.m[0][2] - f.m[2][0];
  n[2][1] = f.m[0][1] + f.m[1][0];
  n[2][2] = -f.m[0][0] + f.m[1][1] - f.m[2][2];
  n[2][3] = f.m[1][2] + f.m[2][1];
  n[3][0] = f.m[1][0] - f.m[0][1];
  n[3][1] = f.m[0][2] + f.m[2][0];
  n[3][2] = f.m[1][2] + f.m[2][1];
  n[3][3] = -f.m[0][0] - f.m[1][1] + f.m[2][2];
  PRECISE float v[4][4] = {{1.0f, 0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f, 0.0f},
                           {0.0f, 0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f}};
  const float eps = 1.1920928955078125e-7f;  // FLT_EPSILON = 2^-23, as std::numeric_limits<float>::epsilon()
  PRECISE float eps2 = eps * eps;
  for (int sweep = 0; sweep < 12; ++sweep) {
    PRECISE float off = 0.0f, total = 0.0f;
    for (int p = 0; p < 4; ++p)
      for (int q = 0; q < 4; ++q) {
        if (p == q)
          total += n[p][q] * n[p][q];
        else
          off += n[p][q] * n[p][q];
      }
    total += off;
    PRECISE float bound = eps2 * total;
    if (off <= bound) break;  // also F = 0: total = 0
    for (int p = 0; p < 3; ++p)
      for (int q = p + 1; q < 4; ++q) {
        const float apq = n[p][q];
        if (apq == 0.0f) continue;
        // The rotation J (c, s) with (J^T N J)[p][q] = 0: t = tan of its
        // angle, the smaller root of t^2 + 2 tau t - 1 = 0.
        PRECISE float tau = (n[q][q] - n[p][p]) / (2.0f * apq);
        PRECISE float t = (tau >= 0.0f ? 1.0f : -1.0f) / (fabs(tau) + sqrt(1.0f + tau * tau));
        PRECISE float c = 1.0f / sqrt(1.0f + t * t);
        PRECISE float sn = t * c;
        for (int k = 0; k < 4; ++k) {  // N J (columns p, q)
          const float kp = n[k][p], kq = n[k][q];
          n[k][p] = c * kp - sn * kq;
          n[k][q] = sn * kp + c * kq;
        }
        for (int k = 0; k < 4; ++k) {  // J^T (N J) (rows p, q)
          const float pk = n[p][k], qk = n[q][k];
          n[p][k] = c * pk - sn * qk;
          n[q][k] = sn * pk + c * qk;
        }
        n[p][q] = 0.0f;
        n[q][p] = 0.0f;
        for (int k = 0; k < 4; ++k) {  // V J
          const float kp = v[k][p], kq = v[k][q];
          v[k][p] = c * kp - sn * kq;
          v[k][q] = sn * kp + c * kq;
        }
      }
  }
  int best = 0;
  for (int k = 1; k < 4; ++k)
    if (n[k][k] > n[best][best]) best = k;
  PRECISE float w = v[0][best], x = v[1][best], y = v[2][best], z = v[3][best];
  PRECISE float len = sqrt(w * w + x * x + y * y + z * z);  // 1 up to rounding
  PRECISE FemQuat q;
  q.w = w / len;
  q.x = x / len;
  q.y = y / len;
  q.z = z / len;
  return q;
}

/* The rotation matrix of a unit quaternion. Twin of fem::quaternion_matrix. */
FemMat3 fem_quaternion_matrix(FemQuat q) {
  const float w = q.w, x = q.x, y = q.y, z = q.z;
  PRECISE FemMat3 r;
  r.m[0][0] = 1.0f - 2.0f * (y * y + z * z);
  r.m[0][1] = 2.0f * (x * y - w * z);
  r.m[0][2] = 2.0f * (x * z + w * y);
  r.m[1][0] = 2.0f * (x * y + w * z);
  r.m[1][1] = 1.0f - 2.0f * (x * x + z * z);
  r.m[1][2] = 2.0f * (y * z - w * x);
  r.m[2][0] = 2.0f * (x * z - w * y);
  r.m[2][1] = 2.0f * (y * z + w * x);
  r.m[2][2] = 1.0f - 2.0f * (x * x + y * y);
  return r;
}

/* The rotation refined from a unit quaternion guess by `iterations`
 * Newton steps on the rotation group, falling back to the step of Müller,
 * Bender, Chentanez, Macklin, "A Robust Method to Extract the Rotational
 * Part of Deformations", MIG 2016, where the Hessian is not positive
 * definite. Twin of fem::refine_rotation (see there). */
FemQuat fem_refine_rotation(FemMat3 f, FemQuat q, int iterations) {
  for (int it = 0; it < iterations; ++it) {
    const FemMat3 r = fem_quaternion_matrix(q);
    PRECISE float s[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s[i][j] = r.m[0][i] * f.m[0][j] + r.m[1][i] * f.m[1][j] + r.m[2][i] * f.m[2][j];
    PRECISE float gx = s[2][1] - s[1][2], gy = s[0][2] - s[2][0], gz = s[1][0] - s[0][1];
    PRECISE float tr = s[0][0] + s[1][1] + s[2][2];
    PRECISE float a = tr - s[0][0], b = tr - s[1][1], c = tr - s[2][2];
    PRECISE float d = -0.5f * (s[0][1] + s[1][0]), e = -0.5f * (s[0][2] + s[2][0]), k = -0.5f * (s[1][2] + s[2][1]);
    PRECISE float c00 = b * c - k * k, c01 = e * k - d * c, c02 = d * k - b * e;
    PRECISE float c11 = a * c - e * e, c12 = d * e - a * k, c22 = a * b - d * d;
    PRECISE float det = a * c00 + d * c01 + e * c02;
    PRECISE float wx, wy, wz;
    PRECISE float bound = 1e-6f * a * c22 * (a + b + c);
    if (a > 0.0f && c22 > 0.0f && det > bound) {
      PRECISE float inv_det = 1.0f / det;
      wx = (c00 * gx + c01 * gy + c02 * gz) * inv_det;
      wy = (c01 * gx + c11 * gy + c12 * gz) * inv_det;
      wz = (c02 * gx + c12 * gy + c22 * gz) * inv_det;
    } else {
      PRECISE float inv = 1.0f / (fabs(tr) + 1e-9f);
      wx = gx * inv;
      wy = gy * inv;
      wz = gz * inv;
    }
    PRECISE float hx = 0.5f * wx, hy = 0.5f * wy, hz = 0.5f * wz;
    PRECISE float w = q.w - q.x * hx - q.y * hy - q.z * hz;
    PRECISE float x = q.x + q.w * hx + q.y * hz - q.z * hy;
    PRECISE float y = q.y + q.w * hy + q.z * hx - q.x * hz;
    PRECISE float z = q.z + q.w * hz + q.x * hy - q.y * hx;
    PRECISE float inv_len = 1.0f / sqrt(w * w + x * x + y * y + z * z);
    q.w = w * inv_len;
    q.x = x * inv_len;
    q.y = y * inv_len;
    q.z = z * inv_len;
  }
  return q;
}

/* Stable Neo-Hookean (Macklin, Müller 2021): C_D = |F|_F, dC_D/dF = F / |F|_F
 * (0 at F = 0); C_H = det F - h0, dC_H/dF = cof F. */
FemConstraints fem_neo_hookean_constraints(FemMat3 f, float h0) {
  PRECISE FemConstraints c;
  c.c_d = fem_frobenius_norm(f);
  PRECISE float inv = c.c_d > 0.0f ? 1.0f / c.c_d : 0.0f;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) c.dc_d.m[r][k] = f.m[r][k] * inv;
  c.c_h = fem_determinant(f) - h0;
  c.dc_h = fem_cofactor(f);
  return c;
}

/* St. Venant-Kirchhoff: C_D = |E|_F, E = (F^T F - I) / 2, dC_D/dF = F E / |E|_F
 * (0 at E = 0); C_H = det F - h0 (h0 = 1), dC_H/dF = cof F. */
FemConstraints fem_stvk_constraints(FemMat3 f, float h0) {
  PRECISE FemConstraints c;
  PRECISE FemMat3 e;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      e.m[i][j] = 0.5f * (f.m[0][i] * f.m[0][j] + f.m[1][i] * f.m[1][j] + f.m[2][i] * f.m[2][j] -
                          (i == j ? 1.0f : 0.0f));
  c.c_d = fem_frobenius_norm(e);
  PRECISE float inv = c.c_d > 0.0f ? 1.0f / c.c_d : 0.0f;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      c.dc_d.m[r][k] = (f.m[r][0] * e.m[0][k] + f.m[r][1] * e.m[1][k] + f.m[r][2] * e.m[2][k]) * inv;
  c.c_h = fem_determinant(f) - h0;
  c.dc_h = fem_cofactor(f);
  return c;
}

/* Corotational linear with the rotation R of F: C_D = |F - R|_F,
 * dC_D/dF = (F - R) / |F - R|_F (0 at F = R); C_H = tr(R^T F) - h0 (h0 = 3),
 * dC_H/dF = R. */
FemConstraints fem_corotational_constraints(FemMat3 f, FemMat3 r, float h0) {
  PRECISE FemConstraints c;
  PRECISE FemMat3 d;
  PRECISE float trace = 0.0f;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      d.m[i][j] = f.m[i][j] - r.m[i][j];
      trace += r.m[i][j] * f.m[i][j];
    }
  c.c_d = fem_frobenius_norm(d);
  PRECISE float inv = c.c_d > 0.0f ? 1.0f / c.c_d : 0.0f;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.dc_d.m[i][j] = d.m[i][j] * inv;
  c.c_h = trace - h0;
  c.dc_h = r;
  return c;
}

#define FEM_MODEL_NEO_HOOKEAN 0
#define FEM_MODEL_STVK 1
#define FEM_MODEL_COROTATIONAL 2

/* One tet's two constraints solved together as one 2x2 xPBD system in the
 * W-orthogonal basis (a, b' = b - beta a) of fem_kernels.cpp: see there for
 * the derivation, the scaling and the guards, all reproduced here. xs: the
 * tet's particles; d: its SINEW_FEM_DATA_STRIDE words of data; ld, lh: its
 * multipliers at the start of the sweep (0 when reset). */
FemTetStep fem_solve_tet(int model, const float4 xs[4], const float d[SINEW_FEM_DATA_STRIDE], float ld, float lh,
                         float inv_h2, bool measure_only, FemQuat kept) {
  FemTetStep s;
  s.rotation = kept;
  s.residual = 0.0f;
  s.lambda_d = ld;
  s.lambda_h = lh;
  s.moved = false;
  FemMat3 dm_inv;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) dm_inv.m[r][c] = d[SINEW_FEM_DM_INV + 3 * r + c];
  const FemMat3 f = fem_deformation_gradient(xs[0], xs[1], xs[2], xs[3], dm_inv);
  const float h0 = d[SINEW_FEM_H0];
  FemConstraints c;
  if (model == FEM_MODEL_NEO_HOOKEAN)
    c = fem_neo_hookean_constraints(f, h0);
  else if (model == FEM_MODEL_STVK)
    c = fem_stvk_constraints(f, h0);
  else {
    // The exact rotation on the first solve (nothing kept yet), then a few
    // iterations from the kept one (fem_kernels.cpp).
    FemQuat q = kept;
    if (q.w == 0.0f && q.x == 0.0f && q.y == 0.0f && q.z == 0.0f) q = fem_rotation_quaternion(f);
    q = fem_refine_rotation(f, q, SINEW_FEM_ROTATION_ITERATIONS);
    s.rotation = q;
    c = fem_corotational_constraints(f, fem_quaternion_matrix(q), h0);
  }

  PRECISE float ad = d[SINEW_FEM_ALPHA_D] * inv_h2, ah = d[SINEW_FEM_ALPHA_H] * inv_h2;
  PRECISE float rd = c.c_d + ad * ld, rh = c.c_h + ah * lh;
  if (measure_only) {
    PRECISE float r = sqrt(rd * rd + rh * rh);
    s.residual = r;
    return s;
  }

  const FemGradients a = fem_position_gradients(c.dc_d, dm_inv);
  FemGradients b = fem_position_gradients(c.dc_h, dm_inv);
  PRECISE float aa = 0.0f, ab = 0.0f;
  for (int k = 0; k < 4; ++k) {
    aa += xs[k].w * dot3(a.g[k], a.g[k]);
    ab += xs[k].w * dot3(a.g[k], b.g[k]);
  }
  PRECISE float beta = aa > 0.0f ? ab / aa : 0.0f;
  PRECISE float bb = 0.0f;  // <b', b'>_W
  for (int k = 0; k < 4; ++k) {
    PRECISE float3 bk = b.g[k] - beta * a.g[k];
    b.g[k] = bk;
    bb += xs[k].w * dot3(bk, bk);
  }
  // Scaled by 1 / (sum of the diagonal terms) against float overflow.
  PRECISE float total = aa + bb + ad + ah;
  // total == 0 or not finite (or det == 0 below): no direction to push
  // along. isnan spelled out, so no compiler may turn !(x > 0) into x <= 0.
  if (!(total > 0.0f) || isnan(total) || isinf(total)) return s;
  PRECISE float scale = 1.0f / total;
  PRECISE float saa = scale * aa, sbb = scale * bb, sad = scale * ad, sah = scale * ah;
  PRECISE float m11 = saa + sad, m12 = -beta * sad, m22 = sbb + beta * beta * sad + sah;
  PRECISE float det = saa * sbb + saa * (beta * beta * sad + sah) + sad * sbb + sad * sah;
  if (!(det > 0.0f) || isnan(det)) return s;
  PRECISE float rhs1 = -scale * rd, rhs2 = -scale * (rh - beta * rd);
  PRECISE float mu1 = (m22 * rhs1 - m12 * rhs2) / det;
  PRECISE float mu2 = (m11 * rhs2 - m12 * rhs1) / det;
  s.moved = true;
  for (int k = 0; k < 4; ++k) {
    if (xs[k].w > 0.0f) {
      PRECISE float3 dx = mu1 * a.g[k] + mu2 * b.g[k];
      PRECISE float3 y = xs[k].xyz + xs[k].w * dx;
      s.x[k] = make_float4_xyz(y, xs[k].w);
    }
  }
  PRECISE float ld_n = ld + (mu1 - beta * mu2), lh_n = lh + mu2;
  s.lambda_d = ld_n;
  s.lambda_h = lh_n;
  return s;
}

#endif /* SINEW_FEM_MATH_H */
