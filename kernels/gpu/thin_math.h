/* thin_math.h — GPU twin of the constraint functions of
 * kernels/math/thin_math.h (namespace thin) and of the xPBD step of
 * kernels/cpu/thin_kernels.cpp (apply<N>), shared by xpbd_solve_area.gpu,
 * xpbd_solve_dihedral.gpu and xpbd_solve_line_bending.gpu.
 *  - area: C = |(x1 - x0) x (x2 - x0)| / 2 - A0;
 *  - dihedral: theta = atan2(sin, cos) of the two normals about the shared
 *    edge, gradients of Bridson, Marino, Fedkiw, "Simulation of Clothing
 *    with Folds and Wrinkles", SCA 2003, section 4;
 *  - line bending: Kelager, Niebe, Erleben, "A Triangle Bending Constraint
 *    Model for Position-Based Dynamics", VRIPHYS 2010.
 * Every expression is written in the CPU code's operation order and every
 * arithmetic result is PRECISE (no fused multiply-add), so the results
 * round like the CPU kernels'. The angle's atan2 is not the builtin: the
 * CPU's is thin::atan2_portable, our own from + - * / and sqrt, and
 * thin_atan2_portable below repeats it operation for operation; a device's
 * atan2 differs from it in the last bits or more (lavapipe's GLSL atan by
 * far more than an ulp), and then a hinge at its rest angle would not have
 * C == 0 exactly. Guards are written as positive conditions
 * (`if (len > 0.0f)`, not `if (!(len > 0.0f))`), so that a NaN takes the
 * same branch as on the CPU even where a compiler turns !(a > b) into
 * a <= b. */
#ifndef SINEW_THIN_MATH_H
#define SINEW_THIN_MATH_H

#include "vec_math.h"
#include "sinew_lang.h"

/* pi rounded to float, as thin::pi<float>. */
#define THIN_PI 3.14159265358979323846f
/* The largest finite float: total <= it is isfinite(total) for total > 0. */
#define THIN_FLOAT_MAX 3.40282346638528859812e+38f

/* A constraint's gradients with respect to its (up to four) particles, the
 * unused ones zero; ok false, with all zero, where it has no direction. */
SINEW_STRUCT_BEGIN(ThinGradients)
  float3 g[4];
  bool ok;
SINEW_STRUCT_END(ThinGradients)

/* One constraint's xPBD step: the multiplier to store and, where moved,
 * its change, by which the movable particles move (thin_moved). */
SINEW_STRUCT_BEGIN(ThinStep)
  float lambda;
  float dlambda;
  bool moved;
SINEW_STRUCT_END(ThinStep)

ThinGradients thin_no_direction() {
  ThinGradients r;
  for (int k = 0; k < 4; ++k) r.g[k] = make_float3(0.0f, 0.0f, 0.0f);
  r.ok = false;
  return r;
}

/* thin::triangle_area. */
PRECISE float thin_triangle_area(float3 x0, float3 x1, float3 x2) {
  PRECISE float3 n = cross3(x1 - x0, x2 - x0);
  PRECISE float a = 0.5f * sqrt(dot3(n, n));
  return a;
}

/* thin::triangle_area_gradients: not ok, with g zero, for a collapsed triangle. */
ThinGradients thin_triangle_area_gradients(float3 x0, float3 x1, float3 x2) {
  ThinGradients r = thin_no_direction();
  PRECISE float3 e1 = x1 - x0, e2 = x2 - x0;
  PRECISE float3 nn = cross3(e1, e2);
  PRECISE float len = sqrt(dot3(nn, nn));
  if (len > 0.0f) {
    PRECISE float3 n = (1.0f / len) * nn;
    PRECISE float3 h1 = 0.5f * cross3(e2, n);
    PRECISE float3 h2 = 0.5f * cross3(n, e1);
    PRECISE float3 h0 = make_float3(0.0f, 0.0f, 0.0f) - (h1 + h2);
    r.g[0] = h0;
    r.g[1] = h1;
    r.g[2] = h2;
    r.ok = true;
  }
  return r;
}

/* ---- atan2: thin::atan2_portable<float> of kernels/math/thin_math.h,
 * operation for operation (the algorithm, its identities and the number of
 * series terms are explained there): only + - * / and sqrt, correctly
 * rounded here as on the CPU, in the CPU's order, every result PRECISE.
 * The constants are floats written in 17 significant digits: read as a
 * double (GLSL compilers) each is that float exactly, so its conversion to
 * float cannot round another way; read as a float (OpenCL) it is that
 * float too. */

