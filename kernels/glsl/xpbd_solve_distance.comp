// xpbd_solve_distance.comp — GLSL twin of
// kernels/cpu/xpbd_kernels.cpp:xpbd_solve_distance (and the OpenCL one).
// Macklin, Müller, Chentanez, "XPBD", MIG 2016, eq. 18. One invocation per
// constraint of one colour: C = |x_a - x_b| - rest, alpha [m/N].
#version 450
#extension GL_GOOGLE_include_directive : require
#include "glsl_math.h"
#include "xpbd_params.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { SolveParams p; };
layout(std430, binding = 0) buffer Position { vec4 x[]; };
layout(std430, binding = 1) readonly buffer Indices { uvec2 idx[]; };
layout(std430, binding = 2) readonly buffer RestAlpha { vec2 rest_alpha[]; };
layout(std430, binding = 3) buffer Lambda { float lambda[]; };
layout(std430, binding = 4) writeonly buffer Residual { float residual[]; };

void main() {
  const uint gid = gl_GlobalInvocationID.x;
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const uvec2 e = idx[i];
  const vec4 xa = x[e.x], xb = x[e.y];
  const vec2 ra = rest_alpha[i];
  precise vec3 d = xa.xyz - xb.xyz;
  precise float len = sqrt(dot3(d, d));
  precise float w = xa.w + xb.w;
  precise float alpha_t = ra.y * p.inv_h2;
  const float lambda_i = p.reset_lambda != 0u ? 0.0 : lambda[i];
  precise float c = len - ra.x;
  if (p.measure_only != 0u) {
    precise float r = abs(c + alpha_t * lambda_i) / ra.x;
    residual[i] = r;
    return;
  }
  precise float denominator = w + alpha_t;
  if (len <= 0.0 || denominator <= 0.0) {
    lambda[i] = lambda_i;
    return;
  }
  precise float dlambda = (-c - alpha_t * lambda_i) / denominator;
  precise vec3 n = (1.0 / len) * d;
  // Immovable particles are never written (several constraints of a colour may share one).
  if (xa.w > 0.0) {
    precise vec3 ya = xa.xyz + (xa.w * dlambda) * n;
    x[e.x] = vec4(ya, xa.w);
  }
  if (xb.w > 0.0) {
    precise vec3 yb = xb.xyz + (-xb.w * dlambda) * n;
    x[e.y] = vec4(yb, xb.w);
  }
  precise float lambda_n = lambda_i + dlambda;
  lambda[i] = lambda_n;
}
