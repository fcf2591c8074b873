/* nanovdb_lang.h — NanoVDB's portable reader, PNanoVDB.h (from the
 * libnanovdb-dev package, included from the system at build time, never
 * copied here), made available to the kernels in both of their languages
 * (issue 14; gpu_lang.h):
 *
 *  - GLSL (Vulkan): PNanoVDB's own GLSL mode. It reads the grid through a
 *    storage buffer it names `pnanovdb_buf_data`, declared here at binding
 *    SINEW_NANOVDB_BINDING (the kernel defines it before including this);
 *    the kernel lists that binding in SINEW_BINDINGS through
 *    SINEW_NANOVDB_GRID_ARG, which declares it in OpenCL only.
 *  - OpenCL C 1.2: PNanoVDB has no OpenCL mode, and its C mode keeps tables
 *    in program-scope `static const` arrays, which OpenCL C 1.2 rejects
 *    (they must be `constant`). So no mode is chosen and this header
 *    supplies the language layer the C mode would: the basic types, the
 *    conversions and the vector helpers, with the buffer a
 *    `global const uint*` passed to every call (PNANOVDB_BUF_CUSTOM).
 *
 * In both, addresses are 32-bit byte offsets (grids under 4 GiB) and a grid
 * is read from byte 0 of its buffer. Without NanoVDB (SINEW_OPENVDB off),
 * SINEW_HAS_NANOVDB is 0 and nothing is defined: kernels that sample grids
 * compile to empty bodies that nothing dispatches. */
#ifndef SINEW_NANOVDB_LANG_H
#define SINEW_NANOVDB_LANG_H

#include "sinew_nanovdb_config.h" /* generated: SINEW_HAS_NANOVDB */

#if SINEW_HAS_NANOVDB

#if defined(__OPENCL_VERSION__) || defined(__OPENCL_C_VERSION__)
/* ------------------------------------------------------------ OpenCL C 1.2 */
#ifdef cl_khr_fp64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#else
/* PNanoVDB declares (never calls, for float grids) readers of double values
 * and structs with double members that document the layout; a device
 * without fp64 gets them in float. */
