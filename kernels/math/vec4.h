// vec4.h — the small vector type of the constraint math (kernels/math/),
// used by the CPU reference kernels (kernels/cpu/) and by the scene
// compiler's rest values (src/compiler/).
//
// vec4 mirrors the buffers' layout (xyz + w, 16 bytes for float) and
// OpenCL's float4, so a CPU kernel reads like its GPU twin. The kernels use
// float4; tests instantiate the same constraint functions with double to
// check gradients by finite differences. + - * act on all four lanes; dot3
// and cross3 on xyz only.
#pragma once

#include <cmath>
#include <cstdint>

namespace sinew::kernels {

template <class T>
struct alignas(16) vec4 {
  T x, y, z, w;
};
using float4 = vec4<float>;
using double4 = vec4<double>;

struct float2 {
  float x, y;
};
struct uint2 {
  std::uint32_t x, y;
};
struct alignas(16) uint4 {
  std::uint32_t x, y, z, w;
};

template <class T>
inline vec4<T> operator+(vec4<T> a, vec4<T> b) { return {a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w}; }
template <class T>
inline vec4<T> operator-(vec4<T> a, vec4<T> b) { return {a.x - b.x, a.y - b.y, a.z - b.z, a.w - b.w}; }
template <class T>
inline vec4<T> operator*(T s, vec4<T> a) { return {s * a.x, s * a.y, s * a.z, s * a.w}; }
template <class T>
inline T dot3(vec4<T> a, vec4<T> b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class T>
inline vec4<T> cross3(vec4<T> a, vec4<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x, T(0)};
}
/// a + s * d on xyz, keeping a.w (the inverse mass stored in w).
template <class T>
inline vec4<T> add_scaled3(vec4<T> a, T s, vec4<T> d) { return {a.x + s * d.x, a.y + s * d.y, a.z + s * d.z, a.w}; }

}  // namespace sinew::kernels
