// The CPU backend's AVX2 solves against the scalar reference kernels:
// random inputs (fresh each run), one colour's worth of constraints (no two
// share a movable particle; several share immovable ones), degenerate
// constraints, odd counts and offsets. The AVX2 path must be bitwise equal.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>

#include "cpu/xpbd_kernels.h"
#include "xpbd_params.h"

namespace sinew::kernels {
namespace {

struct Case {
  std::vector<float4> x;
  std::vector<std::uint32_t> idx;
  std::vector<float> rest_alpha;
  std::vector<float> lambda;
  std::vector<float> residual;
  std::vector<float4> prev;  // the substep's start: a small step from x
};

// `count` constraints of `arity` particles with no shared movable particle.
Case make_case(std::mt19937& rng, std::uint32_t arity, std::uint32_t count) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), pos(0.1f, 2.0f);
  Case c;
  const std::uint32_t movable = arity * count, pinned = 5;
  for (std::uint32_t p = 0; p < movable + pinned; ++p)
    c.x.push_back({u(rng), u(rng), u(rng), p < movable ? pos(rng) : 0.0f});
  std::vector<std::uint32_t> order(movable);
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), rng);
  for (std::uint32_t k = 0; k < count; ++k) {
    for (std::uint32_t j = 0; j < arity; ++j) c.idx.push_back(order[k * arity + j]);
    if (k % 7 == 3) c.idx[k * arity] = movable + k % pinned;   // shares an immovable particle
    if (k % 11 == 5 && arity == 2) c.x[c.idx[k * 2 + 1]] = c.x[c.idx[k * 2]];  // zero length
    if (k % 13 == 6 && arity == 4) c.x[c.idx[k * 4 + 3]] = c.x[c.idx[k * 4 + 2]];  // collapsed tet
    c.rest_alpha.push_back(pos(rng) * (arity == 2 ? 1.0f : 0.2f));
    c.rest_alpha.push_back(k % 3 == 0 ? 0.0f : pos(rng) * 1e-4f);  // rigid and compliant
    c.lambda.push_back(u(rng) * 1e-3f);
    c.residual.push_back(-1.0f);  // poison: every item must overwrite it when asked
  }
  for (const float4& p : c.x) c.prev.push_back({p.x + 0.01f * u(rng), p.y + 0.01f * u(rng), p.z + 0.01f * u(rng), p.w});
  return c;
}

void run(CpuKernelFn fn, Case& c, const SolveParams& p, std::uint32_t begin, std::uint32_t end) {
  std::byte* bindings[6] = {reinterpret_cast<std::byte*>(c.x.data()), reinterpret_cast<std::byte*>(c.idx.data()),
                            reinterpret_cast<std::byte*>(c.rest_alpha.data()),
                            reinterpret_cast<std::byte*>(c.lambda.data()),
                            reinterpret_cast<std::byte*>(c.residual.data()),
                            reinterpret_cast<std::byte*>(c.prev.data())};
  fn(&p, bindings, begin, end);
}

template <std::uint32_t (*Simd)(const void*, std::byte* const*, std::uint32_t, std::uint32_t), CpuKernelFn Scalar>
void simd_then_scalar(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  Scalar(params, bindings, Simd(params, bindings, begin, end), end);
}

void compare(std::uint32_t arity, CpuKernelFn scalar, CpuKernelFn simd) {
  std::mt19937 rng(std::random_device{}());
  for (std::uint32_t count : {8u, 13u, 64u, 203u}) {
    for (std::uint32_t reset : {0u, 1u}) {
     for (float damping : {0.0f, 6.0f}) {  // SolveParams::damping (XPBD eq. 26's gamma)
      Case ref = make_case(rng, arity, count);
      Case fast = ref;
      const Case input = ref;
      // A dispatch over constraints [first, first + n) split into two chunks,
      // as threads would split it.
      const std::uint32_t first = count % 5, n = count - first, split = n / 3;
      const SolveParams solve{first, n, 3600.0f, reset, 1.0f / 60.0f, 1.0f, 0, damping};
      run(scalar, ref, solve, 0, n);
      run(simd, fast, solve, 0, split);
      run(simd, fast, solve, split, n);
      ASSERT_EQ(0, std::memcmp(ref.x.data(), fast.x.data(), ref.x.size() * sizeof(float4)))
          << "positions differ, arity " << arity << ", count " << count;
      ASSERT_EQ(0, std::memcmp(ref.lambda.data(), fast.lambda.data(), ref.lambda.size() * sizeof(float)))
          << "lambdas differ, arity " << arity << ", count " << count;
      EXPECT_NE(0, std::memcmp(input.x.data(), ref.x.data(), ref.x.size() * sizeof(float4))) << "nothing solved";

      // A measuring pass: residuals equal, nothing else written.
      const SolveParams measure{first, n, 3600.0f, 0, 1.0f / 60.0f, 1.0f, 1, 0};
      const Case solved = ref;
      run(scalar, ref, measure, 0, n);
      run(simd, fast, measure, 0, split);
      run(simd, fast, measure, split, n);
      ASSERT_EQ(0, std::memcmp(ref.residual.data(), fast.residual.data(), ref.residual.size() * sizeof(float)))
          << "residuals differ, arity " << arity << ", count " << count;
      for (std::uint32_t k = first; k < count; ++k) ASSERT_GE(ref.residual[k], 0.0f) << "residual not written";
      EXPECT_EQ(0, std::memcmp(solved.x.data(), fast.x.data(), ref.x.size() * sizeof(float4)));
      EXPECT_EQ(0, std::memcmp(solved.lambda.data(), fast.lambda.data(), ref.lambda.size() * sizeof(float)));
     }
    }
  }
}

TEST(CpuSimd, DistanceSolveIsBitwiseEqualToTheReference) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2";
  compare(2, xpbd_solve_distance, simd_then_scalar<xpbd_solve_distance_avx2, xpbd_solve_distance>);
}

TEST(CpuSimd, VolumeSolveIsBitwiseEqualToTheReference) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2";
  compare(4, xpbd_solve_volume, simd_then_scalar<xpbd_solve_volume_avx2, xpbd_solve_volume>);
}

}  // namespace
}  // namespace sinew::kernels
