// xpbd_solve_attachment.cl — OpenCL twin of
// kernels/cpu/contact_kernels.cpp:xpbd_solve_attachment.
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016. One work item per attachment of one
// colour: C = |x - target(substep_end)| (zero rest length), gradient
// (x - target) / C; nothing done where C == 0 or the particle is immovable.
#include "contact_math.h"
#include "xpbd_params.h"

kernel void xpbd_solve_attachment(global float4* x, global const uint* idx, global const float2* data,
                                  global float* lambda, global float* residual, global const TargetEntry* targets,
                                  SolveParams p) {
  const uint gid = get_global_id(0);
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const float4 xi = x[idx[i]];
  const float2 di = data[i];  // (target index, alpha)
  global const TargetEntry* target = targets + (uint)di.x;
  const float3 goal = contact_lerp3((float3)(target->start_x, target->start_y, target->start_z),
                                    (float3)(target->end_x, target->end_y, target->end_z), p.substep_end);
  const float3 d = xi.xyz - goal;
  const float c = contact_length3(d);  // zero rest length
  const float alpha_t = di.y * p.inv_h2;
  const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
  if (p.measure_only) {
    residual[i] = fabs(c + alpha_t * lambda_i);  // [m]: no rest value to normalise by
    return;
  }
  // On the target the gradient is undefined and C = 0: nothing to do.
  // Immovable particles are never written.
  if (!(c > 0.0f) || !(xi.w > 0.0f)) {
    lambda[i] = lambda_i;
    return;
  }
  const float dlambda = (-c - alpha_t * lambda_i) / (xi.w + alpha_t);
  x[idx[i]] = (float4)(xi.xyz + (xi.w * dlambda / c) * d, xi.w);
  lambda[i] = lambda_i + dlambda;
}
