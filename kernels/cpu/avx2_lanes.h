// avx2_lanes.h — eight float4 particles as AVX2 lanes, and the lane
// arithmetic of the AVX2 solves (xpbd_kernels_avx2.cpp, fem_kernels_avx2.cpp).
// Every operation rounds exactly like its scalar counterpart (no fused
// multiply-add, no approximate reciprocals), so lane j of a result equals
// the scalar code's result for item j bit for bit.
//
// Include only from files compiled for CPUs checked with cpu_has_avx2(): the
// functions are built for AVX2 (the target pragma below), and nothing else
// inline is instantiated between the pragmas.
#pragma once

#include <immintrin.h>

#include <cstdint>

#pragma GCC push_options
#pragma GCC target("avx2")

namespace sinew::kernels::avx2 {

struct Lanes {  // eight float4s, transposed
  __m256 x, y, z, w;
};

inline Lanes load_particles(const float* positions, const std::uint32_t (&index)[8]) {
  auto pair = [&](int lo, int hi) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(positions + 4 * index[lo])),
                                _mm_load_ps(positions + 4 * index[hi]), 1);
  };
  const __m256 r0 = pair(0, 4), r1 = pair(1, 5), r2 = pair(2, 6), r3 = pair(3, 7);
  const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
  const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
  return {_mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)), _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)),
          _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)), _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2))};
}

// Stores lane j to positions[index[j]] for the lanes whose bit is set in `store`.
inline void store_particles(float* positions, const std::uint32_t (&index)[8], const Lanes& p, int store) {
  const __m256 t0 = _mm256_unpacklo_ps(p.x, p.y), t1 = _mm256_unpackhi_ps(p.x, p.y);
  const __m256 t2 = _mm256_unpacklo_ps(p.z, p.w), t3 = _mm256_unpackhi_ps(p.z, p.w);
  const __m256 r[4] = {_mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)),
                       _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)),
                       _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)),
                       _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2))};
  for (int j = 0; j < 4; ++j) {
    if (store & (1 << j)) _mm_store_ps(positions + 4 * index[j], _mm256_castps256_ps128(r[j]));
    if (store & (1 << (j + 4))) _mm_store_ps(positions + 4 * index[j + 4], _mm256_extractf128_ps(r[j], 1));
  }
}

// (rest, alpha) pairs of constraints i..i+7 as two lane vectors.
inline void load_rest_alpha(const float* rest_alpha, __m256& rest, __m256& alpha) {
  const __m256 lo = _mm256_loadu_ps(rest_alpha), hi = _mm256_loadu_ps(rest_alpha + 8);
  // shuffle gives [r0 r1 r4 r5 | r2 r3 r6 r7]; the permute restores order.
  rest = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(2, 0, 2, 0))),
                                                _MM_SHUFFLE(3, 1, 2, 0)));
  alpha = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(3, 1, 3, 1))),
                                                 _MM_SHUFFLE(3, 1, 2, 0)));
}

inline __m256 add(__m256 a, __m256 b) { return _mm256_add_ps(a, b); }
inline __m256 sub(__m256 a, __m256 b) { return _mm256_sub_ps(a, b); }
inline __m256 mul(__m256 a, __m256 b) { return _mm256_mul_ps(a, b); }
inline __m256 positive(__m256 a) { return _mm256_cmp_ps(a, _mm256_setzero_ps(), _CMP_GT_OQ); }
// !(a <= 0): true for NaN too, as the scalar code's `if (a <= 0) skip` lets NaN through.
inline __m256 not_le_zero(__m256 a) { return _mm256_cmp_ps(a, _mm256_setzero_ps(), _CMP_NLE_UQ); }
// Unary minus (a sign flip), which differs from 0 - a for a == +0.
inline __m256 negate(__m256 a) { return _mm256_xor_ps(a, _mm256_set1_ps(-0.0f)); }

// dot3 as the scalar code rounds it: (a.x b.x + a.y b.y) + a.z b.z.
inline __m256 dot3(const Lanes& a, const Lanes& b) {
  return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z));
}
inline Lanes cross3(const Lanes& a, const Lanes& b) {
  return {sub(mul(a.y, b.z), mul(a.z, b.y)), sub(mul(a.z, b.x), mul(a.x, b.z)), sub(mul(a.x, b.y), mul(a.y, b.x)),
          _mm256_setzero_ps()};
}
inline Lanes minus(const Lanes& a, const Lanes& b) { return {sub(a.x, b.x), sub(a.y, b.y), sub(a.z, b.z), a.w}; }
inline Lanes scale(__m256 s, const Lanes& a) { return {mul(s, a.x), mul(s, a.y), mul(s, a.z), a.w}; }
// a + s d on xyz in the lanes set in `valid`, a unchanged in the others; w kept.
inline Lanes add_scaled3(const Lanes& a, __m256 s, const Lanes& d, __m256 valid) {
  return {_mm256_blendv_ps(a.x, add(a.x, mul(s, d.x)), valid), _mm256_blendv_ps(a.y, add(a.y, mul(s, d.y)), valid),
          _mm256_blendv_ps(a.z, add(a.z, mul(s, d.z)), valid), a.w};
}

}  // namespace sinew::kernels::avx2

#pragma GCC pop_options
