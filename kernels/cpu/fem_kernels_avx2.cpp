// fem_kernels_avx2.cpp — the stable Neo-Hookean and StVK tet solves of
// fem_kernels.cpp, eight tets at a time with AVX2, for the CPU backend's
// speed.
//
// Same algorithm (the coupled 2x2 xPBD tet solve of Macklin & Müller, "A
// Constraint-based Formulation of Stable Neo-Hookean Materials", MIG 2021,
// in the W-orthogonal basis documented in fem_kernels.cpp) and the same
// operations in the same order as the scalar reference, with no fused
// multiply-add and no approximate reciprocals: every lane rounds like the
// scalar code, so the results are bitwise identical (tests/cpu_simd_test.cpp
// checks it, NaN and degenerate tets included). The scalar code's branches
// become lane masks: `c > 0 ? 1 / c : 0` a blend of both sides, the guards
// on the system's scale and determinant a mask of the lanes that move (the
// others keep their multipliers, as the scalar code stores them).
//
// Corotational tets too: the Newton refinement of their kept rotation
// (fem::refine_rotation) computes both of its branches in every lane and
// blends them by the scalar test; a group of eight in which any tet has no
// rotation kept yet (its first solve, where the exact rotation comes from a
// Jacobi eigen-solve with data-dependent sweeps) runs the scalar kernel for
// those eight. Only the functions between the target("avx2") pragmas use
// AVX2; callers check cpu_has_avx2() first.
#include <immintrin.h>

#include <cstdint>

#include "cpu/avx2_lanes.h"
#include "cpu/fem_kernels.h"
#include "fem_params.h"
#include "math/fem_math.h"
#include "xpbd_params.h"

namespace sinew::kernels {

#pragma GCC push_options
#pragma GCC target("avx2")

namespace {

using namespace avx2;

struct M3 {  // a 3x3 matrix per lane, m[row][column]
  __m256 m[3][3];
};

inline __m256 div(__m256 a, __m256 b) { return _mm256_div_ps(a, b); }
// mask ? a : b, per lane.
inline __m256 select(__m256 mask, __m256 a, __m256 b) { return _mm256_blendv_ps(b, a, mask); }

// fem::frobenius_norm: s = 0, s += a[r][c]^2 row by row, sqrt.
inline __m256 frobenius_norm(const M3& a) {
  __m256 s = _mm256_setzero_ps();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) s = add(s, mul(a.m[r][c], a.m[r][c]));
  return _mm256_sqrt_ps(s);
}

// fem::determinant.
inline __m256 determinant(const M3& a) {
  const auto& m = a.m;
  return add(sub(mul(m[0][0], sub(mul(m[1][1], m[2][2]), mul(m[1][2], m[2][1]))),
                 mul(m[0][1], sub(mul(m[1][0], m[2][2]), mul(m[1][2], m[2][0])))),
             mul(m[0][2], sub(mul(m[1][0], m[2][1]), mul(m[1][1], m[2][0]))));
}

// fem::cofactor: column k = f_i x f_j (cyclic).
inline M3 cofactor(const M3& a) {
  const auto& m = a.m;
  M3 c;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    c.m[0][k] = sub(mul(m[1][i], m[2][j]), mul(m[2][i], m[1][j]));
    c.m[1][k] = sub(mul(m[2][i], m[0][j]), mul(m[0][i], m[2][j]));
    c.m[2][k] = sub(mul(m[0][i], m[1][j]), mul(m[1][i], m[0][j]));
  }
  return c;
}

// fem::deformation_gradient: F = Ds Dm^-1.
inline M3 deformation_gradient(const Lanes (&xs)[4], const M3& dm_inv) {
  const Lanes e1 = minus(xs[1], xs[0]), e2 = minus(xs[2], xs[0]), e3 = minus(xs[3], xs[0]);
  const __m256 ds[3][3] = {{e1.x, e2.x, e3.x}, {e1.y, e2.y, e3.y}, {e1.z, e2.z, e3.z}};
  M3 f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      f.m[r][c] = add(add(mul(ds[r][0], dm_inv.m[0][c]), mul(ds[r][1], dm_inv.m[1][c])), mul(ds[r][2], dm_inv.m[2][c]));
  return f;
}

