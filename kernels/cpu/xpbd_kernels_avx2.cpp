// xpbd_kernels_avx2.cpp — the two constraint solves of xpbd_kernels.cpp,
// eight constraints at a time with AVX2, for the CPU backend's speed.
//
// Same algorithm (Macklin, Müller, Chentanez, "XPBD", MIG 2016, eq. 18) and
// the same operations in the same order as the scalar reference, with no
// fused multiply-add and no approximate reciprocals: every lane rounds
// exactly like the scalar code, so the results are bitwise identical
// (tests/cpu_simd_test.cpp checks it). Eight float4 particles are loaded
// with one 16-byte load each and transposed to xxxxxxxx/yyyyyyyy/... form,
// solved, transposed back and stored; lanes the scalar code would skip
// (degenerate or immovable) keep their old values.
//
// Only the functions in the target("avx2") region use AVX2; callers check
// cpu_has_avx2() first. Nothing inline from other headers is instantiated in
// that region, so no AVX2 copy of a shared inline function can reach a CPU
// without it.
#include <immintrin.h>

#include <cstdint>

#include "cpu/avx2_lanes.h"
#include "cpu/xpbd_kernels.h"
#include "xpbd_params.h"

namespace sinew::kernels {

bool cpu_has_avx2() { return __builtin_cpu_supports("avx2"); }

#pragma GCC push_options
#pragma GCC target("avx2")

namespace {

using namespace avx2;

inline __m256 load_lambda(const float* lambda, std::uint32_t reset) {
  return reset ? _mm256_setzero_ps() : _mm256_loadu_ps(lambda);
}

// |c + alpha~ lambda| / rest, as the scalar kernels compute the residual.
inline void store_residual(float* residual, __m256 c, __m256 alpha_t, __m256 lambda_i, __m256 rest) {
  const __m256 r = add(c, mul(alpha_t, lambda_i));
  _mm256_storeu_ps(residual, _mm256_div_ps(_mm256_andnot_ps(_mm256_set1_ps(-0.0f), r), rest));
}

}  // namespace

std::uint32_t xpbd_solve_distance_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                       std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float*>(bindings[0]);
  const auto* idx = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* rest_alpha = reinterpret_cast<const float*>(bindings[2]);
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  const auto* prev = reinterpret_cast<const float*>(bindings[5]);
  const __m256 inv_h2 = _mm256_set1_ps(p.inv_h2), one = _mm256_set1_ps(1.0f);
  const __m256 gamma = _mm256_set1_ps(p.damping), one_gamma = _mm256_set1_ps(1.0f + p.damping);
  std::uint32_t i = p.first + begin;
  for (; i + 8 <= p.first + end; i += 8) {
    std::uint32_t ia[8], ib[8];
    for (int j = 0; j < 8; ++j) {
      ia[j] = idx[2 * (i + j)];
      ib[j] = idx[2 * (i + j) + 1];
    }
    const Lanes a = load_particles(x, ia), b = load_particles(x, ib);
    __m256 rest, alpha;
    load_rest_alpha(rest_alpha + 2 * i, rest, alpha);
    const Lanes d = minus(a, b);
    const __m256 len = _mm256_sqrt_ps(dot3(d, d));
    const __m256 w = add(a.w, b.w);
    const __m256 alpha_t = mul(alpha, inv_h2);
    const __m256 lambda_i = load_lambda(lambda + i, p.reset_lambda);
    const __m256 valid = _mm256_and_ps(not_le_zero(len), not_le_zero(add(w, alpha_t)));
    const __m256 c = sub(len, rest);
    if (p.measure_only) {
      store_residual(residual + i, c, alpha_t, lambda_i, rest);
      continue;
    }
    const Lanes n = scale(_mm256_div_ps(one, len), d);
    __m256 dlambda;
    if (p.damping == 0.0f) {
      dlambda = _mm256_div_ps(sub(negate(c), mul(alpha_t, lambda_i)), add(w, alpha_t));
    } else {  // eq. 26, as the scalar kernel
      const Lanes moved = minus(minus(a, load_particles(prev, ia)), minus(b, load_particles(prev, ib)));
      dlambda = _mm256_div_ps(sub(sub(negate(c), mul(alpha_t, lambda_i)), mul(gamma, dot3(n, moved))),
                              add(mul(one_gamma, w), alpha_t));
    }
    const Lanes a_new = add_scaled3(a, mul(a.w, dlambda), n, valid);
    const Lanes b_new = add_scaled3(b, mul(negate(b.w), dlambda), n, valid);
    _mm256_storeu_ps(lambda + i, _mm256_blendv_ps(lambda_i, add(lambda_i, dlambda), valid));
    store_particles(x, ia, a_new, _mm256_movemask_ps(positive(a.w)));
    store_particles(x, ib, b_new, _mm256_movemask_ps(positive(b.w)));
  }
  return i - p.first;  // the first item not done; the scalar kernel finishes [it, end)
}

