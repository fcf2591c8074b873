// xpbd_solve_volume.comp — GLSL twin of
// kernels/cpu/xpbd_kernels.cpp:xpbd_solve_volume (and the OpenCL one).
// Macklin, Müller, Chentanez, "XPBD", MIG 2016. One invocation per tet of one
// colour: C = V - rest with V = dot(x1 - x0, cross(x2 - x0, x3 - x0)) / 6.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "glsl_math.h"
#include "xpbd_params.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { SolveParams p; };
layout(std430, binding = 0) buffer Position { vec4 x[]; };
layout(std430, binding = 1) readonly buffer Indices { uvec4 idx[]; };
layout(std430, binding = 2) readonly buffer RestAlpha { vec2 rest_alpha[]; };
layout(std430, binding = 3) buffer Lambda { float lambda[]; };
layout(std430, binding = 4) writeonly buffer Residual { float residual[]; };

void main() {
  const uint gid = gl_GlobalInvocationID.x;
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const uvec4 t = idx[i];
  const vec4 x0 = x[t.x], x1 = x[t.y], x2 = x[t.z], x3 = x[t.w];
  const vec2 ra = rest_alpha[i];
  precise vec3 e1 = x1.xyz - x0.xyz, e2 = x2.xyz - x0.xyz, e3 = x3.xyz - x0.xyz;
  const float sixth = 1.0 / 6.0;
  precise vec3 c23 = cross3(e2, e3);
  precise vec3 g1 = sixth * c23, g2 = sixth * cross3(e3, e1), g3 = sixth * cross3(e1, e2);
  precise vec3 g0 = vec3(0.0) - ((g1 + g2) + g3);
  precise float w = x0.w * dot3(g0, g0) + x1.w * dot3(g1, g1) + x2.w * dot3(g2, g2) + x3.w * dot3(g3, g3);
  precise float alpha_t = ra.y * p.inv_h2;
  const float lambda_i = p.reset_lambda != 0u ? 0.0 : lambda[i];
  precise float c = dot3(e1, c23) * sixth - ra.x;
  if (p.measure_only != 0u) {
    precise float r = abs(c + alpha_t * lambda_i) / ra.x;
    residual[i] = r;
    return;
  }
  precise float denominator = w + alpha_t;
  if (denominator <= 0.0) {  // fully collapsed or immovable: no direction
    lambda[i] = lambda_i;
    return;
  }
  precise float dlambda = (-c - alpha_t * lambda_i) / denominator;
  if (x0.w > 0.0) { precise vec3 y = x0.xyz + (x0.w * dlambda) * g0; x[t.x] = vec4(y, x0.w); }
  if (x1.w > 0.0) { precise vec3 y = x1.xyz + (x1.w * dlambda) * g1; x[t.y] = vec4(y, x1.w); }
  if (x2.w > 0.0) { precise vec3 y = x2.xyz + (x2.w * dlambda) * g2; x[t.z] = vec4(y, x2.w); }
  if (x3.w > 0.0) { precise vec3 y = x3.xyz + (x3.w * dlambda) * g3; x[t.w] = vec4(y, x3.w); }
  precise float lambda_n = lambda_i + dlambda;
  lambda[i] = lambda_n;
}
