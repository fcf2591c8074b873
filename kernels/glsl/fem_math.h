/* fem_math.h — GLSL twin of kernels/cpu/fem_kernels.h: the 3x3 matrix
 * helpers and the constraint functions of the FEM tet materials, and the
 * coupled 2x2 xPBD tet solve of kernels/cpu/fem_kernels.cpp (solve_tets),
 * shared by xpbd_solve_neo_hookean.comp, xpbd_solve_stvk.comp and
 * xpbd_solve_corotational.comp (and like kernels/opencl/fem_math.h).
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
 * `precise` (SPIR-V NoContraction: no fused multiply-add, no inexact
 * rewrites such as 1 / sqrt -> inversesqrt), so that the results are those
 * of the CPU kernels. Matrices are m[row][column] like fem::mat3 (not GLSL's
 * column-major mat3).
 *
 * fem_solve_tet reads and writes the kernel's buffers: the including .comp
 * declares them first, as x (binding 0, vec4), idx (1, uvec4), fem_data
 * (2, float), lambda (3, float), residual (4, float), and the push
 * constant p (SolveParams). */
#ifndef SINEW_FEM_MATH_H
#define SINEW_FEM_MATH_H

#include "fem_params.h"
#include "glsl_math.h"

struct FemMat3 {
  float m[3][3];
};

/* The two constraints of a tet and their derivatives with respect to F. */
struct FemConstraints {
  float c_d;     /* deviatoric constraint value */
  float c_h;     /* hydrostatic constraint value */
  FemMat3 dc_d;  /* dC_D/dF */
  FemMat3 dc_h;  /* dC_H/dF */
};

precise float fem_frobenius_norm(FemMat3 a) {
  precise float s = 0.0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) s += a.m[r][c] * a.m[r][c];
  precise float norm = sqrt(s);
  return norm;
}

precise float fem_determinant(FemMat3 a) {
  return a.m[0][0] * (a.m[1][1] * a.m[2][2] - a.m[1][2] * a.m[2][1]) -
         a.m[0][1] * (a.m[1][0] * a.m[2][2] - a.m[1][2] * a.m[2][0]) +
         a.m[0][2] * (a.m[1][0] * a.m[2][1] - a.m[1][1] * a.m[2][0]);
}

/* cof F = d(det F)/dF: column k is the cross product of the two other
 * columns of F (cyclic). */
FemMat3 fem_cofactor(FemMat3 a) {
  precise FemMat3 c;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    c.m[0][k] = a.m[1][i] * a.m[2][j] - a.m[2][i] * a.m[1][j];
    c.m[1][k] = a.m[2][i] * a.m[0][j] - a.m[0][i] * a.m[2][j];
    c.m[2][k] = a.m[0][i] * a.m[1][j] - a.m[1][i] * a.m[0][j];
  }
  return c;
}

/* F = Ds Dm^-1, Ds = [x1 - x0, x2 - x0, x3 - x0] (columns). */
FemMat3 fem_deformation_gradient(vec4 x0, vec4 x1, vec4 x2, vec4 x3, FemMat3 dm_inv) {
  precise vec3 e1 = x1.xyz - x0.xyz, e2 = x2.xyz - x0.xyz, e3 = x3.xyz - x0.xyz;
  const float ds[3][3] = float[3][3](float[3](e1.x, e2.x, e3.x), float[3](e1.y, e2.y, e3.y), float[3](e1.z, e2.z, e3.z));
  precise FemMat3 f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      f.m[r][c] = ds[r][0] * dm_inv.m[0][c] + ds[r][1] * dm_inv.m[1][c] + ds[r][2] * dm_inv.m[2][c];
  return f;
}

/* g[i] = grad_{x_i} C from G = dC/dF: column i of G Dm^-T,
 * g[0] = -(g[1] + g[2] + g[3]). */
