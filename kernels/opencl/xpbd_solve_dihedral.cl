// xpbd_solve_dihedral.cl — OpenCL twin of kernels/cpu/thin_kernels.cpp:
// xpbd_solve_dihedral. Macklin, Müller, Chentanez, "XPBD", MIG 2016, eq. 18;
// the angle and its gradients of Bridson, Marino, Fedkiw, "Simulation of
// Clothing with Folds and Wrinkles", SCA 2003, section 4 (thin_math.h). One
// work item per hinge (x0, x1 the shared edge, x2, x3 the wings) of one
// colour: C = wrap(theta - theta0), data (theta0 [rad], alpha [1/(N m)]).
#include "thin_math.h"
#include "xpbd_params.h"

kernel void xpbd_solve_dihedral(global float4* x, global const uint4* idx, global const float2* data,
                                global float* lambda, global float* residual, SolveParams p) {
  const uint gid = get_global_id(0);
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const uint4 h = idx[i];
  const float4 x0 = x[h.x], x1 = x[h.y], x2 = x[h.z], x3 = x[h.w];
  const float2 d = data[i];
  const float alpha_t = d.y * p.inv_h2;
  const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
  // Wrapped, so that a hinge at rest near +-pi has no jump; 0 exactly at rest.
  const float c = thin_wrap_angle(thin_dihedral_angle(x0.xyz, x1.xyz, x2.xyz, x3.xyz) - d.x);
  if (p.measure_only) {
    residual[i] = fabs(c + alpha_t * lambda_i);  // radians
    return;
  }
  float3 g[4];
  if (!thin_dihedral_angle_gradients(x0.xyz, x1.xyz, x2.xyz, x3.xyz, g)) {  // degenerate edge or wing
    lambda[i] = lambda_i;
    return;
  }
  const uint ids[4] = {h.x, h.y, h.z, h.w};
  const float4 xs[4] = {x0, x1, x2, x3};
  thin_apply(x, ids, xs, g, 4, c, alpha_t, lambda_i, &lambda[i]);
}
