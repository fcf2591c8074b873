/* thin_math.h — GLSL twin of the constraint functions of
 * kernels/cpu/thin_kernels.h (namespace thin) and of
 * kernels/opencl/thin_math.h, shared by xpbd_solve_area.comp,
 * xpbd_solve_dihedral.comp and xpbd_solve_line_bending.comp.
 *  - area: C = |(x1 - x0) x (x2 - x0)| / 2 - A0;
 *  - dihedral: theta = atan2(sin, cos) of the two normals about the shared
 *    edge, gradients of Bridson, Marino, Fedkiw, "Simulation of Clothing
 *    with Folds and Wrinkles", SCA 2003, section 4;
 *  - line bending: Kelager, Niebe, Erleben, "A Triangle Bending Constraint
 *    Model for Position-Based Dynamics", VRIPHYS 2010.
 * Every expression is written in the CPU code's operation order and every
 * arithmetic result is `precise` (SPIR-V NoContraction: no fused
 * multiply-add), so the results round like the CPU kernels'. The one
 * library function, the CPU's std::atan2(float, float), is thin_atan2f
 * below: GLSL's atan(y, x) may be far less exact (lavapipe's differs from
 * the C library's by far more than an ulp), and then a hinge at its rest
 * angle would not have C == 0 exactly. Guards are written as positive
 * conditions (`if (len > 0.0)`, not `if (!(len > 0.0))`), so that a NaN
 * takes the same branch as on the CPU even where a compiler turns
 * !(a > b) into a <= b. */
#ifndef SINEW_THIN_MATH_H
#define SINEW_THIN_MATH_H

#include "glsl_math.h"

/* pi rounded to float, as thin::pi<float>. */
const float THIN_PI = 3.14159265358979323846;
/* The largest finite float: total <= it is isfinite(total) for total > 0. */
const float THIN_FLOAT_MAX = 3.40282346638528859812e+38;

/* thin::triangle_area. */
precise float thin_triangle_area(vec3 x0, vec3 x1, vec3 x2) {
  precise vec3 n = cross3(x1 - x0, x2 - x0);
  precise float a = 0.5 * sqrt(dot3(n, n));
  return a;
}

/* thin::triangle_area_gradients: false, with g zero, for a collapsed triangle. */
bool thin_triangle_area_gradients(vec3 x0, vec3 x1, vec3 x2, out vec3 g0, out vec3 g1, out vec3 g2) {
  precise vec3 e1 = x1 - x0, e2 = x2 - x0;
  precise vec3 nn = cross3(e1, e2);
  precise float len = sqrt(dot3(nn, nn));
  if (len > 0.0) {
    precise vec3 n = (1.0 / len) * nn;
    precise vec3 h1 = 0.5 * cross3(e2, n);
    precise vec3 h2 = 0.5 * cross3(n, e1);
    precise vec3 h0 = vec3(0.0) - (h1 + h2);
    g0 = h0;
    g1 = h1;
    g2 = h2;
    return true;
  }
  g0 = g1 = g2 = vec3(0.0);
  return false;
}

/* ---- atan2, bit for bit as the C library of the CPU reference computes it
 *
 * thin_atanf and thin_atan2f are the float atan and atan2 of Sun's fdlibm
 * (s_atanf.c, e_atan2f.c; float version by Ian Lance Taylor, Cygnus
 * Support), which glibc's atanf and atan2f are (sysdeps/ieee754/flt-32),
 * as kernels/opencl/thin_math.h has them (see there): same constants (the
 * decimals below are the floats' exact values) and operation order, all in
 * float, every result `precise`. The fdlibm notice, which its license asks
 * to keep:
 *   Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.
 *   Developed at SunPro, a Sun Microsystems, Inc. business.
 *   Permission to use, copy, modify, and distribute this software is
 *   freely granted, provided that this notice is preserved. */

/* atan(c) for c = 1/2, 1, 3/2, infinity: high parts, low parts. */
const float THIN_ATAN_HI[4] = float[4](0.46364760398864746, 0.78539812564849854, 0.98279368877410889,
                                       1.5707962512969971);
const float THIN_ATAN_LO[4] = float[4](5.0121582439999202e-09, 3.7748947079307982e-08, 3.4473217169761483e-08,
                                       7.5497894158615964e-08);