#define double float
#endif
#define PNANOVDB_ADDRESS_32
#define PNANOVDB_BUF_CUSTOM
#define pnanovdb_buf_t global const uint*
uint pnanovdb_buf_read_uint32(pnanovdb_buf_t buf, uint byte_offset) { return buf[byte_offset >> 2u]; }
ulong pnanovdb_buf_read_uint64(pnanovdb_buf_t buf, uint byte_offset) {
  return (ulong)buf[byte_offset >> 2u] | ((ulong)buf[(byte_offset >> 2u) + 1u] << 32u);
}
/* The grid is read-only in the kernels. */
#define pnanovdb_buf_write_uint32(buf, byte_offset, value) ((void)0)
#define pnanovdb_buf_write_uint64(buf, byte_offset, value) ((void)0)
#define pnanovdb_grid_type_t uint
#define PNANOVDB_GRID_TYPE_GET(grid_typeIn, nameIn) pnanovdb_grid_type_constants[grid_typeIn].nameIn
#define PNANOVDB_FORCE_INLINE
#define PNANOVDB_STRUCT_TYPEDEF(X) typedef struct X X;
#define PNANOVDB_STATIC_CONST constant
#define PNANOVDB_INOUT(X) X*
#define PNANOVDB_IN(X) const X*
#define PNANOVDB_DEREF(X) (*X)
#define PNANOVDB_REF(X) &X
#define PNANOVDB_NATIVE_64
typedef uint pnanovdb_uint32_t;
typedef int pnanovdb_int32_t;
typedef int pnanovdb_bool_t;
#define PNANOVDB_FALSE 0
#define PNANOVDB_TRUE 1
typedef ulong pnanovdb_uint64_t;
typedef long pnanovdb_int64_t;
typedef struct pnanovdb_coord_t {
  pnanovdb_int32_t x, y, z;
} pnanovdb_coord_t;
typedef struct pnanovdb_vec3_t {
  float x, y, z;
} pnanovdb_vec3_t;
pnanovdb_int32_t pnanovdb_uint32_as_int32(pnanovdb_uint32_t v) { return as_int(v); }
pnanovdb_int64_t pnanovdb_uint64_as_int64(pnanovdb_uint64_t v) { return as_long(v); }
pnanovdb_uint64_t pnanovdb_int64_as_uint64(pnanovdb_int64_t v) { return as_ulong(v); }
pnanovdb_uint32_t pnanovdb_int32_as_uint32(pnanovdb_int32_t v) { return as_uint(v); }
float pnanovdb_uint32_as_float(pnanovdb_uint32_t v) { return as_float(v); }
#ifdef cl_khr_fp64
double pnanovdb_uint64_as_double(pnanovdb_uint64_t v) { return as_double(v); }
#else
double pnanovdb_uint64_as_double(pnanovdb_uint64_t v) { return 0.0f; }
#endif
pnanovdb_uint32_t pnanovdb_uint64_low(pnanovdb_uint64_t v) { return (pnanovdb_uint32_t)v; }
pnanovdb_uint32_t pnanovdb_uint64_high(pnanovdb_uint64_t v) { return (pnanovdb_uint32_t)(v >> 32u); }
pnanovdb_uint64_t pnanovdb_uint32_as_uint64(pnanovdb_uint32_t x, pnanovdb_uint32_t y) {
  return ((pnanovdb_uint64_t)x) | (((pnanovdb_uint64_t)y) << 32u);
}
pnanovdb_uint64_t pnanovdb_uint32_as_uint64_low(pnanovdb_uint32_t x) { return (pnanovdb_uint64_t)x; }
pnanovdb_int32_t pnanovdb_uint64_is_equal(pnanovdb_uint64_t a, pnanovdb_uint64_t b) { return a == b; }
pnanovdb_int32_t pnanovdb_int64_is_zero(pnanovdb_int64_t a) { return a == 0; }
pnanovdb_int32_t pnanovdb_float_to_int32(float v) { return (pnanovdb_int32_t)v; }
float pnanovdb_int32_to_float(pnanovdb_int32_t v) { return (float)v; }
float pnanovdb_uint32_to_float(pnanovdb_uint32_t v) { return (float)v; }
float pnanovdb_min(float a, float b) { return a < b ? a : b; }
float pnanovdb_max(float a, float b) { return a > b ? a : b; }
pnanovdb_vec3_t pnanovdb_vec3_uniform(float a) {
  pnanovdb_vec3_t v = {a, a, a};
  return v;
}
pnanovdb_vec3_t pnanovdb_vec3_add(const pnanovdb_vec3_t a, const pnanovdb_vec3_t b) {
  pnanovdb_vec3_t v = {a.x + b.x, a.y + b.y, a.z + b.z};
  return v;
}
pnanovdb_vec3_t pnanovdb_vec3_sub(const pnanovdb_vec3_t a, const pnanovdb_vec3_t b) {
  pnanovdb_vec3_t v = {a.x - b.x, a.y - b.y, a.z - b.z};
  return v;
}
pnanovdb_vec3_t pnanovdb_vec3_mul(const pnanovdb_vec3_t a, const pnanovdb_vec3_t b) {
  pnanovdb_vec3_t v = {a.x * b.x, a.y * b.y, a.z * b.z};
  return v;
}
pnanovdb_vec3_t pnanovdb_vec3_div(const pnanovdb_vec3_t a, const pnanovdb_vec3_t b) {
  pnanovdb_vec3_t v = {a.x / b.x, a.y / b.y, a.z / b.z};
  return v;
}
pnanovdb_vec3_t pnanovdb_vec3_min(const pnanovdb_vec3_t a, const pnanovdb_vec3_t b) {
  pnanovdb_vec3_t v = {a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z};
  return v;
}
pnanovdb_vec3_t pnanovdb_vec3_max(const pnanovdb_vec3_t a, const pnanovdb_vec3_t b) {
  pnanovdb_vec3_t v = {a.x > b.x ? a.x : b.x, a.y > b.y ? a.y : b.y, a.z > b.z ? a.z : b.z};
  return v;
}
pnanovdb_vec3_t pnanovdb_coord_to_vec3(const pnanovdb_coord_t coord) {
  pnanovdb_vec3_t v = {(float)coord.x, (float)coord.y, (float)coord.z};
  return v;
}
pnanovdb_coord_t pnanovdb_coord_uniform(const pnanovdb_int32_t a) {
  pnanovdb_coord_t v = {a, a, a};
  return v;
}
pnanovdb_coord_t pnanovdb_coord_add(pnanovdb_coord_t a, pnanovdb_coord_t b) {
  pnanovdb_coord_t v = {a.x + b.x, a.y + b.y, a.z + b.z};
  return v;
}
/* Its population count has a body per language and none for this one: it
 * returns nothing (only index grids call it; sinew's are float grids). */
#ifdef __clang__
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wreturn-type"
#endif
#include "sinew_pnanovdb.h" /* PNanoVDB.h (generated: see CMakeLists.txt) */
#ifdef __clang__
#pragma clang diagnostic pop
#endif
/* The buffer argument of a kernel that samples a grid, and the value its
 * helpers pass to PNanoVDB's calls. */
#define SINEW_NANOVDB_GRID_ARG(X, index, name) X(index, uint, name)
#define SINEW_NANOVDB_BUF(name) (name)

#else
/* ------------------------------------------------------------ GLSL 4.50 */
#ifndef SINEW_NANOVDB_BINDING
#error "define SINEW_NANOVDB_BINDING (the grid's binding) before including nanovdb_lang.h"
#endif
#define PNANOVDB_GLSL
layout(std430, binding = SINEW_NANOVDB_BINDING) readonly buffer NanoVdbGrid { uint pnanovdb_buf_data[]; };
#include "sinew_pnanovdb.h" /* PNanoVDB.h (generated: see CMakeLists.txt) */
#define SINEW_NANOVDB_GRID_ARG(X, index, name)
#define SINEW_NANOVDB_BUF(name) pnanovdb_buf_t(0u)
#endif

#endif /* SINEW_HAS_NANOVDB */
#endif /* SINEW_NANOVDB_LANG_H */