void fem_position_gradients(FemMat3 g_f, FemMat3 dm_inv, out vec3 g[4]) {
  precise vec3 r[4];
  for (int i = 1; i <= 3; ++i) {
    const float d0 = dm_inv.m[i - 1][0], d1 = dm_inv.m[i - 1][1], d2 = dm_inv.m[i - 1][2];
    r[i] = vec3(g_f.m[0][0] * d0 + g_f.m[0][1] * d1 + g_f.m[0][2] * d2,
                g_f.m[1][0] * d0 + g_f.m[1][1] * d1 + g_f.m[1][2] * d2,
                g_f.m[2][0] * d0 + g_f.m[2][1] * d1 + g_f.m[2][2] * d2);
  }
  r[0] = vec3(0.0) - ((r[1] + r[2]) + r[3]);
  g = r;
}

/* The rotation R (det R = +1) maximising tr(R^T F): Horn's quaternion
 * matrix N, whose eigenvector of largest eigenvalue is R's quaternion, by
 * cyclic Jacobi (at most 12 sweeps); ties take the first; F = 0 gives I.
 * Twin of fem::rotation_part. */
FemMat3 fem_rotation_part(FemMat3 f) {
  precise float n[4][4];
  n[0][0] = (f.m[0][0] + f.m[1][1]) + f.m[2][2];
  n[0][1] = f.m[2][1] - f.m[1][2];
  n[0][2] = f.m[0][2] - f.m[2][0];
  n[0][3] = f.m[1][0] - f.m[0][1];
  n[1][0] = f.m[2][1] - f.m[1][2];
  n[1][1] = (f.m[0][0] - f.m[1][1]) - f.m[2][2];
  n[1][2] = f.m[0][1] + f.m[1][0];
  n[1][3] = f.m[0][2] + f.m[2][0];
  n[2][0] = f.m[0][2] - f.m[2][0];
  n[2][1] = f.m[0][1] + f.m[1][0];
  n[2][2] = (-f.m[0][0] + f.m[1][1]) - f.m[2][2];
  n[2][3] = f.m[1][2] + f.m[2][1];
  n[3][0] = f.m[1][0] - f.m[0][1];
  n[3][1] = f.m[0][2] + f.m[2][0];
  n[3][2] = f.m[1][2] + f.m[2][1];
  n[3][3] = (-f.m[0][0] - f.m[1][1]) + f.m[2][2];
  precise float v[4][4] = float[4][4](float[4](1.0, 0.0, 0.0, 0.0), float[4](0.0, 1.0, 0.0, 0.0),
                                      float[4](0.0, 0.0, 1.0, 0.0), float[4](0.0, 0.0, 0.0, 1.0));
  const float eps = 1.1920928955078125e-7;  // FLT_EPSILON = 2^-23, as std::numeric_limits<float>::epsilon()
  precise float eps2 = eps * eps;
  for (int sweep = 0; sweep < 12; ++sweep) {
    precise float off = 0.0, total = 0.0;
    for (int p = 0; p < 4; ++p)
      for (int q = 0; q < 4; ++q) {
        if (p == q)
          total += n[p][q] * n[p][q];
        else
          off += n[p][q] * n[p][q];
      }
    total += off;
    precise float bound = eps2 * total;
    if (off <= bound) break;  // also F = 0: total = 0
    for (int p = 0; p < 3; ++p)
      for (int q = p + 1; q < 4; ++q) {
        const float apq = n[p][q];
        if (apq == 0.0) continue;
        // The rotation J (c, s) with (J^T N J)[p][q] = 0: t = tan of its
        // angle, the smaller root of t^2 + 2 tau t - 1 = 0.
        precise float tau = (n[q][q] - n[p][p]) / (2.0 * apq);
        precise float t = (tau >= 0.0 ? 1.0 : -1.0) / (abs(tau) + sqrt(1.0 + tau * tau));
        precise float c = 1.0 / sqrt(1.0 + t * t);
        precise float sn = t * c;
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
        n[p][q] = 0.0;
        n[q][p] = 0.0;
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
  precise float w = v[0][best], x = v[1][best], y = v[2][best], z = v[3][best];
  precise float len = sqrt(((w * w + x * x) + y * y) + z * z);  // 1 up to rounding
  w = w / len;
  x = x / len;
  y = y / len;
  z = z / len;
  precise FemMat3 r;
  r.m[0][0] = 1.0 - 2.0 * (y * y + z * z);
  r.m[0][1] = 2.0 * (x * y - w * z);
  r.m[0][2] = 2.0 * (x * z + w * y);
  r.m[1][0] = 2.0 * (x * y + w * z);
  r.m[1][1] = 1.0 - 2.0 * (x * x + z * z);
  r.m[1][2] = 2.0 * (y * z - w * x);
  r.m[2][0] = 2.0 * (x * z - w * y);
  r.m[2][1] = 2.0 * (y * z + w * x);
  r.m[2][2] = 1.0 - 2.0 * (x * x + y * y);
  return r;
}

/* Stable Neo-Hookean (Macklin, Müller 2021): C_D = |F|_F, dC_D/dF = F / |F|_F
 * (0 at F = 0); C_H = det F - h0, dC_H/dF = cof F. */
FemConstraints fem_neo_hookean_constraints(FemMat3 f, float h0) {
  precise FemConstraints c;
  c.c_d = fem_frobenius_norm(f);
  precise float inv = c.c_d > 0.0 ? 1.0 / c.c_d : 0.0;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) c.dc_d.m[r][k] = f.m[r][k] * inv;
  c.c_h = fem_determinant(f) - h0;
  c.dc_h = fem_cofactor(f);
  return c;
}

/* St. Venant-Kirchhoff: C_D = |E|_F, E = (F^T F - I) / 2, dC_D/dF = F E / |E|_F
 * (0 at E = 0); C_H = det F - h0 (h0 = 1), dC_H/dF = cof F. */
FemConstraints fem_stvk_constraints(FemMat3 f, float h0) {
  precise FemConstraints c;
  precise FemMat3 e;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      e.m[i][j] = 0.5 * (((f.m[0][i] * f.m[0][j] + f.m[1][i] * f.m[1][j]) + f.m[2][i] * f.m[2][j]) -
                         (i == j ? 1.0 : 0.0));
  c.c_d = fem_frobenius_norm(e);
  precise float inv = c.c_d > 0.0 ? 1.0 / c.c_d : 0.0;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      c.dc_d.m[r][k] = ((f.m[r][0] * e.m[0][k] + f.m[r][1] * e.m[1][k]) + f.m[r][2] * e.m[2][k]) * inv;
  c.c_h = fem_determinant(f) - h0;
  c.dc_h = fem_cofactor(f);
  return c;
}

/* Corotational linear: R = rotation_part(F), C_D = |F - R|_F,
 * dC_D/dF = (F - R) / |F - R|_F (0 at F = R); C_H = tr(R^T F) - h0 (h0 = 3),
 * dC_H/dF = R. */
FemConstraints fem_corotational_constraints(FemMat3 f, float h0) {
  precise FemConstraints c;
  const FemMat3 r = fem_rotation_part(f);
  precise FemMat3 d;
  precise float trace = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      d.m[i][j] = f.m[i][j] - r.m[i][j];
      trace += r.m[i][j] * f.m[i][j];
    }
  c.c_d = fem_frobenius_norm(d);
  precise float inv = c.c_d > 0.0 ? 1.0 / c.c_d : 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.dc_d.m[i][j] = d.m[i][j] * inv;
  c.c_h = trace - h0;
  c.dc_h = r;
  return c;
}

