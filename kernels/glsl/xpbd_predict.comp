// xpbd_predict.comp — GLSL twin of kernels/cpu/xpbd_kernels.cpp:xpbd_predict
// (and kernels/opencl/xpbd_predict.cl). One invocation per particle:
// v += h g; prev = x; x += h v (w > 0 only).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "glsl_math.h"
#include "xpbd_params.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { PredictParams p; };
layout(std430, binding = 0) buffer Position { vec4 x[]; };
layout(std430, binding = 1) writeonly buffer Previous { vec4 prev[]; };
layout(std430, binding = 2) buffer Velocity { vec4 v[]; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= p.count) return;
  const vec4 xi = x[i];
  prev[i] = xi;
  if (xi.w == 0.0) return;  // pinned or kinematic: inverse mass 0
  const vec4 vo = v[i];
  precise vec3 vi = vo.xyz + p.h * vec3(p.gravity_x, p.gravity_y, p.gravity_z);
  v[i] = vec4(vi, vo.w);
  precise vec3 xn = xi.xyz + p.h * vi;
  x[i] = vec4(xn, xi.w);
}
