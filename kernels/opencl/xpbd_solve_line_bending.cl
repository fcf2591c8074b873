// xpbd_solve_line_bending.cl — OpenCL twin of kernels/cpu/thin_kernels.cpp:
// xpbd_solve_line_bending. Kelager, Niebe, Erleben, "A Triangle Bending
// Constraint Model for Position-Based Dynamics", VRIPHYS 2010, solved as in
// Macklin, Müller, Chentanez, "XPBD", MIG 2016, eq. 18. One work item per
// thread vertex (b0, v, b1) of one colour: C = |x_v - c| - h0 with
// c = (x_b0 + x_v + x_b1) / 3, data (h0 [m], alpha [m/N], L [m], 0).
#include "thin_math.h"
#include "xpbd_params.h"

kernel void xpbd_solve_line_bending(global float4* x, global const uint* idx, global const float4* data,
                                    global float* lambda, global float* residual, SolveParams p) {
  const uint gid = get_global_id(0);
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const uint i0 = idx[3 * i], i1 = idx[3 * i + 1], i2 = idx[3 * i + 2];
  const float4 x0 = x[i0], x1 = x[i1], x2 = x[i2];
  const float4 d = data[i];
  const float alpha_t = d.y * p.inv_h2;
  const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
  const float c = thin_line_bending_offset(x0.xyz, x1.xyz, x2.xyz) - d.x;
  if (p.measure_only) {
    residual[i] = fabs(c + alpha_t * lambda_i) / d.z;  // per segment rest length
    return;
  }
  float3 g[3];
  if (!thin_line_bending_gradients(x0.xyz, x1.xyz, x2.xyz, g)) {  // vertex at the centroid: no direction
    lambda[i] = lambda_i;
    return;
  }
  const uint ids[3] = {i0, i1, i2};
  const float4 xs[3] = {x0, x1, x2};
  thin_apply(x, ids, xs, g, 3, c, alpha_t, lambda_i, &lambda[i]);
}