#define THIN_PI_2 1.5707963705062866f   /* THIN_PI / 2 (exact), as thin::pi<float> / 2 */
#define THIN_PI_4 0.78539818525314331f  /* THIN_PI / 4 (exact), as thin::pi<float> / 4 */
/* (-1)^k / (2k + 1) rounded to float, k = 1..8, as the CPU computes them. */
#define THIN_ATAN_C1 -0.3333333432674408f
#define THIN_ATAN_C2 0.20000000298023224f
#define THIN_ATAN_C3 -0.1428571492433548f
#define THIN_ATAN_C4 0.1111111119389534f
#define THIN_ATAN_C5 -0.090909093618392944f
#define THIN_ATAN_C6 0.076923079788684845f
#define THIN_ATAN_C7 -0.066666670143604279f
#define THIN_ATAN_C8 0.058823529630899429f

/* atan(r) for r in [0, 1]: 2 atan(t), t = r / (1 + sqrt(1 + r^2)), and nine
 * terms of atan(t) = t - t^3/3 + t^5/5 - ... in Horner form in z = t^2. */
PRECISE float thin_atan01(float r) {
  PRECISE float t = r / (1.0f + sqrt(1.0f + r * r));
  PRECISE float z = t * t;
  PRECISE float q =
      THIN_ATAN_C1 +
      z * (THIN_ATAN_C2 +
           z * (THIN_ATAN_C3 +
                z * (THIN_ATAN_C4 +
                     z * (THIN_ATAN_C5 + z * (THIN_ATAN_C6 + z * (THIN_ATAN_C7 + z * THIN_ATAN_C8))))));
  PRECISE float a = 2.0f * (t + t * (z * q));
  return a;
}

/* thin::atan2_portable(y, x) in -pi..pi, C's conventions for signed zeros,
 * infinities and NaN. NaN and the signs are read from the bits, which no
 * compiler assumption about NaN can change. */
PRECISE float thin_atan2_portable(float y, float x) {
  const uint hx = float_bits(x), hy = float_bits(y);
  if ((hx & 0x7fffffffu) > 0x7f800000u || (hy & 0x7fffffffu) > 0x7f800000u) {  // NaN
    PRECISE float nan_out = x + y;
    return nan_out;
  }
  PRECISE float ax = fabs(x), ay = fabs(y);
  PRECISE float a;
  if (ax == ay) a = ax == 0.0f ? 0.0f : THIN_PI_4;
  else if (ay < ax) a = thin_atan01(ay / ax);
  else a = THIN_PI_2 - thin_atan01(ax / ay);
  if (hx >= 0x80000000u) a = THIN_PI - a;  // sign bit of x
  PRECISE float r = hy >= 0x80000000u ? -a : a;
  return r;
}

/* thin::dihedral_angle: the signed angle of the hinge x0-x1 with wings x2,
 * x3, in -pi..pi; 0 when the edge or a wing is degenerate. */
PRECISE float thin_dihedral_angle(float3 x0, float3 x1, float3 x2, float3 x3) {
  PRECISE float3 e = x1 - x0;
  PRECISE float3 n1 = cross3(e, x2 - x0), n2 = cross3(x3 - x0, e);
  PRECISE float l1 = sqrt(dot3(n1, n1)), l2 = sqrt(dot3(n2, n2)), le = sqrt(dot3(e, e));
  if (l1 > 0.0f && l2 > 0.0f && le > 0.0f) {
    PRECISE float3 u1 = (1.0f / l1) * n1, u2 = (1.0f / l2) * n2;
    PRECISE float s = dot3(cross3(u1, u2), e) / le;  // sin theta
    PRECISE float c = dot3(u1, u2);                  // cos theta
    PRECISE float theta = thin_atan2_portable(s, c);
    return theta;
  }
  return 0.0f;
}

/* thin::wrap_angle: d, a difference of two angles, wrapped into -pi..pi. */
PRECISE float thin_wrap_angle(float d) {
  if (d > THIN_PI) {
    PRECISE float r = d - 2.0f * THIN_PI;
    return r;
  }
  if (d < -THIN_PI) {
    PRECISE float r = d + 2.0f * THIN_PI;
    return r;
  }
  return d;
}

