/* cl_math.h — vector helpers of the OpenCL kernels that round exactly like
 * kernels/cpu/cpu_math.h: no fused multiply-add (FP_CONTRACT OFF) and dot
 * and cross products written out in the CPU code's order, because the
 * builtins may fuse or reorder. Then a rest value computed on the host is
 * reproduced exactly, and a body at rest stays bitwise at rest here too. */
#ifndef SINEW_CL_MATH_H
#define SINEW_CL_MATH_H

#pragma OPENCL FP_CONTRACT OFF

inline float dot3(float3 a, float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

inline float3 cross3(float3 a, float3 b) {
  return (float3)(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

#endif /* SINEW_CL_MATH_H */
