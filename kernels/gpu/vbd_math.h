/* vbd_math.h — GPU twin of kernels/math/vbd_math.h: one tet's share of a
 * vertex's Vertex Block Descent step (Chen, Liu, Yang, Yuksel, "Vertex
 * Block Descent", ACM TOG 43(4), SIGGRAPH 2024). Every operation in the
 * CPU twin's order (bitwise agreement). */
#ifndef SINEW_VBD_MATH_H
#define SINEW_VBD_MATH_H

#include "fem_math.h"

/* Force (-gradient) and symmetric Hessian (xx, yy, zz, xy, xz, yz). */
SINEW_STRUCT_BEGIN(VbdSystem)
  float f[3];
  float h[6];
SINEW_STRUCT_END(VbdSystem)

/* A step: dx, and whether it is taken (det H safely positive, finite). */
SINEW_STRUCT_BEGIN(VbdStep)
  float dx[3];
  bool ok;
SINEW_STRUCT_END(VbdStep)

/* b_i of corner `corner` from Dm^-1 (vbd::corner_weights). */
float3 vbd_corner_weights(FemMat3 dm_inv, uint corner) {
  PRECISE float b[3];
  for (int k = 0; k < 3; ++k) {
    if (corner == 0u) {
      PRECISE float sum = dm_inv.m[0][k] + dm_inv.m[1][k] + dm_inv.m[2][k];
      b[k] = -sum;
    } else {
      b[k] = dm_inv.m[to_int(corner) - 1][k];
    }
  }
  return make_float3(b[0], b[1], b[2]);
}

/* vbd::add_tet. */
VbdSystem vbd_add_tet(VbdSystem s, FemMat3 a, FemMat3 p, float3 bv, float inv_ad, float inv_ah) {
  const float b[3] = {bv.x, bv.y, bv.z};
  PRECISE float ab[3];
  PRECISE float pb[3];
  for (int r = 0; r < 3; ++r) {
    ab[r] = a.m[r][0] * b[0] + a.m[r][1] * b[1] + a.m[r][2] * b[2];
    pb[r] = p.m[r][0] * b[0] + p.m[r][1] * b[1] + p.m[r][2] * b[2];
  }
  PRECISE float diagonal = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]) * inv_ad;
  PRECISE VbdSystem o = s;
  for (int r = 0; r < 3; ++r) o.f[r] = s.f[r] - pb[r];
  o.h[0] = s.h[0] + (diagonal + ab[0] * ab[0] * inv_ah);
  o.h[1] = s.h[1] + (diagonal + ab[1] * ab[1] * inv_ah);
  o.h[2] = s.h[2] + (diagonal + ab[2] * ab[2] * inv_ah);
  o.h[3] = s.h[3] + ab[0] * ab[1] * inv_ah;
  o.h[4] = s.h[4] + ab[0] * ab[2] * inv_ah;
  o.h[5] = s.h[5] + ab[1] * ab[2] * inv_ah;
  return o;
}

/* vbd::corotational_stress. */
FemMat3 vbd_corotational_stress(FemMat3 f, FemMat3 r, float h0, float inv_ad, float inv_ah) {
  PRECISE float trace = 0.0f;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) trace += r.m[i][j] * f.m[i][j];
  PRECISE float c_h = (trace - h0) * inv_ah;
  PRECISE FemMat3 p;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) p.m[i][j] = (f.m[i][j] - r.m[i][j]) * inv_ad + c_h * r.m[i][j];
  return p;
}

/* vbd::neo_hookean_stress. */
FemMat3 vbd_neo_hookean_stress(FemMat3 f, FemMat3 cof, float h0, float inv_ad, float inv_ah) {
  PRECISE float c_h = (fem_determinant(f) - h0) * inv_ah;
  PRECISE FemMat3 p;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) p.m[i][j] = f.m[i][j] * inv_ad + c_h * cof.m[i][j];
  return p;
}

/* vbd::solve_step. */
VbdStep vbd_solve_step(VbdSystem s) {
  VbdStep r;
  r.ok = false;
  r.dx[0] = 0.0f;
  r.dx[1] = 0.0f;
  r.dx[2] = 0.0f;
  const float a = s.h[0], b = s.h[1], c = s.h[2], d = s.h[3], e = s.h[4], k = s.h[5];
  PRECISE float c00 = b * c - k * k, c01 = e * k - d * c, c02 = d * k - b * e;
  PRECISE float c11 = a * c - e * e, c12 = d * e - a * k, c22 = a * b - d * d;
  PRECISE float det = a * c00 + d * c01 + e * c02;
  PRECISE float bound = 1e-10f * a * b * c;
  if (!(det > bound) || isnan(det)) return r;
  PRECISE float inv_det = 1.0f / det;
  PRECISE float x = (c00 * s.f[0] + c01 * s.f[1] + c02 * s.f[2]) * inv_det;
  PRECISE float y = (c01 * s.f[0] + c11 * s.f[1] + c12 * s.f[2]) * inv_det;
  PRECISE float z = (c02 * s.f[0] + c12 * s.f[1] + c22 * s.f[2]) * inv_det;
  if (isnan(x) || isinf(x) || isnan(y) || isinf(y) || isnan(z) || isinf(z)) return r;
  r.dx[0] = x;
  r.dx[1] = y;
  r.dx[2] = z;
  r.ok = true;
  return r;
}

#endif /* SINEW_VBD_MATH_H */