// fem::position_gradients: g[i] = column i of G Dm^-T, g[0] = 0 - (g1 + g2 + g3).
inline void position_gradients(const M3& dc_df, const M3& dm_inv, Lanes (&g)[4]) {
  const __m256 zero = _mm256_setzero_ps();
  for (int i = 1; i <= 3; ++i) {
    const __m256* d = dm_inv.m[i - 1];
    Lanes& gi = g[i];
    gi.x = add(add(mul(dc_df.m[0][0], d[0]), mul(dc_df.m[0][1], d[1])), mul(dc_df.m[0][2], d[2]));
    gi.y = add(add(mul(dc_df.m[1][0], d[0]), mul(dc_df.m[1][1], d[1])), mul(dc_df.m[1][2], d[2]));
    gi.z = add(add(mul(dc_df.m[2][0], d[0]), mul(dc_df.m[2][1], d[1])), mul(dc_df.m[2][2], d[2]));
    gi.w = zero;
  }
  g[0] = {sub(zero, add(add(g[1].x, g[2].x), g[3].x)), sub(zero, add(add(g[1].y, g[2].y), g[3].y)),
          sub(zero, add(add(g[1].z, g[2].z), g[3].z)), zero};
}

struct Constraints {  // fem::TetConstraints per lane
  __m256 c_d, c_h;
  M3 dc_d, dc_h;
};

// 1 / c where c > 0, else 0 (the scalar code's guard; NaN gives 0 too).
inline __m256 inverse_or_zero(__m256 c) {
  return select(positive(c), div(_mm256_set1_ps(1.0f), c), _mm256_setzero_ps());
}

// fem::neo_hookean_constraints.
inline Constraints neo_hookean(const M3& f, __m256 h0) {
  Constraints c;
  c.c_d = frobenius_norm(f);
  const __m256 inv = inverse_or_zero(c.c_d);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) c.dc_d.m[r][k] = mul(f.m[r][k], inv);
  c.c_h = sub(determinant(f), h0);
  c.dc_h = cofactor(f);
  return c;
}

// fem::stvk_constraints.
inline Constraints stvk(const M3& f, __m256 h0) {
  Constraints c;
  M3 e;
  const __m256 half = _mm256_set1_ps(0.5f), one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      e.m[i][j] = mul(half, sub(add(add(mul(f.m[0][i], f.m[0][j]), mul(f.m[1][i], f.m[1][j])), mul(f.m[2][i], f.m[2][j])),
                                i == j ? one : zero));
  c.c_d = frobenius_norm(e);
  const __m256 inv = inverse_or_zero(c.c_d);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      c.dc_d.m[r][k] =
          mul(add(add(mul(f.m[r][0], e.m[0][k]), mul(f.m[r][1], e.m[1][k])), mul(f.m[r][2], e.m[2][k])), inv);
  c.c_h = sub(determinant(f), h0);
  c.dc_h = cofactor(f);
  return c;
}

struct Quat {  // fem::quat per lane
  __m256 w, x, y, z;
};

// fem::quaternion_matrix.
inline M3 quaternion_matrix(const Quat& q) {
  const __m256 one = _mm256_set1_ps(1.0f), two = _mm256_set1_ps(2.0f);
  const __m256 w = q.w, x = q.x, y = q.y, z = q.z;
  M3 r;
  r.m[0][0] = sub(one, mul(two, add(mul(y, y), mul(z, z))));
  r.m[0][1] = mul(two, sub(mul(x, y), mul(w, z)));
  r.m[0][2] = mul(two, add(mul(x, z), mul(w, y)));
  r.m[1][0] = mul(two, add(mul(x, y), mul(w, z)));
  r.m[1][1] = sub(one, mul(two, add(mul(x, x), mul(z, z))));
  r.m[1][2] = mul(two, sub(mul(y, z), mul(w, x)));
  r.m[2][0] = mul(two, sub(mul(x, z), mul(w, y)));
  r.m[2][1] = mul(two, add(mul(y, z), mul(w, x)));
  r.m[2][2] = sub(one, mul(two, add(mul(x, x), mul(y, y))));
  return r;
}

