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
 * like the CPU kernels'. The angle's atan2 is not the builtin: the CPU's is
 * thin::atan2_portable, our own from + - * / and sqrt, and
 * thin_atan2_portable below repeats it operation for operation; a device's
 * builtin atan2 differs from it in the last bits or more, and then a hinge
 * at its rest angle would not have C == 0 exactly. */
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

/* ---- atan2: thin::atan2_portable<float> of kernels/cpu/thin_kernels.h,
 * operation for operation (the algorithm, its identities and the number of
 * series terms are explained there): only + - * / and sqrt, correctly
 * rounded here as on the CPU, in the CPU's order without contraction, so
 * every angle has the CPU's bits. */

#define THIN_PI_2 0x1.921fb6p+0f /* THIN_PI / 2 (exact), as thin::pi<float> / 2 */
#define THIN_PI_4 0x1.921fb6p-1f /* THIN_PI / 4 (exact), as thin::pi<float> / 4 */

/* atan(r) for r in [0, 1]: 2 atan(t), t = r / (1 + sqrt(1 + r^2)), and nine
 * terms of atan(t) = t - t^3/3 + t^5/5 - ... in Horner form in z = t^2; the
 * coefficients are (-1)^k / (2k + 1), k = 1..8, rounded to float, as the CPU
 * computes them (float(+-1) / float(2k + 1)). */
inline float thin_atan01(float r) {
  const float t = r / (1.0f + sqrt(1.0f + r * r));
  const float z = t * t;
  const float q =
      -0x1.555556p-2f +
      z * (0x1.99999ap-3f +
           z * (-0x1.24924ap-3f +
                z * (0x1.c71c72p-4f +
                     z * (-0x1.745d18p-4f + z * (0x1.3b13b2p-4f + z * (-0x1.111112p-4f + z * 0x1.e1e1e2p-5f))))));
  return 2.0f * (t + t * (z * q));
}

/* thin::atan2_portable(y, x) in [-pi, pi], C's conventions for signed zeros,
 * infinities and NaN. */
inline float thin_atan2_portable(float y, float x) {
  if (isnan(x) || isnan(y)) return x + y;
  const float ax = fabs(x), ay = fabs(y);
  float a;
  if (ax == ay) a = ax == 0.0f ? 0.0f : THIN_PI_4;
  else if (ay < ax) a = thin_atan01(ay / ax);
  else a = THIN_PI_2 - thin_atan01(ax / ay);
  if (signbit(x)) a = THIN_PI - a;
  return signbit(y) ? -a : a;
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
  return thin_atan2_portable(s, c);
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

/* The xPBD step of one constraint over n particles (ids, their positions xs,
 * gradients g): twin of thin_kernels.cpp's apply<N>, the same sums in the
 * same order. Without a usable step it stores lambda unchanged and moves
 * nothing; immovable particles are never written (several constraints of a
 * colour may share one). */
inline void thin_apply(global float4* x, const uint* ids, const float4* xs, const float3* g, int n, float c,
                       float alpha_t, float lambda_i, global float* lambda_out) {
  float w = 0.0f;
  for (int k = 0; k < n; ++k) w += xs[k].w * dot3(g[k], g[k]);
  const float total = w + alpha_t;
  if (!thin_step_usable(total)) {
    *lambda_out = lambda_i;
    return;
  }
  const float dlambda = (-c - alpha_t * lambda_i) / total;
  for (int k = 0; k < n; ++k)
    if (xs[k].w > 0.0f) x[ids[k]] = (float4)(xs[k].xyz + (xs[k].w * dlambda) * g[k], xs[k].w);
  *lambda_out = lambda_i + dlambda;
}

#endif /* SINEW_THIN_MATH_H */
