// primitives_test.cpp — the device primitives (scan, compaction, radix sort,
// reductions) on every backend: integer results equal the plain C++
// algorithm word for word, float reductions equal the CPU reference bitwise
// and a double-precision sum within float rounding. Sizes around block
// boundaries (0, 1, 2^k - 1, 2^k, 2^k + 1 for one and several levels) and
// the key patterns that break sorts (all equal, sorted, reversed, the
// largest key).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>

#include "program/primitives.h"
#include "stats_params.h"
#include "test_support.h"

namespace sinew {
namespace {

using test::BackendTest;

const std::uint32_t kSizes[] = {0, 1, 2, 255, 256, 257, 1000, 65535, 65536, 65537};

// A device with a count buffer holding n, and helpers to upload and read words.
struct Rig {
  std::unique_ptr<Device> device;
  BufferHandle counts;

  explicit Rig(const std::string& backend) {
    auto d = create_device({.backend = backend, .quiet = true});
    EXPECT_TRUE(d.ok()) << (d.ok() ? "" : d.error().message());
    if (d.ok()) device = std::move(*d);
  }
  BufferHandle words(const std::vector<std::uint32_t>& data, std::size_t at_least = 1) {
    auto b = device->create_buffer(std::max(data.size(), at_least) * 4, "test");
    EXPECT_TRUE(b.ok());
    if (!data.empty()) {
      EXPECT_TRUE(device->write_buffer(*b, 0, data.data(), data.size() * 4).ok());
    }
    return *b;
  }
  std::vector<std::uint32_t> read(BufferHandle b, std::size_t count, std::size_t offset = 0) {
    std::vector<std::uint32_t> out(count);
    if (count) {
      EXPECT_TRUE(device->read_buffer(b, offset * 4, out.data(), count * 4).ok());
    }
    return out;
  }
  Status run(const FrameProgram& program) {
    auto prepared = device->create_program(program);
    if (!prepared) return prepared.error();
    Status s = device->run_program(*prepared);
    if (Status d = device->destroy_program(*prepared); s && !d) return d;
    return s;
  }
};

std::vector<std::uint32_t> random_words(std::size_t n, std::uint32_t seed, std::uint32_t below = 0) {
  std::mt19937 rng(seed);
  std::vector<std::uint32_t> v(n);
  for (auto& x : v) x = below ? rng() % below : rng();
  return v;
}

class Primitives : public BackendTest {};

TEST_P(Primitives, ExclusiveScanEqualsStdExclusiveScan) {
  Rig rig(GetParam());
  for (std::uint32_t n : kSizes) {
    // The capacity is larger than n: the count on the device decides.
    const std::uint32_t capacity = n + 300;
    const auto input = random_words(capacity, n, 1u << 20);
    std::vector<std::uint32_t> expected(n);
    std::exclusive_scan(input.begin(), input.begin() + n, expected.begin(), 0u);
    const BufferHandle counts = rig.words({0, n});
    const BufferHandle in = rig.words(input);
    const BufferHandle out = rig.words(std::vector<std::uint32_t>(capacity, 0xdeadbeefu));
    const BufferHandle scratch = rig.words({}, scan_scratch_words(capacity));
    FrameProgram program;
    const std::uint32_t total = append_exclusive_scan(program, {counts, 1, capacity}, {in, 0}, {out, 0}, {scratch, 0});
    SINEW_ASSERT_OK(rig.run(program));
    const auto got = rig.read(out, capacity);
    EXPECT_TRUE(std::equal(expected.begin(), expected.end(), got.begin())) << "n = " << n;
    EXPECT_TRUE(std::all_of(got.begin() + n, got.end(), [](std::uint32_t w) { return w == 0xdeadbeefu; }))
        << "n = " << n << ": items past the count are left alone";
    const std::uint32_t sum = std::accumulate(input.begin(), input.begin() + n, 0u);
    EXPECT_EQ(rig.read(scratch, 1, total)[0], sum) << "n = " << n;
  }
}

TEST_P(Primitives, ScanInPlaceWrapsLikeUnsignedArithmetic) {
  Rig rig(GetParam());
  const std::uint32_t n = 70000;
  const auto input = random_words(n, 7);  // full 32-bit words: the sums wrap
  std::vector<std::uint32_t> expected(n);
  std::exclusive_scan(input.begin(), input.end(), expected.begin(), 0u);
  const BufferHandle counts = rig.words({n});
  const BufferHandle data = rig.words(input);
  const BufferHandle scratch = rig.words({}, scan_scratch_words(n));
  FrameProgram program;
  append_exclusive_scan(program, {counts, 0, n}, {data, 0}, {data, 0}, {scratch, 0});
  SINEW_ASSERT_OK(rig.run(program));
  EXPECT_EQ(rig.read(data, n), expected);
}

TEST_P(Primitives, CompactionKeepsFlaggedItemsInOrder) {
  Rig rig(GetParam());
  for (std::uint32_t n : kSizes) {
    for (std::uint32_t pattern = 0; pattern < 3; ++pattern) {  // random, none, all
      const std::uint32_t capacity = std::max(n, 1u);
      auto flags = random_words(capacity, n + pattern, 2);
      if (pattern == 1) std::fill(flags.begin(), flags.end(), 0u);
      if (pattern == 2) std::fill(flags.begin(), flags.end(), 1u);
      const auto values = random_words(capacity, 99 + n);
      std::vector<std::uint32_t> kept, indices;
      for (std::uint32_t i = 0; i < n; ++i)
        if (flags[i]) {
          kept.push_back(values[i]);
          indices.push_back(i);
        }
      const BufferHandle counts = rig.words({n, 12345, 12345});
      const BufferHandle f = rig.words(flags), v = rig.words(values);
      const BufferHandle out = rig.words({}, capacity), out_index = rig.words({}, capacity);
      const BufferHandle scratch = rig.words({}, compact_scratch_words(capacity));
      const BufferHandle scratch2 = rig.words({}, compact_scratch_words(capacity));
      FrameProgram program;
      append_compact(program, {counts, 0, capacity}, f, v, out, {counts, 1, capacity}, "kept", scratch);
      append_compact(program, {counts, 0, capacity}, f, BufferHandle{}, out_index, {counts, 2, capacity}, "index",
                     scratch2);
      SINEW_ASSERT_OK(rig.run(program));
      ASSERT_EQ(rig.device->counters().size(), 2u);
      EXPECT_EQ(rig.device->counters()[0], kept.size()) << "n = " << n;
      EXPECT_EQ(rig.read(counts, 1, 1)[0], kept.size());
      EXPECT_EQ(rig.read(out, kept.size()), kept) << "n = " << n << " pattern " << pattern;
      EXPECT_EQ(rig.read(out_index, indices.size()), indices) << "n = " << n << " pattern " << pattern;
    }
  }
}

TEST_P(Primitives, CompactionPastItsCapacityIsReportedNotSilent) {
  Rig rig(GetParam());
  const std::uint32_t n = 1000, capacity = 10;
  const BufferHandle counts = rig.words({n, 0});
  const BufferHandle flags = rig.words(std::vector<std::uint32_t>(n, 1u));
  const BufferHandle out = rig.words(std::vector<std::uint32_t>(capacity + 1, 7u));
  const BufferHandle scratch = rig.words({}, compact_scratch_words(n));
  FrameProgram program;
  append_compact(program, {counts, 0, n}, flags, BufferHandle{}, out, {counts, 1, capacity}, "contacts", scratch);
  const Status s = rig.run(program);
  ASSERT_FALSE(s.ok()) << "1000 items kept with room for 10";
  EXPECT_EQ(s.error().code(), ErrorCode::capacity_exceeded);
  EXPECT_NE(s.error().message().find("'contacts' reached 1000 of capacity 10"), std::string::npos) << s.error().message();
  ASSERT_EQ(rig.device->counters().size(), 1u);
  EXPECT_EQ(rig.device->counters()[0], n);
  std::vector<std::uint32_t> first(capacity);
  std::iota(first.begin(), first.end(), 0u);
  first.push_back(7u);  // the word past the capacity is untouched
  EXPECT_EQ(rig.read(out, capacity + 1), first);
}

// Keys of the patterns that break sorts.
std::vector<std::uint64_t> keys_of(int pattern, std::size_t n, std::uint32_t seed, bool wide) {
  std::mt19937_64 rng(seed);
  const std::uint64_t top = wide ? std::numeric_limits<std::uint64_t>::max() : 0xffffffffull;
  std::vector<std::uint64_t> k(n);
  for (std::size_t i = 0; i < n; ++i) {
    switch (pattern) {
      case 0: k[i] = rng() & top; break;                 // random
      case 1: k[i] = 42; break;                          // all equal
      case 2: k[i] = i * 3; break;                       // sorted
      case 3: k[i] = (n - i) * 5; break;                 // reversed
      case 4: k[i] = (rng() % 3 == 0) ? top : rng() % 4; break;  // the largest key, few distinct
    }
  }
  return k;
}

TEST_P(Primitives, RadixSortIsAStableSortOf32And64BitKeys) {
  Rig rig(GetParam());
  for (bool wide : {false, true}) {
    for (std::uint32_t n : kSizes) {
      if (wide && n > 1000 && GetParam() != "cpu") continue;  // 16 passes on a CPU-emulated GPU: keep it short
      for (int pattern = 0; pattern < 5; ++pattern) {
        const std::uint32_t capacity = std::max(n, 1u);
        const auto k = keys_of(pattern, capacity, n * 7 + pattern, wide);
        std::vector<std::uint32_t> key_words, payload(capacity);
        for (std::size_t i = 0; i < capacity; ++i) {
          key_words.push_back(static_cast<std::uint32_t>(k[i]));
          if (wide) key_words.push_back(static_cast<std::uint32_t>(k[i] >> 32));
          payload[i] = static_cast<std::uint32_t>(i);
        }
        std::vector<std::uint32_t> order(n);
        std::iota(order.begin(), order.end(), 0u);
        std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return k[a] < k[b]; });
        const std::uint32_t words_per_key = wide ? 2 : 1;
        const BufferHandle counts = rig.words({n});
        const BufferHandle keys = rig.words(key_words), pay = rig.words(payload);
        const BufferHandle keys_tmp = rig.words({}, key_words.size()), pay_tmp = rig.words({}, capacity);
        const BufferHandle scratch = rig.words({}, radix_sort_scratch_words(capacity));
        FrameProgram program;
        append_radix_sort(program, {counts, 0, capacity}, wide ? 64 : 32, keys, pay, keys_tmp, pay_tmp, {scratch, 0});
        SINEW_ASSERT_OK(rig.run(program));
        const auto got_keys = rig.read(keys, std::size_t{n} * words_per_key);
        const auto got_payload = rig.read(pay, n);
        EXPECT_EQ(got_payload, order) << (wide ? "64" : "32") << "-bit keys, n = " << n << ", pattern " << pattern;
        bool keys_follow = true;
        for (std::uint32_t i = 0; i < n; ++i)
          keys_follow = keys_follow && got_keys[i * words_per_key] == key_words[order[i] * words_per_key] &&
                        (!wide || got_keys[i * 2 + 1] == key_words[order[i] * 2 + 1]);
        EXPECT_TRUE(keys_follow) << "n = " << n << ", pattern " << pattern;
      }
    }
  }
}

