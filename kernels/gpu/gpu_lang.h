/* gpu_lang.h — the thin macro layer that lets one kernel source
 * (kernels/gpu/NAME.gpu) compile as OpenCL C 1.2 (embedded, built at run
 * time) and as GLSL 4.50 for Vulkan (glslc -> SPIR-V at build time). The
 * idea is Jolt Physics' ShaderCore.h: write the kernel once in the
 * intersection of the two languages, and let a few macros paper over the
 * declarations that differ. The CPU reference kernels (kernels/cpu) are not
 * generated from these: they are independent C++ and the oracle.
 *
 * A kernel file:
 *
 *   #include "gpu_lang.h"
 *   #include "primitive_params.h"        // its PARAMS struct (kernels/shared)
 *   #define SINEW_BINDINGS(X) X(0, uint, counts) X(1, float4, x)  // binding, type, name
 *   #define SINEW_SHARED(X) X(uint, tile, 256)                    // group memory (may be empty)
 *   SINEW_KERNEL_BEGIN(name, ParamsStruct, 256)                   // group size: 64 for independent items
 *     const uint i = global_id();  ... p.count ...                // parameters are `p`
 *   SINEW_KERNEL_END
 *
 * Rules of the intersection (both compilers reject the rest):
 *  - buffers are reached only through their binding names, never passed to
 *    functions (GLSL has no pointers); helper functions take values;
 *  - vector types float2/float3/float4/uint2/uint4 and make_float4(...)
 *    etc. (make_float4_xyz(v, w): a float3 and a w); no splats: write
 *    every component; conversions with to_uint(x), to_int(x), to_float(x),
 *    bit casts with float_bits(f) and bits_float(u); no C casts (GLSL), no
 *    constructors (OpenCL). float3 lives in registers only: buffers and
 *    shared structs hold float4 (see kernels/shared/sinew_lang.h);
 *  - float literals with the f suffix (1.0f: float in both; an unsuffixed
 *    literal is a double in OpenCL C); fabs(x) for a float's magnitude (GLSL
 *    abs; OpenCL's abs is for integers); sqrt, isnan, isinf alike in both;
 *  - helper functions return values: a struct (SINEW_STRUCT_BEGIN/END of
 *    kernels/shared/sinew_lang.h; any member types when only kernels use
 *    it) instead of out parameters, which GLSL spells `out` and OpenCL as
 *    pointers. Array parameters (float4 xs[4]) are read, never written: GLSL
 *    copies them in, OpenCL passes a pointer. Arrays are initialised with
 *    braces, {a, b, c}, never GLSL's float[3](...); no dynamic index into
 *    a vector (OpenCL), use an array;
 *  - no `inline` or `static` (reserved in GLSL); functions are plain;
 *  - declare float arithmetic results PRECISE (GLSL `precise`: no fused
 *    multiply-add; OpenCL: FP_CONTRACT OFF below), so kernels round like
 *    the CPU reference and agree bitwise;
 *  - float min/max as explicit comparisons (the builtins differ on NaN);
 *  - names that are keywords in either language are out: in, out, input,
 *    output, shared, buffer, sample, filter, common, partition, active,
 *    global, local, kernel, constant, half, char, short, long.
 * All OpenCL kernels are built as one program: the embedding #undefs
 * SINEW_BINDINGS and SINEW_SHARED after each file, and helper functions
 * need names unique across kernels (or an include-guarded header). */
#ifndef SINEW_GPU_LANG_H
#define SINEW_GPU_LANG_H

