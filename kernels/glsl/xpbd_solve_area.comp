// xpbd_solve_area.comp — GLSL twin of
// kernels/cpu/thin_kernels.cpp:xpbd_solve_area (and the OpenCL one).
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016, eq. 18. One invocation per triangle of
// one colour: C = |(x1 - x0) x (x2 - x0)| / 2 - A0, data (A0 [m^2],
// alpha [m^3/N]) as kernels/shared/thin_params.h lays out.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "thin_math.h"
#include "thin_params.h"
#include "xpbd_params.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { SolveParams p; };
layout(std430, binding = 0) buffer Position { vec4 x[]; };
layout(std430, binding = 1) readonly buffer Indices { uint idx[]; };
layout(std430, binding = 2) readonly buffer Data { vec2 data[]; };
layout(std430, binding = 3) buffer Lambda { float lambda[]; };
layout(std430, binding = 4) writeonly buffer Residual { float residual[]; };
#include "thin_apply.h"

void main() {
  const uint gid = gl_GlobalInvocationID.x;
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const uint i0 = idx[3u * i], i1 = idx[3u * i + 1u], i2 = idx[3u * i + 2u];
  const vec4 x0 = x[i0], x1 = x[i1], x2 = x[i2];
  const vec2 d = data[i];
  precise float alpha_t = d.y * p.inv_h2;
  const float lambda_i = p.reset_lambda != 0u ? 0.0 : lambda[i];
  precise float c = thin_triangle_area(x0.xyz, x1.xyz, x2.xyz) - d.x;  // rounds as the rest area did
  if (p.measure_only != 0u) {
    precise float r = abs(c + alpha_t * lambda_i) / d.x;
    residual[i] = r;
    return;
  }
  // Guards as positive conditions (see thin_math.h): a collapsed element has no
  // direction, and a step needs a positive, finite denominator; else lambda is
  // kept and nothing moves.
  vec3 g0, g1, g2;
  if (thin_triangle_area_gradients(x0.xyz, x1.xyz, x2.xyz, g0, g1, g2)) {
    thin_apply(i, uint[4](i0, i1, i2, 0u), vec4[4](x0, x1, x2, vec4(0.0)),
               vec3[4](g0, g1, g2, vec3(0.0)), 3, c, alpha_t, lambda_i);
    return;
  }
  lambda[i] = lambda_i;
}
