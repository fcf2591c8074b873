/* thin_math.h — OpenCL twin of the constraint functions of
 * kernels/cpu/thin_kernels.h (namespace thin), shared by
 * xpbd_solve_area.cl, xpbd_solve_dihedral.cl and xpbd_solve_line_bending.cl
 * (all .cl files become one program, so these live here, once).
 *  - area: C = |(x1 - x0) x (x2 - x0)| / 2 - A0;
 *  - dihedral: theta = atan2(sin, cos) of the two normals about the shared
 *    edge, gradients of Bridson, Marino, Fedkiw, "Simulation of Clothing
 *    with Folds and Wrinkles", SCA 2003, section 4;
 *  - line bending: Kelager, Niebe, Erleben, "A Triangle Bending Constraint
 *    Model for Position-Based Dynamics", VRIPHYS 2010.
 * Every expression is written in the CPU code's operation order, with no
 * fused multiply-add (cl_math.h sets FP_CONTRACT OFF), so the results round
 * like the CPU kernels'. The one library function, the CPU's
 * std::atan2(float, float), is thin_atan2f below: a device's builtin
 * atan2 differs from the C library's in the last bits (PoCL's, for about
 * one hinge in ten) or more (lavapipe's GLSL atan), and then a hinge at its
 * rest angle would not have C == 0 exactly. */
#ifndef SINEW_THIN_MATH_H
#define SINEW_THIN_MATH_H

#include "cl_math.h"

/* pi rounded to float, as thin::pi<float>. */
#define THIN_PI 3.14159265358979323846f

/* thin::triangle_area. */
inline float thin_triangle_area(float3 x0, float3 x1, float3 x2) {
  const float3 n = cross3(x1 - x0, x2 - x0);
  return 0.5f * sqrt(dot3(n, n));
}

/* thin::triangle_area_gradients: false, with g zero, for a collapsed triangle. */
inline bool thin_triangle_area_gradients(float3 x0, float3 x1, float3 x2, float3* g) {
  const float3 e1 = x1 - x0, e2 = x2 - x0;
  const float3 nn = cross3(e1, e2);
  const float len = sqrt(dot3(nn, nn));
  if (!(len > 0.0f)) {
    g[0] = g[1] = g[2] = (float3)(0.0f);
    return false;
  }
  const float3 n = (1.0f / len) * nn;
  g[1] = 0.5f * cross3(e2, n);
  g[2] = 0.5f * cross3(n, e1);
  g[0] = (float3)(0.0f) - (g[1] + g[2]);
  return true;
}

/* ---- atan2, bit for bit as the C library of the CPU reference computes it
 *
 * thin_atanf and thin_atan2f are the float atan and atan2 of Sun's fdlibm
 * (s_atanf.c, e_atan2f.c; float version by Ian Lance Taylor, Cygnus
 * Support), which glibc's atanf and atan2f are (sysdeps/ieee754/flt-32):
 * range reduction of |x| to 4 intervals about 1/2, 1, 3/2 and infinity,
 * atan(c) = hi + lo stored for each, and an 11-term odd polynomial in
 * float. Same constants and operation order, all in float without
 * contraction: checked bitwise equal to glibc 2.36's atanf over all 2^32
 * inputs and to its atan2f over 2e8 random and special argument pairs. The
 * fdlibm notice, which its license asks to keep:
 *   Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.
 *   Developed at SunPro, a Sun Microsystems, Inc. business.
 *   Permission to use, copy, modify, and distribute this software is
 *   freely granted, provided that this notice is preserved.
 * (A C library with another atan2f, e.g. a correctly rounded one, gives
 * the CPU kernel other last bits; the agreement tests would show it.) */

/* atan(c) for c = 1/2, 1, 3/2, infinity: high parts, low parts. */
constant float thin_atan_hi[4] = {0x1.dac670p-2f, 0x1.921fb4p-1f, 0x1.f730bcp-1f, 0x1.921fb4p+0f};
constant float thin_atan_lo[4] = {0x1.586ed2p-28f, 0x1.4442d0p-25f, 0x1.281f68p-25f, 0x1.4442d0p-24f};
/* The polynomial atan(x) = x - x (aT0 z + aT1 z^2 + ... + aT10 z^11), z = x^2. */
constant float thin_atan_t[11] = {0x1.555556p-2f,  -0x1.99999ap-3f, 0x1.24924ap-3f,  -0x1.c71c70p-4f,
                                  0x1.745cdcp-4f,  -0x1.3b0f2ap-4f, 0x1.10d66ap-4f,  -0x1.dde2d6p-5f,
                                  0x1.97b4b2p-5f,  -0x1.2b4442p-5f, 0x1.0ad3aep-6f};
