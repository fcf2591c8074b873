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
 * multiply-add), so the results round like the CPU kernels'. The angle's
 * atan2 is not GLSL's atan(y, x): the CPU's is thin::atan2_portable, our
 * own from + - * / and sqrt, and thin_atan2_portable below repeats it
 * operation for operation; GLSL's atan may be far less exact (lavapipe's
 * is off by far more than an ulp), and then a hinge at its rest angle
 * would not have C == 0 exactly. Guards are written as positive
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

/* ---- atan2: thin::atan2_portable<float> of kernels/cpu/thin_kernels.h,
 * operation for operation (the algorithm, its identities and the number of
 * series terms are explained there), as kernels/opencl/thin_math.h has it:
 * only + - * / and sqrt, correctly rounded here as on the CPU, in the CPU's
 * order, every result `precise`. The constants below are the floats of the
 * OpenCL twin's hexadecimal literals, in 17 significant digits: read as a
 * double, each is that float exactly, so its conversion to float cannot
 * round another way. */

const float THIN_PI_2 = 1.5707963705062866;   // THIN_PI / 2 (exact), as thin::pi<float> / 2
const float THIN_PI_4 = 0.78539818525314331;  // THIN_PI / 4 (exact), as thin::pi<float> / 4
// (-1)^k / (2k + 1) rounded to float, k = 1..8, as the CPU computes them.
const float THIN_ATAN_C1 = -0.3333333432674408, THIN_ATAN_C2 = 0.20000000298023224,
            THIN_ATAN_C3 = -0.1428571492433548, THIN_ATAN_C4 = 0.1111111119389534,
            THIN_ATAN_C5 = -0.090909093618392944, THIN_ATAN_C6 = 0.076923079788684845,
            THIN_ATAN_C7 = -0.066666670143604279, THIN_ATAN_C8 = 0.058823529630899429;

/* atan(r) for r in [0, 1]: 2 atan(t), t = r / (1 + sqrt(1 + r^2)), and nine
 * terms of atan(t) = t - t^3/3 + t^5/5 - ... in Horner form in z = t^2. */
precise float thin_atan01(float r) {
  precise float t = r / (1.0 + sqrt(1.0 + r * r));
  precise float z = t * t;
  precise float q =
      THIN_ATAN_C1 +
      z * (THIN_ATAN_C2 +
           z * (THIN_ATAN_C3 +
                z * (THIN_ATAN_C4 +
                     z * (THIN_ATAN_C5 + z * (THIN_ATAN_C6 + z * (THIN_ATAN_C7 + z * THIN_ATAN_C8))))));
  precise float a = 2.0 * (t + t * (z * q));
  return a;
}

/* thin::atan2_portable(y, x) in -pi..pi, C's conventions for signed zeros,
 * infinities and NaN. NaN and the signs are read from the bits, which no
 * compiler assumption about NaN can change. */
precise float thin_atan2_portable(float y, float x) {
  const int hx = floatBitsToInt(x), hy = floatBitsToInt(y);
  if ((hx & 0x7fffffff) > 0x7f800000 || (hy & 0x7fffffff) > 0x7f800000) {  // NaN
    precise float nan_out = x + y;
    return nan_out;
  }
  precise float ax = abs(x), ay = abs(y);
  precise float a;
  if (ax == ay) a = ax == 0.0 ? 0.0 : THIN_PI_4;
  else if (ay < ax) a = thin_atan01(ay / ax);
  else a = THIN_PI_2 - thin_atan01(ax / ay);
  if (hx < 0) a = THIN_PI - a;
  precise float r = hy < 0 ? -a : a;
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
    precise float theta = thin_atan2_portable(s, c);
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
