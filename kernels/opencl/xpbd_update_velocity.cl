// xpbd_update_velocity.cl — OpenCL twin of xpbd_kernels.cpp:xpbd_update_velocity.
// One work item per particle: v = (x - prev) / h (w > 0), else 0.
#include "cl_math.h"
#include "xpbd_params.h"

kernel void xpbd_update_velocity(global const float4* x, global const float4* prev, global float4* v,
                                 UpdateVelocityParams p) {
  const uint i = get_global_id(0);
  if (i >= p.count) return;
  const float4 xi = x[i];
  v[i] = xi.w == 0.0f ? (float4)(0.0f) : (float4)((xi.xyz - prev[i].xyz) * p.inv_h, 0.0f);
}