float as_float(std::uint32_t u) { return std::bit_cast<float>(u); }

// Runs one reduction and returns the result word.
std::uint32_t reduce_on(Rig& rig, ReduceOp op, const std::vector<std::uint32_t>& values, std::uint32_t n,
                        std::uint32_t stride) {
  const std::uint32_t capacity = std::max<std::uint32_t>(n, 1);
  const BufferHandle counts = rig.words({n});
  const BufferHandle v = rig.words(values);
  const BufferHandle scratch = rig.words({}, reduce_scratch_words(capacity));
  FrameProgram program;
  const std::uint32_t at = append_reduce(program, {counts, 0, capacity}, op, {v, 1}, stride, {scratch, 0});
  EXPECT_TRUE(rig.run(program).ok());
  return rig.read(scratch, 1, at)[0];
}

TEST_P(Primitives, ReductionsAgreeWithTheCpuReferenceBitwise) {
  Rig rig(GetParam());
  Rig cpu("cpu");
  std::mt19937 rng(5);
  std::normal_distribution<float> normal(0.0f, 3.0f);
  for (std::uint32_t n : kSizes) {
    for (std::uint32_t stride : {1u, 3u}) {
      std::vector<std::uint32_t> values(1 + std::size_t{std::max(n, 1u)} * stride);
      std::vector<std::uint32_t> ints(values.size());
      double sum = 0.0, squares = 0.0, abs_sum = 0.0;
      float lo = std::numeric_limits<float>::infinity(), hi = -lo;
      std::uint32_t isum = 0, imin = 0xffffffffu, imax = 0;
      for (std::size_t w = 0; w < values.size(); ++w) {
        const float f = normal(rng);
        values[w] = std::bit_cast<std::uint32_t>(f);
        ints[w] = static_cast<std::uint32_t>(rng());
      }
      for (std::uint32_t i = 0; i < n; ++i) {
        const float f = as_float(values[1 + std::size_t{i} * stride]);
        sum += f;
        abs_sum += std::abs(f);
        squares += double(f) * f;
        lo = std::min(lo, f);
        hi = std::max(hi, f);
        const std::uint32_t u = ints[1 + std::size_t{i} * stride];
        isum += u;
        imin = std::min(imin, u);
        imax = std::max(imax, u);
      }
      const std::string at = "n = " + std::to_string(n) + ", stride " + std::to_string(stride);
      for (ReduceOp op : {ReduceOp::sum_f32, ReduceOp::min_f32, ReduceOp::max_f32, ReduceOp::sum_squares_f32}) {
        const std::uint32_t got = reduce_on(rig, op, values, n, stride);
        EXPECT_EQ(got, reduce_on(cpu, op, values, n, stride)) << at << ", op " << static_cast<int>(op);
        const double want = op == ReduceOp::sum_f32 ? sum : op == ReduceOp::min_f32 ? lo
                          : op == ReduceOp::max_f32 ? hi : squares;
        const double scale = op == ReduceOp::sum_f32 ? abs_sum : op == ReduceOp::sum_squares_f32 ? squares : 0.0;
        // A pairwise tree of float adds: error below (levels * eps) of the sum of magnitudes.
        if (std::isinf(want))
          EXPECT_EQ(as_float(got), want) << at << ": the identity of an empty min or max";
        else
          EXPECT_NEAR(as_float(got), want, 20 * std::numeric_limits<float>::epsilon() * scale + 1e-30) << at;
      }
      EXPECT_EQ(reduce_on(rig, ReduceOp::sum_u32, ints, n, stride), isum) << at;
      EXPECT_EQ(reduce_on(rig, ReduceOp::min_u32, ints, n, stride), imin) << at;
      EXPECT_EQ(reduce_on(rig, ReduceOp::max_u32, ints, n, stride), imax) << at;
    }
  }
}

