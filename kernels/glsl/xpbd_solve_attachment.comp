// xpbd_solve_attachment.comp — GLSL twin of
// kernels/cpu/contact_kernels.cpp:xpbd_solve_attachment (and the OpenCL one).
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016. One invocation per attachment of one
// colour: C = |x - target(substep_end)| (zero rest length), gradient
// (x - target) / C; nothing done where C == 0 or the particle is immovable.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "contact_math.h"
#include "xpbd_params.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { SolveParams p; };
layout(std430, binding = 0) buffer Position { vec4 x[]; };
layout(std430, binding = 1) readonly buffer Indices { uint idx[]; };
layout(std430, binding = 2) readonly buffer Data { vec2 data[]; };  // (target index, alpha)
layout(std430, binding = 3) buffer Lambda { float lambda[]; };
layout(std430, binding = 4) writeonly buffer Residual { float residual[]; };
layout(std430, binding = 5) readonly buffer Targets { TargetEntry targets[]; };

void main() {
  const uint gid = gl_GlobalInvocationID.x;
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const uint particle = idx[i];
  const vec4 xi = x[particle];
  const vec2 di = data[i];
  const TargetEntry target = targets[uint(di.x)];
  precise vec3 goal = contact_lerp3(vec3(target.start_x, target.start_y, target.start_z),
                                    vec3(target.end_x, target.end_y, target.end_z), p.substep_end);
  precise vec3 d = xi.xyz - goal;
  precise float c = contact_length3(d);  // zero rest length
  precise float alpha_t = di.y * p.inv_h2;
  const float lambda_i = p.reset_lambda != 0u ? 0.0 : lambda[i];
  if (p.measure_only != 0u) {
    precise float r = abs(c + alpha_t * lambda_i);  // [m]: no rest value to normalise by
    residual[i] = r;
    return;
  }
  // On the target the gradient is undefined and C = 0: nothing to do.
  // Immovable particles are never written.
  if (!(c > 0.0) || !(xi.w > 0.0)) {
    lambda[i] = lambda_i;
    return;
  }
  precise float dlambda = (-c - alpha_t * lambda_i) / (xi.w + alpha_t);
  precise float s = xi.w * dlambda / c;
  precise vec3 y = xi.xyz + s * d;
  x[particle] = vec4(y, xi.w);
  precise float lambda_new = lambda_i + dlambda;
  lambda[i] = lambda_new;
}
