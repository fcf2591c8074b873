/* sinew_lang.h — lets one declaration of a kernel's parameters be read by
 * C++ (host and CPU kernels), OpenCL C and GLSL (Vulkan).
 *
 * Rules for shared structs, so that every language lays them out alike:
 *  - only 4-byte scalars (float, uint, int) between SINEW_STRUCT_BEGIN/END;
 *  - total size a multiple of 16 bytes (pad explicitly);
 *  - no vectors: std140/std430, OpenCL and C++ disagree on float3 alignment.
 * Buffers hold float4 (xyz + inverse mass in w) for the same reason. */
#ifndef SINEW_LANG_H
#define SINEW_LANG_H

#if defined(__OPENCL_VERSION__) || defined(__OPENCL_C_VERSION__)
/* OpenCL C: uint and float exist. */
#define SINEW_STRUCT_BEGIN(name) typedef struct name {
#define SINEW_STRUCT_END(name) } name;
#elif defined(VULKAN) || defined(GL_core_profile) || defined(GL_es_profile)
/* GLSL: uint and float exist; structs are not typedef'd. */
#define SINEW_STRUCT_BEGIN(name) struct name {
#define SINEW_STRUCT_END(name) };
#else
/* C++ */
#include <cstdint>
namespace sinew::kernels {
using uint = std::uint32_t;
}
#define SINEW_STRUCT_BEGIN(name) struct name {
#define SINEW_STRUCT_END(name) }; static_assert(sizeof(name) % 16 == 0, #name " must be a multiple of 16 bytes");
#endif

#endif /* SINEW_LANG_H */