/* The polynomial atan(x) = x - x (aT0 z + aT1 z^2 + ... + aT10 z^11), z = x^2. */
const float THIN_AT0 = 0.3333333432674408, THIN_AT1 = -0.20000000298023224, THIN_AT2 = 0.1428571492433548,
            THIN_AT3 = -0.1111111044883728, THIN_AT4 = 0.090908870100975037, THIN_AT5 = -0.076918758451938629,
            THIN_AT6 = 0.066610731184482574, THIN_AT7 = -0.058335702866315842, THIN_AT8 = 0.049768779426813126,
            THIN_AT9 = -0.036531571298837662, THIN_AT10 = 0.016285819932818413;
const float THIN_PI_LO = -8.7422776573475858e-08;  // pi - THIN_PI
const float THIN_PI_2 = 1.5707963705062866;        // pi / 2 rounded
const float THIN_PI_4 = 0.78539818525314331;       // pi / 4 rounded
const float THIN_3PI_4 = 2.3561944961547852;       // 3 * THIN_PI_4 rounded

precise float thin_atanf(float x_in) {
  precise float x = x_in;
  const int hx = floatBitsToInt(x), ix = hx & 0x7fffffff;
  int id;
  if (ix >= 0x4c000000) {  // |x| >= 2^25, or NaN
    if (ix > 0x7f800000) {
      precise float nan_out = x + x;
      return nan_out;
    }
    precise float r = hx > 0 ? THIN_ATAN_HI[3] + THIN_ATAN_LO[3] : -THIN_ATAN_HI[3] - THIN_ATAN_LO[3];
    return r;
  }
  if (ix < 0x3ee00000) {              // |x| < 7/16
    if (ix < 0x31000000) return x;    // |x| < 2^-29
    id = -1;
  } else {
    x = abs(x);
    if (ix < 0x3f980000) {    // |x| < 19/16
      if (ix < 0x3f300000) {  // 7/16 <= |x| < 11/16
        id = 0;
        x = (2.0 * x - 1.0) / (2.0 + x);
      } else {  // 11/16 <= |x| < 19/16
        id = 1;
        x = (x - 1.0) / (x + 1.0);
      }
    } else if (ix < 0x401c0000) {  // 19/16 <= |x| < 39/16
      id = 2;
      x = (x - 1.5) / (1.0 + 1.5 * x);
    } else {  // 39/16 <= |x| < 2^25
      id = 3;
      x = -1.0 / x;
    }
  }
  precise float z = x * x, w = z * z;
  // The odd and even halves of the sum over aT_k z^(k+1), in w = z^2.
  precise float s1 = z * (THIN_AT0 + w * (THIN_AT2 + w * (THIN_AT4 + w * (THIN_AT6 + w * (THIN_AT8 + w * THIN_AT10)))));
  precise float s2 = w * (THIN_AT1 + w * (THIN_AT3 + w * (THIN_AT5 + w * (THIN_AT7 + w * THIN_AT9))));
  if (id < 0) {
    precise float r = x - x * (s1 + s2);
    return r;
  }
  precise float r = THIN_ATAN_HI[id] - ((x * (s1 + s2) - THIN_ATAN_LO[id]) - x);
  return hx < 0 ? -r : r;
}

/* atan2(y, x) in -pi..pi, signs of zeros and infinities as C's atan2f. */
precise float thin_atan2f(float y, float x) {
  const int hx = floatBitsToInt(x), ix = hx & 0x7fffffff, hy = floatBitsToInt(y), iy = hy & 0x7fffffff;
  if (ix > 0x7f800000 || iy > 0x7f800000) {  // NaN
    precise float nan_out = x + y;
    return nan_out;
  }
  if (hx == 0x3f800000) return thin_atanf(y);         // x == 1
  const int m = (hy < 0 ? 1 : 0) | (hx < 0 ? 2 : 0);  // 2 sign(x) + sign(y)
  if (iy == 0) return m < 2 ? y : (m == 2 ? THIN_PI : -THIN_PI);
  if (ix == 0) return hy < 0 ? -THIN_PI_2 : THIN_PI_2;
  if (ix == 0x7f800000) {
    if (iy == 0x7f800000) return m == 0 ? THIN_PI_4 : m == 1 ? -THIN_PI_4 : m == 2 ? THIN_3PI_4 : -THIN_3PI_4;
    return m == 0 ? 0.0 : m == 1 ? -0.0 : m == 2 ? THIN_PI : -THIN_PI;
  }
  if (iy == 0x7f800000) return hy < 0 ? -THIN_PI_2 : THIN_PI_2;
  const int k = (iy - ix) >> 23;
  precise float z;
  if (k > 60) z = THIN_PI_2 + 0.5 * THIN_PI_LO;  // |y / x| > 2^60
  else if (hx < 0 && k < -60) z = 0.0;           // |y| / x < -2^60
  else z = thin_atanf(abs(y / x));
  if (m == 0) return z;
  if (m == 1) return -z;
  precise float r = m == 2 ? THIN_PI - (z - THIN_PI_LO) : (z - THIN_PI_LO) - THIN_PI;
  return r;
}

