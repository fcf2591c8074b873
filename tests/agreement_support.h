// agreement_support.h — what the kernel-by-kernel agreement tests share:
// one dispatch of a kernel on a device with NaN-poisoned outputs, the
// comparison against the CPU reference, and random inputs. The Agreement
// suite is instantiated once, in backend_agreement_test.cpp, for every GPU
// backend that is built; TEST_P(Agreement, ...) in any file of test_backends
// runs on each of them.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "math/vec4.h"
#include "test_support.h"
#include "xpbd_params.h"

namespace sinew::test {

using kernels::float4;

inline std::vector<std::string> gpu_backends() {
  std::vector<std::string> out;
  for (const std::string& b : test::backends())
    if (b != "cpu") out.push_back(b);
  if (out.empty()) out.push_back("none_built");  // keeps the suites instantiated; skipped below
  return out;
}

class Agreement : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (GetParam() == "none_built") GTEST_SKIP() << "no GPU backend is built";
    if (const std::string why = missing_device(GetParam()); !why.empty())
      GTEST_SKIP() << "backend " << GetParam() << " has no device here: " << why;
  }
};

// One buffer of a kernel case: its bytes, and whether the kernel only
// writes it (then both devices get it poisoned with NaN).
struct Binding {
  std::vector<float> data;  // every buffer viewed as 4-byte words
  bool output_only = false;
  // Words per element (4 for xyzw particles): expect_agree scales its
  // tolerance per lane, so inverse masses (up to 1e8) do not hide position
  // errors.
  std::uint32_t lanes = 1;
};

struct KernelCase {
  Kernel kernel;
  std::uint32_t count;
  std::vector<Binding> bindings;
  std::vector<std::byte> params;
};

template <class P>
std::vector<std::byte> bytes_of(const P& p) {
  std::vector<std::byte> b(sizeof(P));
  std::memcpy(b.data(), &p, sizeof(P));
  return b;
}

inline std::vector<float> as_words(const std::vector<std::uint32_t>& v) {
  std::vector<float> w(v.size());
  std::memcpy(w.data(), v.data(), v.size() * 4);
  return w;
}

// Runs one dispatch of `c` on a device and returns every buffer after it.
/// Runs the case on a device of `backend` (on "cpu", `threads` threads and
/// the AVX2 solves when `cpu_simd`); returns every binding's words after.
inline std::vector<std::vector<float>> run_on(const std::string& backend, const KernelCase& c, bool cpu_simd = true,
                                              int threads = 0) {
  auto made = create_device({.backend = backend, .threads = threads, .cpu_simd = cpu_simd, .quiet = true});
  EXPECT_TRUE(made.ok()) << made.error().message();
  if (!made.ok()) return {};
  Device& device = **made;
  Dispatch d;
  d.kernel = c.kernel;
  d.count = c.count;
  d.binding_count = static_cast<std::uint32_t>(c.bindings.size());
  for (std::size_t b = 0; b < c.bindings.size(); ++b) {
    std::vector<float> data = c.bindings[b].data;
    if (c.bindings[b].output_only) std::fill(data.begin(), data.end(), std::numeric_limits<float>::quiet_NaN());
    auto buffer = device.create_buffer(data.size() * 4, "case");
    EXPECT_TRUE(buffer.ok());
    EXPECT_TRUE(device.write_buffer(*buffer, 0, data.data(), data.size() * 4).ok());
    d.bindings[b] = *buffer;
  }
  d.params_bytes = static_cast<std::uint32_t>(c.params.size());
  std::memcpy(d.params, c.params.data(), c.params.size());
  FrameProgram program;
  // FrameProgram::dispatch takes a typed struct; a raw Dispatch goes in by copy.
  program.dispatch_raw(d);
  auto prepared = device.create_program(program);
  EXPECT_TRUE(prepared.ok()) << prepared.error().message();
  if (!prepared.ok()) return {};
  EXPECT_TRUE(device.run_program(*prepared).ok());
  std::vector<std::vector<float>> out;
  for (std::size_t b = 0; b < c.bindings.size(); ++b) {
    out.emplace_back(c.bindings[b].data.size());
    EXPECT_TRUE(device.read_buffer(d.bindings[b], 0, out.back().data(), out.back().size() * 4).ok());
  }
  return out;
}

// Compares float words; index buffers (bitwise ints) compare exactly.
inline void expect_agree(const KernelCase& c, const std::vector<std::vector<float>>& ref,
                  const std::vector<std::vector<float>>& gpu, const std::string& what) {
  ASSERT_EQ(ref.size(), gpu.size());
  for (std::size_t b = 0; b < ref.size(); ++b) {
    const std::uint32_t lanes = std::max(c.bindings[b].lanes, 1u);
    std::vector<float> scale(lanes, 0.0f);  // largest finite magnitude per lane
    for (std::size_t i = 0; i < ref[b].size(); ++i)
      if (std::isfinite(ref[b][i])) scale[i % lanes] = std::max(scale[i % lanes], std::abs(ref[b][i]));
    for (std::size_t i = 0; i < ref[b].size(); ++i) {
      const float r = ref[b][i], g = gpu[b][i];
      if (std::isnan(r) && std::isnan(g)) continue;  // untouched poison on both
      ASSERT_FALSE(std::isnan(g)) << what << ": binding " << b << " word " << i << " left poisoned by the GPU kernel";
      // Equal values agree, infinities included (inf - inf is NaN, which no
      // tolerance accepts: a line-bending residual of +inf on both devices
      // failed here with a random seed that produced it).
      if (g == r) continue;
      ASSERT_NEAR(g, r, 1e-5f * std::max(scale[i % lanes], 1e-6f) + 1e-5f * std::abs(r))
          << what << " (" << kernel_name(c.kernel) << "): binding " << b << " word " << i;
    }
  }
}

