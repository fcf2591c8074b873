// xpbd_update_velocity.comp — GLSL twin of
// kernels/cpu/xpbd_kernels.cpp:xpbd_update_velocity. One invocation per
// particle: v = (x - prev) / h (w > 0), else 0.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "glsl_math.h"
#include "xpbd_params.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { UpdateVelocityParams p; };
layout(std430, binding = 0) readonly buffer Position { vec4 x[]; };
layout(std430, binding = 1) readonly buffer Previous { vec4 prev[]; };
layout(std430, binding = 2) writeonly buffer Velocity { vec4 v[]; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= p.count) return;
  const vec4 xi = x[i];
  if (xi.w == 0.0) {
    v[i] = vec4(0.0);
    return;
  }
  precise vec3 d = xi.xyz - prev[i].xyz;
  precise vec3 vi = d * p.inv_h;
  v[i] = vec4(vi, 0.0);
}
