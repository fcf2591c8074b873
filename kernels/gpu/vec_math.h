/* vec_math.h — the vector helpers of the GPU kernels, rounding exactly like
 * kernels/math/vec4.h: dot and cross products written out in the CPU
 * code's order (the builtins dot/cross may fuse or reorder) and every result
 * PRECISE (gpu_lang.h: no fused multiply-add in either language). Then a
 * rest value computed on the host is reproduced exactly, and a body at rest
 * stays bitwise at rest on the GPU too. */
#ifndef SINEW_VEC_MATH_H
#define SINEW_VEC_MATH_H

#include "gpu_lang.h"

PRECISE float dot3(float3 a, float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

PRECISE float3 cross3(float3 a, float3 b) {
  return make_float3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

#endif /* SINEW_VEC_MATH_H */