/* thin::dihedral_angle_gradients (Bridson et al. 2003): not ok, with g
 * zero, when the edge or a wing is degenerate. */
ThinGradients thin_dihedral_angle_gradients(float3 x0, float3 x1, float3 x2, float3 x3) {
  ThinGradients r = thin_no_direction();
  PRECISE float3 e = x1 - x0, a = x2 - x0, b = x3 - x0;
  PRECISE float3 n1 = cross3(e, a), n2 = cross3(b, e);
  PRECISE float q1 = dot3(n1, n1), q2 = dot3(n2, n2), qe = dot3(e, e);
  if (q1 > 0.0f && q2 > 0.0f && qe > 0.0f) {
    PRECISE float le = sqrt(qe);
    PRECISE float3 h2 = (-le / q1) * n1;
    PRECISE float3 h3 = (-le / q2) * n2;
    PRECISE float s2 = dot3(a, e) / qe, s3 = dot3(b, e) / qe;
    const float3 zero = make_float3(0.0f, 0.0f, 0.0f);
    PRECISE float3 h1 = zero - (s2 * h2 + s3 * h3);
    PRECISE float3 h0 = zero - ((1.0f - s2) * h2 + (1.0f - s3) * h3);
    r.g[0] = h0;
    r.g[1] = h1;
    r.g[2] = h2;
    r.g[3] = h3;
    r.ok = true;
  }
  return r;
}

/* thin::line_bending_offset (Kelager et al. 2010): |x_v - c|,
 * c = (x_b0 + x_v + x_b1) / 3. */
PRECISE float thin_line_bending_offset(float3 b0, float3 v, float3 b1) {
  PRECISE float3 d = v - (1.0f / 3.0f) * (b0 + v + b1);
  PRECISE float len = sqrt(dot3(d, d));
  return len;
}

/* thin::line_bending_gradients: (grad_b0, grad_v, grad_b1); not ok, with g
 * zero, when x_v is at the centroid. */
ThinGradients thin_line_bending_gradients(float3 b0, float3 v, float3 b1) {
  ThinGradients r = thin_no_direction();
  PRECISE float3 d = v - (1.0f / 3.0f) * (b0 + v + b1);
  PRECISE float len = sqrt(dot3(d, d));
  if (len > 0.0f) {
    PRECISE float3 n = (1.0f / len) * d;
    PRECISE float3 h1 = (2.0f / 3.0f) * n;
    PRECISE float3 h0 = (-1.0f / 3.0f) * n;
    r.g[0] = h0;
    r.g[1] = h1;
    r.g[2] = h0;
    r.ok = true;
  }
  return r;
}

/* The guard of thin_kernels.cpp's apply(), positively: a usable step needs
 * total > 0 (not all immovable and rigid) and finite (no overflowed
 * gradient); NaN fails both comparisons. */
bool thin_step_usable(float total) { return total > 0.0f && total <= THIN_FLOAT_MAX; }

/* The xPBD step of one constraint over its n particles xs with gradients
 * gr: twin of thin_kernels.cpp's apply<N>, the same sums in the same order.
 * Without a direction (gr not ok) or a usable step it keeps lambda and moves
 * nothing. */
ThinStep thin_step(ThinGradients gr, const float4 xs[4], int n, float c, float alpha_t, float lambda_i) {
  ThinStep s;
  s.lambda = lambda_i;
  s.dlambda = 0.0f;
  s.moved = false;
  if (!gr.ok) return s;
  PRECISE float w = 0.0f;
  for (int k = 0; k < n; ++k) w += xs[k].w * dot3(gr.g[k], gr.g[k]);
  PRECISE float total = w + alpha_t;
  if (!thin_step_usable(total)) return s;  // positive inside: NaN gives false, so it lands here
  PRECISE float dlambda = (-c - alpha_t * lambda_i) / total;
  PRECISE float lambda_n = lambda_i + dlambda;
  s.lambda = lambda_n;
  s.dlambda = dlambda;
  s.moved = true;
  return s;
}

/* Particle xk (w > 0) moved by the step: xk + (w dlambda) g. The kernel
 * writes movable particles only (several constraints of a colour may share
 * an immovable one). */
float4 thin_moved(float4 xk, float dlambda, float3 g) {
  PRECISE float3 y = xk.xyz + (xk.w * dlambda) * g;
  return make_float4_xyz(y, xk.w);
}

#endif /* SINEW_THIN_MATH_H */