#define THIN_PI_HI 0x1.921fb6p+1f     /* pi rounded to float (= THIN_PI) */
#define THIN_PI_LO (-0x1.777a5cp-24f) /* pi - THIN_PI_HI */
#define THIN_PI_2 0x1.921fb6p+0f      /* pi / 2 rounded */
#define THIN_PI_4 0x1.921fb6p-1f      /* pi / 4 rounded */
#define THIN_3PI_4 0x1.2d97c8p+1f     /* 3 * THIN_PI_4 rounded */

inline float thin_atanf(float x) {
  const int hx = as_int(x), ix = hx & 0x7fffffff;
  int id;
  if (ix >= 0x4c000000) { /* |x| >= 2^25, or NaN */
    if (ix > 0x7f800000) return x + x;
    return hx > 0 ? thin_atan_hi[3] + thin_atan_lo[3] : -thin_atan_hi[3] - thin_atan_lo[3];
  }
  if (ix < 0x3ee00000) {                /* |x| < 7/16 */
    if (ix < 0x31000000) return x;      /* |x| < 2^-29 */
    id = -1;
  } else {
    x = fabs(x);
    if (ix < 0x3f980000) {   /* |x| < 19/16 */
      if (ix < 0x3f300000) { /* 7/16 <= |x| < 11/16 */
        id = 0;
        x = (2.0f * x - 1.0f) / (2.0f + x);
      } else { /* 11/16 <= |x| < 19/16 */
        id = 1;
        x = (x - 1.0f) / (x + 1.0f);
      }
    } else if (ix < 0x401c0000) { /* 19/16 <= |x| < 39/16 */
      id = 2;
      x = (x - 1.5f) / (1.0f + 1.5f * x);
    } else { /* 39/16 <= |x| < 2^25 */
      id = 3;
      x = -1.0f / x;
    }
  }
  const float z = x * x, w = z * z;
  /* The odd and even halves of the sum over aT_k z^(k+1), in w = z^2. */
  constant float* t = thin_atan_t;
  const float s1 = z * (t[0] + w * (t[2] + w * (t[4] + w * (t[6] + w * (t[8] + w * t[10])))));
  const float s2 = w * (t[1] + w * (t[3] + w * (t[5] + w * (t[7] + w * t[9]))));
  if (id < 0) return x - x * (s1 + s2);
  const float r = thin_atan_hi[id] - ((x * (s1 + s2) - thin_atan_lo[id]) - x);
  return hx < 0 ? -r : r;
}

/* atan2(y, x) in [-pi, pi], signs of zeros and infinities as C's atan2f. */
inline float thin_atan2f(float y, float x) {
  const int hx = as_int(x), ix = hx & 0x7fffffff, hy = as_int(y), iy = hy & 0x7fffffff;
  if (ix > 0x7f800000 || iy > 0x7f800000) return x + y; /* NaN */
  if (hx == 0x3f800000) return thin_atanf(y);           /* x == 1 */
  const int m = (hy < 0 ? 1 : 0) | (hx < 0 ? 2 : 0);    /* 2 sign(x) + sign(y) */
  if (iy == 0) return m < 2 ? y : (m == 2 ? THIN_PI_HI : -THIN_PI_HI);
  if (ix == 0) return hy < 0 ? -THIN_PI_2 : THIN_PI_2;
  if (ix == 0x7f800000) {
    if (iy == 0x7f800000) return m == 0 ? THIN_PI_4 : m == 1 ? -THIN_PI_4 : m == 2 ? THIN_3PI_4 : -THIN_3PI_4;
    return m == 0 ? 0.0f : m == 1 ? -0.0f : m == 2 ? THIN_PI_HI : -THIN_PI_HI;
  }
  if (iy == 0x7f800000) return hy < 0 ? -THIN_PI_2 : THIN_PI_2;
  const int k = (iy - ix) >> 23;
  float z;
  if (k > 60) z = THIN_PI_2 + 0.5f * THIN_PI_LO; /* |y / x| > 2^60 */
  else if (hx < 0 && k < -60) z = 0.0f;        /* |y| / x < -2^60 */
  else z = thin_atanf(fabs(y / x));
  if (m == 0) return z;
  if (m == 1) return -z;
  if (m == 2) return THIN_PI_HI - (z - THIN_PI_LO);
  return (z - THIN_PI_LO) - THIN_PI_HI;
}