// fem::refine_rotation: each iteration computes the Newton turn and the
// fallback turn in every lane and keeps the one the scalar test picks.
inline Quat refine_rotation(const M3& f, Quat q, int iterations) {
  const __m256 one = _mm256_set1_ps(1.0f), half = _mm256_set1_ps(0.5f);
  const __m256 minus_half = _mm256_set1_ps(-0.5f), tiny = _mm256_set1_ps(1e-6f), eps = _mm256_set1_ps(1e-9f);
  for (int it = 0; it < iterations; ++it) {
    const M3 r = quaternion_matrix(q);
    __m256 s[3][3];  // R^T F
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        s[i][j] = add(add(mul(r.m[0][i], f.m[0][j]), mul(r.m[1][i], f.m[1][j])), mul(r.m[2][i], f.m[2][j]));
    const __m256 gx = sub(s[2][1], s[1][2]), gy = sub(s[0][2], s[2][0]), gz = sub(s[1][0], s[0][1]);
    const __m256 tr = add(add(s[0][0], s[1][1]), s[2][2]);
    const __m256 a = sub(tr, s[0][0]), b = sub(tr, s[1][1]), c = sub(tr, s[2][2]);
    const __m256 d = mul(minus_half, add(s[0][1], s[1][0])), e = mul(minus_half, add(s[0][2], s[2][0]));
    const __m256 k = mul(minus_half, add(s[1][2], s[2][1]));
    const __m256 c00 = sub(mul(b, c), mul(k, k)), c01 = sub(mul(e, k), mul(d, c)), c02 = sub(mul(d, k), mul(b, e));
    const __m256 c11 = sub(mul(a, c), mul(e, e)), c12 = sub(mul(d, e), mul(a, k)), c22 = sub(mul(a, b), mul(d, d));
    const __m256 det = add(add(mul(a, c00), mul(d, c01)), mul(e, c02));
    // a > 0 && c22 > 0 && det > 1e-6 a c22 (a + b + c), ordered (NaN: fallback).
    const __m256 bound = mul(mul(mul(tiny, a), c22), add(add(a, b), c));
    const __m256 newton = _mm256_and_ps(_mm256_and_ps(positive(a), positive(c22)), _mm256_cmp_ps(det, bound, _CMP_GT_OQ));
    const __m256 inv_det = div(one, det);
    const __m256 nx = mul(add(add(mul(c00, gx), mul(c01, gy)), mul(c02, gz)), inv_det);
    const __m256 ny = mul(add(add(mul(c01, gx), mul(c11, gy)), mul(c12, gz)), inv_det);
    const __m256 nz = mul(add(add(mul(c02, gx), mul(c12, gy)), mul(c22, gz)), inv_det);
    const __m256 abs_tr = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), tr);
    const __m256 inv = div(one, add(abs_tr, eps));
    const __m256 wx = select(newton, nx, mul(gx, inv)), wy = select(newton, ny, mul(gy, inv));
    const __m256 wz = select(newton, nz, mul(gz, inv));
    const __m256 hx = mul(half, wx), hy = mul(half, wy), hz = mul(half, wz);  // q * (1, w / 2)
    const __m256 w = sub(sub(sub(q.w, mul(q.x, hx)), mul(q.y, hy)), mul(q.z, hz));
    const __m256 x = sub(add(add(q.x, mul(q.w, hx)), mul(q.y, hz)), mul(q.z, hy));
    const __m256 y = sub(add(add(q.y, mul(q.w, hy)), mul(q.z, hx)), mul(q.x, hz));
    const __m256 z = sub(add(add(q.z, mul(q.w, hz)), mul(q.x, hy)), mul(q.y, hx));
    const __m256 inv_len = div(one, _mm256_sqrt_ps(add(add(add(mul(w, w), mul(x, x)), mul(y, y)), mul(z, z))));
    q = {mul(w, inv_len), mul(x, inv_len), mul(y, inv_len), mul(z, inv_len)};
  }
  return q;
}