#if defined(__OPENCL_VERSION__) || defined(__OPENCL_C_VERSION__)
/* ------------------------------------------------------------ OpenCL C 1.2 */
#pragma OPENCL FP_CONTRACT OFF
#define PRECISE
#define SINEW_CL_ARG(index, type, name) global type* name,
#define SINEW_CL_SHARED(type, name, size) local type name[size];
#define SINEW_KERNEL_BEGIN(name, params_type, group_size)                                        \
  __attribute__((reqd_work_group_size(group_size, 1, 1))) kernel void name(                      \
      SINEW_BINDINGS(SINEW_CL_ARG) const params_type p) {                                        \
    SINEW_SHARED(SINEW_CL_SHARED)
#define SINEW_KERNEL_END }
#define global_id() ((uint)get_global_id(0))
#define local_id() ((uint)get_local_id(0))
#define group_id() ((uint)get_group_id(0))
/* Every item of the group reaches it; group memory and buffer writes before
 * it are visible to the group after it. */
#define group_barrier() barrier(CLK_LOCAL_MEM_FENCE | CLK_GLOBAL_MEM_FENCE)
#define make_float2(a, b) ((float2)((a), (b)))
#define make_float3(a, b, c) ((float3)((a), (b), (c)))
#define make_float4(a, b, c, d) ((float4)((a), (b), (c), (d)))
#define make_float4_xyz(v, w) ((float4)((v), (w)))
#define make_uint2(a, b) ((uint2)((a), (b)))
#define make_uint4(a, b, c, d) ((uint4)((a), (b), (c), (d)))
#define to_uint(x) ((uint)(x))
#define to_int(x) ((int)(x))
#define to_float(x) ((float)(x))
#define float_bits(f) as_uint(f)
#define bits_float(u) as_float(u)
#define atomic_add_u32(buf, index, value) atomic_add(&(buf)[index], (value))
#define atomic_max_u32(buf, index, value) atomic_max(&(buf)[index], (value))
#define atomic_or_u32(buf, index, value) atomic_or(&(buf)[index], (value))
#define count_leading_zeros(x) ((int)clz((uint)(x)))

#else
/* ------------------------------------------------------------ GLSL 4.50 (Vulkan) */
#define PRECISE precise
#define float2 vec2
#define float3 vec3
#define float4 vec4
#define uint2 uvec2
#define uint4 uvec4
#define SINEW_GLSL_BUFFER(index, type, name) \
  layout(std430, binding = index) buffer Binding##index { type name[]; };
#define SINEW_GLSL_SHARED(type, name, size) shared type name[size];
#define SINEW_KERNEL_BEGIN(name, params_type, group_size) \
  layout(local_size_x = group_size) in;                   \
  SINEW_BINDINGS(SINEW_GLSL_BUFFER)                       \
  SINEW_SHARED(SINEW_GLSL_SHARED)                         \
  layout(push_constant) uniform PushConstants { params_type p; }; \
  void main() {
#define SINEW_KERNEL_END }
#define global_id() gl_GlobalInvocationID.x
#define local_id() gl_LocalInvocationID.x
#define group_id() gl_WorkGroupID.x
#define group_barrier() \
  memoryBarrierShared();  \
  memoryBarrierBuffer();  \
  barrier()
#define make_float2(a, b) vec2((a), (b))
#define make_float3(a, b, c) vec3((a), (b), (c))
#define make_float4(a, b, c, d) vec4((a), (b), (c), (d))
#define make_float4_xyz(v, w) vec4((v), (w))
#define make_uint2(a, b) uvec2((a), (b))
#define make_uint4(a, b, c, d) uvec4((a), (b), (c), (d))
#define to_uint(x) uint(x)
#define to_int(x) int(x)
#define to_float(x) float(x)
#define float_bits(f) floatBitsToUint(f)
#define bits_float(u) uintBitsToFloat(u)
#define fabs(x) abs(x)
#define atomic_add_u32(buf, index, value) atomicAdd((buf)[index], (value))
#define atomic_max_u32(buf, index, value) atomicMax((buf)[index], (value))
#define atomic_or_u32(buf, index, value) atomicOr((buf)[index], (value))
/* 32 for 0, like OpenCL's clz (findMSB(0) is -1). */
#define count_leading_zeros(x) (31 - findMSB(uint(x)))
#endif

#endif /* SINEW_GPU_LANG_H */
