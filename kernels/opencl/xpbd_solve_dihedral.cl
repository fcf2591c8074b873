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
  float w = 0.0f;
  w += x0.w * dot3(g[0], g[0]);
  w += x1.w * dot3(g[1], g[1]);
  w += x2.w * dot3(g[2], g[2]);
  w += x3.w * dot3(g[3], g[3]);
  const float total = w + alpha_t;
  if (!thin_step_usable(total)) {
    lambda[i] = lambda_i;
    return;
  }
  const float dlambda = (-c - alpha_t * lambda_i) / total;
  // Immovable particles are never written (several constraints of a colour may share one).
  if (x0.w > 0.0f) x[h.x] = (float4)(x0.xyz + (x0.w * dlambda) * g[0], x0.w);
  if (x1.w > 0.0f) x[h.y] = (float4)(x1.xyz + (x1.w * dlambda) * g[1], x1.w);
  if (x2.w > 0.0f) x[h.z] = (float4)(x2.xyz + (x2.w * dlambda) * g[2], x2.w);
  if (x3.w > 0.0f) x[h.w] = (float4)(x3.xyz + (x3.w * dlambda) * g[3], x3.w);
  lambda[i] = lambda_i + dlambda;
}
