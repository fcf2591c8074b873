// xpbd_solve_area.cl — OpenCL twin of kernels/cpu/thin_kernels.cpp:
// xpbd_solve_area. Macklin, Müller, Chentanez, "XPBD: Position-Based
// Simulation of Compliant Constrained Dynamics", MIG 2016, eq. 18. One work
// item per triangle of one colour: C = |(x1 - x0) x (x2 - x0)| / 2 - A0,
// data (A0 [m^2], alpha [m^3/N]) as kernels/shared/thin_params.h lays out.
#include "thin_math.h"
#include "xpbd_params.h"

kernel void xpbd_solve_area(global float4* x, global const uint* idx, global const float2* data,
                            global float* lambda, global float* residual, SolveParams p) {
  const uint gid = get_global_id(0);
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const uint i0 = idx[3 * i], i1 = idx[3 * i + 1], i2 = idx[3 * i + 2];
  const float4 x0 = x[i0], x1 = x[i1], x2 = x[i2];
  const float2 d = data[i];
  const float alpha_t = d.y * p.inv_h2;
  const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
  const float c = thin_triangle_area(x0.xyz, x1.xyz, x2.xyz) - d.x;  // rounds as the rest area did
  if (p.measure_only) {
    residual[i] = fabs(c + alpha_t * lambda_i) / d.x;
    return;
  }
  float3 g[3];
  if (!thin_triangle_area_gradients(x0.xyz, x1.xyz, x2.xyz, g)) {  // collapsed: no direction
    lambda[i] = lambda_i;
    return;
  }
  const uint ids[3] = {i0, i1, i2};
  const float4 xs[3] = {x0, x1, x2};
  thin_apply(x, ids, xs, g, 3, c, alpha_t, lambda_i, &lambda[i]);
}