// Prints how close the GPU came, one line per case: how many words of
// binding 0 (positions) the CPU kernel moved (so a case that moves nothing
// shows), how many words differ bitwise (+0 and -0 count as equal), the
// largest difference in units in the last place and relative to its lane's
// scale (what expect_agree bounds by 1e-5).
inline void report_difference(const KernelCase& c, const std::vector<std::vector<float>>& ref,
                              const std::vector<std::vector<float>>& gpu, const std::string& what) {
  auto ordered = [](float f) {  // sign-magnitude bits onto a monotonic integer line
    std::int32_t i;
    std::memcpy(&i, &f, 4);
    return i < 0 ? -std::int64_t(i & 0x7fffffff) : std::int64_t(i);
  };
  std::size_t moved = 0, words = 0, differ = 0;
  std::int64_t ulps = 0;
  double relative = 0.0;
  if (!c.bindings.empty() && !ref.empty())
    for (std::size_t i = 0; i < c.bindings[0].data.size() && i < ref[0].size(); ++i)
      moved += std::memcmp(&c.bindings[0].data[i], &ref[0][i], 4) != 0 ? 1 : 0;
  for (std::size_t b = 0; b < ref.size() && b < gpu.size() && b < c.bindings.size(); ++b) {
    const std::uint32_t lanes = std::max(c.bindings[b].lanes, 1u);
    std::vector<double> scale(lanes, 0.0);
    for (std::size_t i = 0; i < ref[b].size(); ++i)
      if (std::isfinite(ref[b][i])) scale[i % lanes] = std::max(scale[i % lanes], double(std::abs(ref[b][i])));
    for (std::size_t i = 0; i < ref[b].size() && i < gpu[b].size(); ++i) {
      const float r = ref[b][i], g = gpu[b][i];
      ++words;
      if (r == g || (std::isnan(r) && std::isnan(g))) continue;
      ++differ;
      ulps = std::max(ulps, std::abs(ordered(r) - ordered(g)));
      relative = std::max(relative, std::abs(double(g) - r) / std::max(scale[i % lanes], 1e-30));
    }
  }
  std::printf("[ agree    ] %s: moved %zu words of x; %zu of %zu words differ (largest %" PRId64
              " ulp, %.1e of the lane's scale)\n",
              what.c_str(), moved, differ, words, ulps, relative);
}

// Particles in a unit box with inverse masses; a few immovable ones.
inline std::vector<float> random_particles(std::mt19937& rng, std::uint32_t n, std::uint32_t pinned_every = 7) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), w(0.5f, 2.0f);
  std::vector<float> x;
  for (std::uint32_t p = 0; p < n; ++p) {
    x.insert(x.end(), {u(rng), u(rng), u(rng), p % pinned_every == 3 ? 0.0f : w(rng)});
  }
  return x;
}

// `count` constraints of `arity` particles, none sharing a movable one.
inline std::vector<std::uint32_t> one_colour(std::mt19937& rng, std::uint32_t count, std::uint32_t arity) {
  std::vector<std::uint32_t> order(count * arity);
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), rng);
  return order;
}

/// A colour of distance or volume constraints; `damping` is SolveParams::damping
/// (gamma of XPBD eq. 26), the previous positions a small random step away.
inline KernelCase solve_case(std::mt19937& rng, Kernel kernel, std::uint32_t arity, std::uint32_t count, bool reset,
                      bool measure, float damping = 0.0f) {
  std::uniform_real_distribution<float> rest(0.05f, 0.5f), alpha(0.0f, 1e-4f), lam(-1e-3f, 1e-3f), step(-1e-2f, 1e-2f);
  KernelCase c{kernel, count, {}, {}};
  const std::uint32_t first = 3, total = first + count + 5;
  const std::vector<float> x = random_particles(rng, total * arity);
  std::vector<float> prev = x;
  for (std::size_t k = 0; k < prev.size(); ++k)
    if (k % 4 != 3) prev[k] += step(rng);
  c.bindings.push_back({x, false, 4});
  std::vector<std::uint32_t> idx = one_colour(rng, total, arity);
  c.bindings.push_back({as_words(idx), false});
  std::vector<float> data, lambda, residual(total, 0.0f);
  for (std::uint32_t k = 0; k < total; ++k) {
    data.insert(data.end(), {rest(rng), k % 3 == 0 ? 0.0f : alpha(rng)});
    lambda.push_back(lam(rng));
  }
  c.bindings.push_back({data, false});
  c.bindings.push_back({lambda, reset && !measure});
  c.bindings.push_back({residual, measure});
  c.bindings.push_back({prev, false, 4});
  kernels::SolveParams p{first, count, 3600.0f, reset ? 1u : 0u, 1.0f / 60.0f, 1.0f, measure ? 1u : 0u, damping};
  c.params = bytes_of(p);
  return c;
}

}  // namespace sinew::test