std::uint32_t xpbd_solve_volume_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                     std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float*>(bindings[0]);
  const auto* idx = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* rest_alpha = reinterpret_cast<const float*>(bindings[2]);
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  const auto* prev = reinterpret_cast<const float*>(bindings[5]);
  const __m256 inv_h2 = _mm256_set1_ps(p.inv_h2), sixth = _mm256_set1_ps(1.0f / 6.0f);
  const __m256 gamma = _mm256_set1_ps(p.damping), one_gamma = _mm256_set1_ps(1.0f + p.damping);
  std::uint32_t i = p.first + begin;
  for (; i + 8 <= p.first + end; i += 8) {
    std::uint32_t iv[4][8];
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 4; ++k) iv[k][j] = idx[4 * (i + j) + k];
    const Lanes x0 = load_particles(x, iv[0]), x1 = load_particles(x, iv[1]);
    const Lanes x2 = load_particles(x, iv[2]), x3 = load_particles(x, iv[3]);
    __m256 rest, alpha;
    load_rest_alpha(rest_alpha + 2 * i, rest, alpha);
    const Lanes e1 = minus(x1, x0), e2 = minus(x2, x0), e3 = minus(x3, x0);
    const Lanes c23 = cross3(e2, e3);
    const Lanes g1 = scale(sixth, c23), g2 = scale(sixth, cross3(e3, e1)), g3 = scale(sixth, cross3(e1, e2));
    const __m256 zero = _mm256_setzero_ps();
    const Lanes sum = {add(add(g1.x, g2.x), g3.x), add(add(g1.y, g2.y), g3.y), add(add(g1.z, g2.z), g3.z), zero};
    const Lanes g0 = {sub(zero, sum.x), sub(zero, sum.y), sub(zero, sum.z), zero};
    const __m256 w = add(add(add(mul(x0.w, dot3(g0, g0)), mul(x1.w, dot3(g1, g1))), mul(x2.w, dot3(g2, g2))),
                         mul(x3.w, dot3(g3, g3)));
    const __m256 alpha_t = mul(alpha, inv_h2);
    const __m256 lambda_i = load_lambda(lambda + i, p.reset_lambda);
    const __m256 valid = not_le_zero(add(w, alpha_t));
    const __m256 c = sub(mul(dot3(e1, c23), sixth), rest);  // tet_volume(x0, x1, x2, x3) - rest
    if (p.measure_only) {
      store_residual(residual + i, c, alpha_t, lambda_i, rest);
      continue;
    }
    __m256 dlambda;
    if (p.damping == 0.0f) {
      dlambda = _mm256_div_ps(sub(negate(c), mul(alpha_t, lambda_i)), add(w, alpha_t));
    } else {  // eq. 26, as the scalar kernel
      const __m256 rate = add(add(add(dot3(g0, minus(x0, load_particles(prev, iv[0]))),
                                      dot3(g1, minus(x1, load_particles(prev, iv[1])))),
                                  dot3(g2, minus(x2, load_particles(prev, iv[2])))),
                              dot3(g3, minus(x3, load_particles(prev, iv[3]))));
      dlambda = _mm256_div_ps(sub(sub(negate(c), mul(alpha_t, lambda_i)), mul(gamma, rate)),
                              add(mul(one_gamma, w), alpha_t));
    }
    _mm256_storeu_ps(lambda + i, _mm256_blendv_ps(lambda_i, add(lambda_i, dlambda), valid));
    store_particles(x, iv[0], add_scaled3(x0, mul(x0.w, dlambda), g0, valid), _mm256_movemask_ps(positive(x0.w)));
    store_particles(x, iv[1], add_scaled3(x1, mul(x1.w, dlambda), g1, valid), _mm256_movemask_ps(positive(x1.w)));
    store_particles(x, iv[2], add_scaled3(x2, mul(x2.w, dlambda), g2, valid), _mm256_movemask_ps(positive(x2.w)));
    store_particles(x, iv[3], add_scaled3(x3, mul(x3.w, dlambda), g3, valid), _mm256_movemask_ps(positive(x3.w)));
  }
  return i - p.first;
}

#pragma GCC pop_options

}  // namespace sinew::kernels
