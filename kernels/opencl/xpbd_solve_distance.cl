// xpbd_solve_distance.cl — OpenCL twin of xpbd_kernels.cpp:xpbd_solve_distance.
// Macklin, Müller, Chentanez, "XPBD", MIG 2016, eq. 18. One work item per
// constraint of one colour: C = |x_a - x_b| - rest, alpha [m/N].
#include "cl_math.h"
#include "xpbd_params.h"

kernel void xpbd_solve_distance(global float4* x, global const uint2* idx, global const float2* rest_alpha,
                                global float* lambda, global float* residual, SolveParams p) {
  const uint gid = get_global_id(0);
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const uint2 e = idx[i];
  const float4 xa = x[e.x], xb = x[e.y];
  const float3 d = xa.xyz - xb.xyz;
  const float len = sqrt(dot3(d, d));
  const float w = xa.w + xb.w;
  const float alpha_t = rest_alpha[i].y * p.inv_h2;
  const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
  const float c = len - rest_alpha[i].x;
  if (p.measure_only) {
    residual[i] = fabs(c + alpha_t * lambda_i) / rest_alpha[i].x;
    return;
  }
  if (len <= 0.0f || w + alpha_t <= 0.0f) {
    lambda[i] = lambda_i;
    return;
  }
  const float dlambda = (-c - alpha_t * lambda_i) / (w + alpha_t);
  const float3 n = (1.0f / len) * d;
  // Immovable particles are never written (several constraints of a colour may share one).
  if (xa.w > 0.0f) x[e.x] = (float4)(xa.xyz + (xa.w * dlambda) * n, xa.w);
  if (xb.w > 0.0f) x[e.y] = (float4)(xb.xyz + (-xb.w * dlambda) * n, xb.w);
  lambda[i] = lambda_i + dlambda;
}