// fem::corotational_constraints with the rotation r.
inline Constraints corotational(const M3& f, const M3& r, __m256 h0) {
  Constraints c;
  M3 d;
  __m256 trace = _mm256_setzero_ps();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      d.m[i][j] = sub(f.m[i][j], r.m[i][j]);
      trace = add(trace, mul(r.m[i][j], f.m[i][j]));
    }
  c.c_d = frobenius_norm(d);
  const __m256 inv = inverse_or_zero(c.c_d);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.dc_d.m[i][j] = mul(d.m[i][j], inv);
  c.c_h = sub(trace, h0);
  c.dc_h = r;
  return c;
}

enum class Model { neo_hookean, stvk, corotational };

template <Model kModel>
std::uint32_t solve_tets(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float*>(bindings[0]);
  const auto* idx = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* data = reinterpret_cast<const float*>(bindings[2]);
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  const __m256 inv_h2 = _mm256_set1_ps(p.inv_h2), zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256 infinity = _mm256_set1_ps(__builtin_inff());
  constexpr std::uint32_t stride =
      kModel == Model::corotational ? SINEW_FEM_COROTATIONAL_LAMBDA_STRIDE : SINEW_FEM_LAMBDA_STRIDE;
  std::uint32_t i = p.first + begin;
  for (; i + 8 <= p.first + end; i += 8) {
    // Gather: particles (transposed), the per-tet data and multipliers.
    std::uint32_t iv[4][8];
    alignas(32) float col[13][8], l0[8], l1[8], kept[4][8];
    bool first_solve = false;  // corotational: a tet without a kept rotation
    for (int j = 0; j < 8; ++j) {
      for (int k = 0; k < 4; ++k) iv[k][j] = idx[4 * (i + j) + k];
      const float* d = data + std::size_t{i + j} * SINEW_FEM_DATA_STRIDE;
      for (int k = 0; k < 13; ++k) col[k][j] = d[k];
      const float* l = lambda + std::size_t{i + j} * stride;
      l0[j] = p.reset_lambda ? 0.0f : l[0];
      l1[j] = p.reset_lambda ? 0.0f : l[1];
      if constexpr (kModel == Model::corotational) {
        for (int k = 0; k < 4; ++k) kept[k][j] = l[SINEW_FEM_ROTATION + k];
        first_solve = first_solve || (kept[0][j] == 0.0f && kept[1][j] == 0.0f && kept[2][j] == 0.0f &&
                                      kept[3][j] == 0.0f);
      }
    }
    if constexpr (kModel == Model::corotational) {
      if (first_solve) {  // the exact rotation: the scalar kernel does these eight
        xpbd_solve_corotational(params, bindings, i - p.first, i - p.first + 8);
        continue;
      }
    }
    const Lanes xs[4] = {load_particles(x, iv[0]), load_particles(x, iv[1]), load_particles(x, iv[2]),
                         load_particles(x, iv[3])};
    M3 dm_inv;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) dm_inv.m[r][c] = _mm256_load_ps(col[SINEW_FEM_DM_INV + 3 * r + c]);
    const M3 f = deformation_gradient(xs, dm_inv);
    const __m256 h0 = _mm256_load_ps(col[SINEW_FEM_H0]);
    Constraints c;
    if constexpr (kModel == Model::neo_hookean) {
      c = neo_hookean(f, h0);
    } else if constexpr (kModel == Model::stvk) {
      c = stvk(f, h0);
    } else {
      Quat q{_mm256_load_ps(kept[0]), _mm256_load_ps(kept[1]), _mm256_load_ps(kept[2]), _mm256_load_ps(kept[3])};
      q = refine_rotation(f, q, fem::kRotationIterations);
      if (!p.measure_only) {  // kept by every solving pass, never by the measuring one
        _mm256_store_ps(kept[0], q.w), _mm256_store_ps(kept[1], q.x);
        _mm256_store_ps(kept[2], q.y), _mm256_store_ps(kept[3], q.z);
        for (int j = 0; j < 8; ++j)
          for (int k = 0; k < 4; ++k) lambda[std::size_t{i + j} * stride + SINEW_FEM_ROTATION + k] = kept[k][j];
      }
      c = corotational(f, quaternion_matrix(q), h0);
    }

    const __m256 ad = mul(_mm256_load_ps(col[SINEW_FEM_ALPHA_D]), inv_h2);
    const __m256 ah = mul(_mm256_load_ps(col[SINEW_FEM_ALPHA_H]), inv_h2);
    const __m256 ld = _mm256_load_ps(l0), lh = _mm256_load_ps(l1);
    const __m256 rd = add(c.c_d, mul(ad, ld)), rh = add(c.c_h, mul(ah, lh));
    if (p.measure_only) {
      _mm256_storeu_ps(residual + i, _mm256_sqrt_ps(add(mul(rd, rd), mul(rh, rh))));
      continue;
    }

    Lanes a[4], b[4];
    position_gradients(c.dc_d, dm_inv, a);
    position_gradients(c.dc_h, dm_inv, b);
    __m256 aa = zero, ab = zero;
    for (int k = 0; k < 4; ++k) {
      aa = add(aa, mul(xs[k].w, dot3(a[k], a[k])));
      ab = add(ab, mul(xs[k].w, dot3(a[k], b[k])));
    }
    const __m256 beta = select(positive(aa), div(ab, aa), zero);
    __m256 bb = zero;
    for (int k = 0; k < 4; ++k) {
      b[k] = {sub(b[k].x, mul(beta, a[k].x)), sub(b[k].y, mul(beta, a[k].y)), sub(b[k].z, mul(beta, a[k].z)),
              sub(b[k].w, mul(beta, a[k].w))};
      bb = add(bb, mul(xs[k].w, dot3(b[k], b[k])));
    }
    const __m256 total = add(add(add(aa, bb), ad), ah);
    const __m256 scale = div(one, total);
    const __m256 saa = mul(scale, aa), sbb = mul(scale, bb), sad = mul(scale, ad), sah = mul(scale, ah);
    const __m256 beta2 = mul(beta, beta);
    const __m256 m11 = add(saa, sad), m12 = mul(negate(beta), sad), m22 = add(add(sbb, mul(beta2, sad)), sah);
    const __m256 det =
        add(add(add(mul(saa, sbb), mul(saa, add(mul(beta2, sad), sah))), mul(sad, sbb)), mul(sad, sah));
    // The scalar guards: total > 0 and finite, then det > 0 (ordered: NaN fails).
    const __m256 moves = _mm256_and_ps(_mm256_and_ps(positive(total), _mm256_cmp_ps(total, infinity, _CMP_LT_OQ)),
                                       positive(det));
    const __m256 rhs1 = mul(negate(scale), rd), rhs2 = mul(negate(scale), sub(rh, mul(beta, rd)));
    const __m256 mu1 = div(sub(mul(m22, rhs1), mul(m12, rhs2)), det);
    const __m256 mu2 = div(sub(mul(m11, rhs2), mul(m12, rhs1)), det);
    for (int k = 0; k < 4; ++k) {
      const Lanes dx = {add(mul(mu1, a[k].x), mul(mu2, b[k].x)), add(mul(mu1, a[k].y), mul(mu2, b[k].y)),
                        add(mul(mu1, a[k].z), mul(mu2, b[k].z)), zero};
      store_particles(x, iv[k], add_scaled3(xs[k], xs[k].w, dx, moves),
                      _mm256_movemask_ps(_mm256_and_ps(moves, positive(xs[k].w))));
    }
    _mm256_store_ps(l0, select(moves, add(ld, sub(mu1, mul(beta, mu2))), ld));
    _mm256_store_ps(l1, select(moves, add(lh, mu2), lh));
    for (int j = 0; j < 8; ++j) {
      lambda[std::size_t{i + j} * stride] = l0[j];
      lambda[std::size_t{i + j} * stride + 1] = l1[j];
    }
  }
  return i - p.first;  // the first item not done; the scalar kernel finishes [it, end)
}

}  // namespace

std::uint32_t xpbd_solve_neo_hookean_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                          std::uint32_t end) {
  return solve_tets<Model::neo_hookean>(params, bindings, begin, end);
}

std::uint32_t xpbd_solve_stvk_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                   std::uint32_t end) {
  return solve_tets<Model::stvk>(params, bindings, begin, end);
}

std::uint32_t xpbd_solve_corotational_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                           std::uint32_t end) {
  return solve_tets<Model::corotational>(params, bindings, begin, end);
}

#pragma GCC pop_options

}  // namespace sinew::kernels
