// xpbd_predict.cl — OpenCL twin of kernels/cpu/xpbd_kernels.cpp:xpbd_predict.
// One work item per particle: v += h g; prev = x; x += h v (w > 0 only).
#include "cl_math.h"
#include "xpbd_params.h"

kernel void xpbd_predict(global float4* x, global float4* prev, global float4* v, PredictParams p) {
  const uint i = get_global_id(0);
  if (i >= p.count) return;
  const float4 xi = x[i];
  prev[i] = xi;
  if (xi.w == 0.0f) return;  // pinned or kinematic: inverse mass 0
  const float4 g = (float4)(p.gravity_x, p.gravity_y, p.gravity_z, 0.0f);
  const float4 vi = v[i] + p.h * g;
  v[i] = vi;
  x[i] = (float4)(xi.xyz + p.h * vi.xyz, xi.w);
}