TEST_P(Primitives, FloatMinAndMaxFollowTheirNanRule) {
  Rig rig(GetParam());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // b < a ? b : a over the tree: a NaN is skipped when it is the right operand
  // of every comparison it meets... and kept when it is the left. The CPU
  // reference defines the answer; every backend must give the same bits.
  Rig cpu("cpu");
  for (std::size_t where : {std::size_t{0}, std::size_t{1}, std::size_t{200}}) {
    std::vector<std::uint32_t> v(300);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::bit_cast<std::uint32_t>(float(i) - 100.0f);
    v[where] = std::bit_cast<std::uint32_t>(nan);
    for (ReduceOp op : {ReduceOp::min_f32, ReduceOp::max_f32})
      EXPECT_EQ(reduce_on(rig, op, v, 299, 1), reduce_on(cpu, op, v, 299, 1)) << "NaN at " << where;
  }
}


// Double-float sums (the per-frame statistics): the same bits as the CPU
// reference on every backend, and within 1e-13 of the exact sum where a
// float sum is off by 1e-7 (values of mixed sign and magnitude).
TEST_P(Primitives, DoubleFloatSumsAgreeBitwiseAndKeepDoublePrecision) {
  Rig rig(GetParam());
  Rig cpu("cpu");
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> mantissa(-1.0f, 1.0f);
  std::uniform_int_distribution<int> exponent(-10, 10);
  auto run = [](Rig& r, DdItems items, const std::vector<std::uint32_t>& values, std::uint32_t n, std::uint32_t stride) {
    const std::uint32_t capacity = std::max(n, 1u);
    const BufferHandle counts = r.words({n});
    const BufferHandle v = r.words(values);
    const BufferHandle scratch = r.words({}, reduce_dd_scratch_words(capacity));
    FrameProgram program;
    const std::uint32_t at = append_reduce_dd(program, {counts, 0, capacity}, items, {v, 0}, stride, {scratch, 0});
    EXPECT_TRUE(r.run(program).ok());
    return r.read(scratch, 2, at);
  };
  for (std::uint32_t n : kSizes) {
    std::vector<std::uint32_t> floats(std::max(n, 1u)), pairs(2 * std::size_t{std::max(n, 1u)});
    long double exact = 0, exact_squares = 0, exact_pairs = 0;
    for (std::uint32_t i = 0; i < floats.size(); ++i) {
      const float f = std::ldexp(mantissa(rng), exponent(rng));
      const float lo = std::ldexp(f, -30);  // a pair (f, lo): hi + lo with lo far below hi's last bit
      floats[i] = std::bit_cast<std::uint32_t>(f);
      pairs[2 * i] = floats[i];
      pairs[2 * i + 1] = std::bit_cast<std::uint32_t>(lo);
      if (i < n) {
        exact += f;
        exact_squares += (long double)f * f;
        exact_pairs += (long double)f + lo;
      }
    }
    for (auto [items, values, stride, want] :
         {std::tuple{DdItems::floats, &floats, 1u, exact}, std::tuple{DdItems::squares, &floats, 1u, exact_squares},
          std::tuple{DdItems::pairs, &pairs, 2u, exact_pairs}}) {
      const auto got = run(rig, items, *values, n, stride);
      EXPECT_EQ(got, run(cpu, items, *values, n, stride)) << "n = " << n << ", items " << static_cast<int>(items);
      const double sum = double(as_float(got[0])) + double(as_float(got[1]));
      EXPECT_NEAR(sum, double(want), 1e-13 * (1.0 + std::abs(double(want)))) << "n = " << n;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, Primitives, ::testing::ValuesIn(test::backends()), test::backend_name);

}  // namespace
}  // namespace sinew
