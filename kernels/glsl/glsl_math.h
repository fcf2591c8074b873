/* glsl_math.h — vector helpers of the GLSL kernels that round exactly like
 * kernels/cpu/cpu_math.h and kernels/opencl/cl_math.h: dot and cross
 * products written out in the CPU code's order, and `precise` (SPIR-V
 * NoContraction) so no driver fuses a multiply and an add. Every kernel
 * declares its arithmetic results `precise` for the same reason. Then a rest
 * value computed on the host is reproduced exactly, and a body at rest stays
 * bitwise at rest on Vulkan too. */
#ifndef SINEW_GLSL_MATH_H
#define SINEW_GLSL_MATH_H

precise float dot3(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

precise vec3 cross3(vec3 a, vec3 b) {
  return vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

#endif /* SINEW_GLSL_MATH_H */