/* thin::dihedral_angle: the signed angle of the hinge x0-x1 with wings x2,
 * x3, in -pi..pi; 0 when the edge or a wing is degenerate. */
precise float thin_dihedral_angle(vec3 x0, vec3 x1, vec3 x2, vec3 x3) {
  precise vec3 e = x1 - x0;
  precise vec3 n1 = cross3(e, x2 - x0), n2 = cross3(x3 - x0, e);
  precise float l1 = sqrt(dot3(n1, n1)), l2 = sqrt(dot3(n2, n2)), le = sqrt(dot3(e, e));
  if (l1 > 0.0 && l2 > 0.0 && le > 0.0) {
    precise vec3 u1 = (1.0 / l1) * n1, u2 = (1.0 / l2) * n2;
    precise float s = dot3(cross3(u1, u2), e) / le;  // sin theta
    precise float c = dot3(u1, u2);                  // cos theta
    precise float theta = thin_atan2f(s, c);  // std::atan2(s, c) of the CPU's C library
    return theta;
  }
  return 0.0;
}

/* thin::wrap_angle: d, a difference of two angles, wrapped into -pi..pi. */
precise float thin_wrap_angle(float d) {
  if (d > THIN_PI) {
    precise float r = d - 2.0 * THIN_PI;
    return r;
  }
  if (d < -THIN_PI) {
    precise float r = d + 2.0 * THIN_PI;
    return r;
  }
  return d;
}

/* thin::dihedral_angle_gradients (Bridson et al. 2003): false, with g zero,
 * when the edge or a wing is degenerate. */
bool thin_dihedral_angle_gradients(vec3 x0, vec3 x1, vec3 x2, vec3 x3, out vec3 g0, out vec3 g1, out vec3 g2,
                                   out vec3 g3) {
  precise vec3 e = x1 - x0, a = x2 - x0, b = x3 - x0;
  precise vec3 n1 = cross3(e, a), n2 = cross3(b, e);
  precise float q1 = dot3(n1, n1), q2 = dot3(n2, n2), qe = dot3(e, e);
  if (q1 > 0.0 && q2 > 0.0 && qe > 0.0) {
    precise float le = sqrt(qe);
    precise vec3 h2 = (-le / q1) * n1;
    precise vec3 h3 = (-le / q2) * n2;
    precise float s2 = dot3(a, e) / qe, s3 = dot3(b, e) / qe;
    const vec3 zero = vec3(0.0);
    precise vec3 h1 = zero - (s2 * h2 + s3 * h3);
    precise vec3 h0 = zero - ((1.0 - s2) * h2 + (1.0 - s3) * h3);
    g0 = h0;
    g1 = h1;
    g2 = h2;
    g3 = h3;
    return true;
  }
  g0 = g1 = g2 = g3 = vec3(0.0);
  return false;
}

/* thin::line_bending_offset (Kelager et al. 2010): |x_v - c|,
 * c = (x_b0 + x_v + x_b1) / 3. */
precise float thin_line_bending_offset(vec3 b0, vec3 v, vec3 b1) {
  precise vec3 d = v - (1.0 / 3.0) * (b0 + v + b1);
  precise float len = sqrt(dot3(d, d));
  return len;
}

/* thin::line_bending_gradients: (grad_b0, grad_v, grad_b1); false, with g
 * zero, when x_v is at the centroid. */
bool thin_line_bending_gradients(vec3 b0, vec3 v, vec3 b1, out vec3 g0, out vec3 g1, out vec3 g2) {
  precise vec3 d = v - (1.0 / 3.0) * (b0 + v + b1);
  precise float len = sqrt(dot3(d, d));
  if (len > 0.0) {
    precise vec3 n = (1.0 / len) * d;
    precise vec3 h1 = (2.0 / 3.0) * n;
    precise vec3 h0 = (-1.0 / 3.0) * n;
    g0 = h0;
    g1 = h1;
    g2 = h0;
    return true;
  }
  g0 = g1 = g2 = vec3(0.0);
  return false;
}

/* The guard of thin_kernels.cpp's apply(), positively: a usable step needs
 * total > 0 (not all immovable and rigid) and finite (no overflowed
 * gradient); NaN fails both comparisons. */
bool thin_step_usable(float total) { return total > 0.0 && total <= THIN_FLOAT_MAX; }

#endif /* SINEW_THIN_MATH_H */
