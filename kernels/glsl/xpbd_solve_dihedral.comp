// xpbd_solve_dihedral.comp — GLSL twin of
// kernels/cpu/thin_kernels.cpp:xpbd_solve_dihedral (and the OpenCL one).
// Macklin, Müller, Chentanez, "XPBD", MIG 2016, eq. 18; the angle and its
// gradients of Bridson, Marino, Fedkiw, "Simulation of Clothing with Folds
// and Wrinkles", SCA 2003, section 4 (thin_math.h). One invocation per
// hinge (x0, x1 the shared edge, x2, x3 the wings) of one colour:
// C = wrap(theta - theta0), data (theta0 [rad], alpha [1/(N m)]).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "thin_math.h"
#include "thin_params.h"
#include "xpbd_params.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { SolveParams p; };
layout(std430, binding = 0) buffer Position { vec4 x[]; };
layout(std430, binding = 1) readonly buffer Indices { uvec4 idx[]; };
layout(std430, binding = 2) readonly buffer Data { vec2 data[]; };
layout(std430, binding = 3) buffer Lambda { float lambda[]; };
layout(std430, binding = 4) writeonly buffer Residual { float residual[]; };
#include "thin_apply.h"

void main() {
  const uint gid = gl_GlobalInvocationID.x;
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  const uvec4 h = idx[i];
  const vec4 x0 = x[h.x], x1 = x[h.y], x2 = x[h.z], x3 = x[h.w];
  const vec2 d = data[i];
  precise float alpha_t = d.y * p.inv_h2;
  const float lambda_i = p.reset_lambda != 0u ? 0.0 : lambda[i];
  // Wrapped, so that a hinge at rest near +-pi has no jump; 0 exactly at rest.
  precise float c = thin_wrap_angle(thin_dihedral_angle(x0.xyz, x1.xyz, x2.xyz, x3.xyz) - d.x);
  if (p.measure_only != 0u) {
    precise float r = abs(c + alpha_t * lambda_i);  // radians
    residual[i] = r;
    return;
  }
  // Guards as positive conditions (see thin_math.h): a collapsed element has no
  // direction, and a step needs a positive, finite denominator; else lambda is
  // kept and nothing moves.
  vec3 g0, g1, g2, g3;
  if (thin_dihedral_angle_gradients(x0.xyz, x1.xyz, x2.xyz, x3.xyz, g0, g1, g2, g3)) {
    thin_apply(i, uint[4](h.x, h.y, h.z, h.w), vec4[4](x0, x1, x2, x3),
               vec3[4](g0, g1, g2, g3), 4, c, alpha_t, lambda_i);
    return;
  }
  lambda[i] = lambda_i;
}