const int FEM_MODEL_NEO_HOOKEAN = 0;
const int FEM_MODEL_STVK = 1;
const int FEM_MODEL_COROTATIONAL = 2;

/* One tet's two constraints solved together as one 2x2 xPBD system in the
 * W-orthogonal basis (a, b' = b - beta a) of fem_kernels.cpp: see there for
 * the derivation, the scaling and the guards, all reproduced here. */
void fem_solve_tet(const int model, const uint i) {
  const uvec4 t = idx[i];
  const uint d = i * SINEW_FEM_DATA_STRIDE;
  FemMat3 dm_inv;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) dm_inv.m[r][c] = fem_data[d + SINEW_FEM_DM_INV + 3 * r + c];
  const vec4 xs[4] = vec4[4](x[t.x], x[t.y], x[t.z], x[t.w]);
  const FemMat3 f = fem_deformation_gradient(xs[0], xs[1], xs[2], xs[3], dm_inv);
  const float h0 = fem_data[d + SINEW_FEM_H0];
  FemConstraints c;
  if (model == FEM_MODEL_NEO_HOOKEAN)
    c = fem_neo_hookean_constraints(f, h0);
  else if (model == FEM_MODEL_STVK)
    c = fem_stvk_constraints(f, h0);
  else
    c = fem_corotational_constraints(f, h0);

  precise float ad = fem_data[d + SINEW_FEM_ALPHA_D] * p.inv_h2, ah = fem_data[d + SINEW_FEM_ALPHA_H] * p.inv_h2;
  const uint l = i * SINEW_FEM_LAMBDA_STRIDE;
  const float ld = p.reset_lambda != 0u ? 0.0 : lambda[l], lh = p.reset_lambda != 0u ? 0.0 : lambda[l + 1];
  precise float rd = c.c_d + ad * ld, rh = c.c_h + ah * lh;
  if (p.measure_only != 0u) {
    precise float r = sqrt(rd * rd + rh * rh);
    residual[i] = r;
    return;
  }

  vec3 a[4], b[4];
  fem_position_gradients(c.dc_d, dm_inv, a);
  fem_position_gradients(c.dc_h, dm_inv, b);
  precise float aa = 0.0, ab = 0.0;
  for (int k = 0; k < 4; ++k) {
    aa += xs[k].w * dot3(a[k], a[k]);
    ab += xs[k].w * dot3(a[k], b[k]);
  }
  precise float beta = aa > 0.0 ? ab / aa : 0.0;
  precise float bb = 0.0;  // <b', b'>_W
  for (int k = 0; k < 4; ++k) {
    precise vec3 bk = b[k] - beta * a[k];
    b[k] = bk;
    bb += xs[k].w * dot3(bk, bk);
  }
  // Scaled by 1 / (sum of the diagonal terms) against float overflow.
  precise float total = ((aa + bb) + ad) + ah;
  // total == 0 or not finite (or det == 0 below): no direction to push
  // along. isnan spelled out, so no compiler may turn !(x > 0) into x <= 0.
  if (!(total > 0.0) || isnan(total) || isinf(total)) {
    lambda[l] = ld;
    lambda[l + 1] = lh;
    return;
  }
  precise float scale = 1.0 / total;
  precise float saa = scale * aa, sbb = scale * bb, sad = scale * ad, sah = scale * ah;
  precise float m11 = saa + sad, m12 = -beta * sad, m22 = (sbb + (beta * beta) * sad) + sah;
  precise float det = ((saa * sbb + saa * ((beta * beta) * sad + sah)) + sad * sbb) + sad * sah;
  if (!(det > 0.0) || isnan(det)) {
    lambda[l] = ld;
    lambda[l + 1] = lh;
    return;
  }
  precise float rhs1 = -scale * rd, rhs2 = -scale * (rh - beta * rd);
  precise float mu1 = (m22 * rhs1 - m12 * rhs2) / det;
  precise float mu2 = (m11 * rhs2 - m12 * rhs1) / det;
  const uint ids[4] = uint[4](t.x, t.y, t.z, t.w);
  for (int k = 0; k < 4; ++k) {
    if (xs[k].w > 0.0) {
      precise vec3 dx = mu1 * a[k] + mu2 * b[k];
      precise vec3 y = xs[k].xyz + xs[k].w * dx;
      x[ids[k]] = vec4(y, xs[k].w);
    }
  }
  precise float ld_n = ld + (mu1 - beta * mu2), lh_n = lh + mu2;
  lambda[l] = ld_n;
  lambda[l + 1] = lh_n;
}

#endif /* SINEW_FEM_MATH_H */
