// xpbd_solve_volume.cl — OpenCL twin of xpbd_kernels.cpp:xpbd_solve_volume.
// Macklin, Müller, Chentanez, "XPBD", MIG 2016. One work item per tet of one
// colour: C = V - rest with V = dot(x1 - x0, cross(x2 - x0, x3 - x0)) / 6.
#include "cl_math.h"
#include "xpbd_params.h"

kernel void xpbd_solve_volume(global float4* x, global const uint4* idx, global const float2* rest_alpha,
                              global float* lambda, global float* residual, SolveParams p) {
  const uint gid = get_global_id(0);
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const uint4 t = idx[i];
  const float4 x0 = x[t.x], x1 = x[t.y], x2 = x[t.z], x3 = x[t.w];
  const float3 e1 = x1.xyz - x0.xyz, e2 = x2.xyz - x0.xyz, e3 = x3.xyz - x0.xyz;
  const float sixth = 1.0f / 6.0f;
  const float3 c23 = cross3(e2, e3);
  const float3 g1 = sixth * c23, g2 = sixth * cross3(e3, e1), g3 = sixth * cross3(e1, e2);
  const float3 g0 = (float3)(0.0f) - (g1 + g2 + g3);
  const float w = x0.w * dot3(g0, g0) + x1.w * dot3(g1, g1) + x2.w * dot3(g2, g2) + x3.w * dot3(g3, g3);
  const float alpha_t = rest_alpha[i].y * p.inv_h2;
  const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
  const float c = dot3(e1, c23) * sixth - rest_alpha[i].x;
  if (p.measure_only) {
    residual[i] = fabs(c + alpha_t * lambda_i) / rest_alpha[i].x;
    return;
  }
  if (w + alpha_t <= 0.0f) {
    lambda[i] = lambda_i;
    return;
  }
  const float dlambda = (-c - alpha_t * lambda_i) / (w + alpha_t);
  if (x0.w > 0.0f) x[t.x] = (float4)(x0.xyz + (x0.w * dlambda) * g0, x0.w);
  if (x1.w > 0.0f) x[t.y] = (float4)(x1.xyz + (x1.w * dlambda) * g1, x1.w);
  if (x2.w > 0.0f) x[t.z] = (float4)(x2.xyz + (x2.w * dlambda) * g2, x2.w);
  if (x3.w > 0.0f) x[t.w] = (float4)(x3.xyz + (x3.w * dlambda) * g3, x3.w);
  lambda[i] = lambda_i + dlambda;
}