/* thin::dihedral_angle: the signed angle of the hinge x0-x1 with wings x2,
 * x3, in -pi..pi; 0 when the edge or a wing is degenerate. */
inline float thin_dihedral_angle(float3 x0, float3 x1, float3 x2, float3 x3) {
  const float3 e = x1 - x0;
  const float3 n1 = cross3(e, x2 - x0), n2 = cross3(x3 - x0, e);
  const float l1 = sqrt(dot3(n1, n1)), l2 = sqrt(dot3(n2, n2)), le = sqrt(dot3(e, e));
  if (!(l1 > 0.0f) || !(l2 > 0.0f) || !(le > 0.0f)) return 0.0f;
  const float3 u1 = (1.0f / l1) * n1, u2 = (1.0f / l2) * n2;
  const float s = dot3(cross3(u1, u2), e) / le; /* sin theta */
  const float c = dot3(u1, u2);                 /* cos theta */
  return thin_atan2f(s, c); /* std::atan2(s, c) of the CPU's C library */
}

/* thin::wrap_angle: d, a difference of two angles, wrapped into -pi..pi. */
inline float thin_wrap_angle(float d) {
  if (d > THIN_PI) return d - 2.0f * THIN_PI;
  if (d < -THIN_PI) return d + 2.0f * THIN_PI;
  return d;
}

/* thin::dihedral_angle_gradients (Bridson et al. 2003): false, with g zero,
 * when the edge or a wing is degenerate. */
inline bool thin_dihedral_angle_gradients(float3 x0, float3 x1, float3 x2, float3 x3, float3* g) {
  const float3 e = x1 - x0, a = x2 - x0, b = x3 - x0;
  const float3 n1 = cross3(e, a), n2 = cross3(b, e);
  const float q1 = dot3(n1, n1), q2 = dot3(n2, n2), qe = dot3(e, e);
  if (!(q1 > 0.0f) || !(q2 > 0.0f) || !(qe > 0.0f)) {
    g[0] = g[1] = g[2] = g[3] = (float3)(0.0f);
    return false;
  }
  const float le = sqrt(qe);
  g[2] = (-le / q1) * n1;
  g[3] = (-le / q2) * n2;
  const float s2 = dot3(a, e) / qe, s3 = dot3(b, e) / qe;
  const float3 zero = (float3)(0.0f);
  g[1] = zero - (s2 * g[2] + s3 * g[3]);
  g[0] = zero - ((1.0f - s2) * g[2] + (1.0f - s3) * g[3]);
  return true;
}

/* thin::line_bending_offset (Kelager et al. 2010): |x_v - c|,
 * c = (x_b0 + x_v + x_b1) / 3. */
inline float thin_line_bending_offset(float3 b0, float3 v, float3 b1) {
  const float3 d = v - (1.0f / 3.0f) * (b0 + v + b1);
  return sqrt(dot3(d, d));
}

/* thin::line_bending_gradients: (grad_b0, grad_v, grad_b1); false, with g
 * zero, when x_v is at the centroid. */
inline bool thin_line_bending_gradients(float3 b0, float3 v, float3 b1, float3* g) {
  const float3 d = v - (1.0f / 3.0f) * (b0 + v + b1);
  const float len = sqrt(dot3(d, d));
  if (!(len > 0.0f)) {
    g[0] = g[1] = g[2] = (float3)(0.0f);
    return false;
  }
  const float3 n = (1.0f / len) * d;
  g[1] = (2.0f / 3.0f) * n;
  g[0] = g[2] = (-1.0f / 3.0f) * n;
  return true;
}

/* The guard of thin_kernels.cpp's apply(): total == 0 (all immovable and
 * rigid) or not finite (an overflowed gradient) gives no usable step. */
inline bool thin_step_usable(float total) { return !(!(total > 0.0f) || !isfinite(total)); }

#endif /* SINEW_THIN_MATH_H */
