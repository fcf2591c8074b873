// primitive_kernels.cpp — CPU reference kernels of the device primitives.
//
// Plain sequential code per block: the GPU kernels (kernels/gpu/) must give
// the same words. Scan, compaction and sort have one right answer in
// integers; the float reductions fix their order instead (a pairwise tree
// over blocks of 256, padded with the operator's identity), which the GPU
// kernels follow step by step.
//
// Scan: Blelloch, "Prefix sums and their applications" (1990), as a
// multi-level block scan (Harris, Sengupta, Owens, GPU Gems 3, ch. 39).
// Radix sort: stable least-significant-digit passes of 4 bits, per-block
// digit histograms scanned digit-major (Satish, Harris, Garland, "Designing
// efficient sorting algorithms for manycore GPUs", IPDPS 2009).
#include "cpu/cpu_kernels.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include "primitive_params.h"

namespace sinew::kernels {
namespace {

constexpr std::uint32_t kBlock = SINEW_PRIMITIVE_BLOCK;

std::uint32_t* words(std::byte* const* bindings, int b) { return reinterpret_cast<std::uint32_t*>(bindings[b]); }

// n = min(counts[count_word], capacity).
std::uint32_t item_count(std::byte* const* bindings, std::uint32_t count_word, std::uint32_t capacity) {
  return std::min(words(bindings, 0)[count_word], capacity);
}

// Items at a level of a multi-level primitive: ceil(n / 2^shift).
std::uint32_t level_items(std::uint32_t n, std::uint32_t shift) {
  return static_cast<std::uint32_t>((std::uint64_t{n} + (std::uint64_t{1} << shift) - 1) >> shift);
}

std::uint32_t digit_of(const std::uint32_t* keys, std::uint32_t i, const RadixParams& p) {
  const std::uint32_t shift = p.shift;
  const std::uint32_t word = p.key_words == 2 ? keys[2 * i + (shift >= 32 ? 1 : 0)] : keys[i];
  return (word >> (shift & 31u)) & (SINEW_RADIX_DIGITS - 1);
}

float as_float(std::uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}
std::uint32_t as_bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

// The reduction operators on raw words (float ops as the GPU writes them).
std::uint32_t identity(std::uint32_t op) {
  switch (op) {
    case SINEW_REDUCE_MIN_F32: return as_bits(std::numeric_limits<float>::infinity());
    case SINEW_REDUCE_MAX_F32: return as_bits(-std::numeric_limits<float>::infinity());
    case SINEW_REDUCE_MIN_U32: return 0xffffffffu;
    default: return 0u;  // +0.0f and 0u
  }
}
template <std::uint32_t Op>
std::uint32_t combine(std::uint32_t a, std::uint32_t b) {
  if constexpr (Op == SINEW_REDUCE_SUM_F32 || Op == SINEW_REDUCE_SUM_SQUARES_F32) return as_bits(as_float(a) + as_float(b));
  if constexpr (Op == SINEW_REDUCE_MIN_F32) return as_float(b) < as_float(a) ? b : a;
  if constexpr (Op == SINEW_REDUCE_MAX_F32) return as_float(b) > as_float(a) ? b : a;
  if constexpr (Op == SINEW_REDUCE_SUM_U32) return a + b;
  if constexpr (Op == SINEW_REDUCE_MIN_U32) return std::min(a, b);
  if constexpr (Op == SINEW_REDUCE_MAX_U32) return std::max(a, b);
  return a;
}

// The pairwise tree of a block: v[t] = op(v[t], v[t + s]) for s = 128, ..., 1.
template <std::uint32_t Op>
void halve(std::uint32_t* v) {
  for (std::uint32_t s = kBlock / 2; s > 0; s /= 2)
    for (std::uint32_t t = 0; t < s; ++t) v[t] = combine<Op>(v[t], v[t + s]);
}

// The operator chosen once per block, not per pair.
void halve(std::uint32_t op, std::uint32_t* v) {
  switch (op) {
    case SINEW_REDUCE_SUM_F32:
    case SINEW_REDUCE_SUM_SQUARES_F32: return halve<SINEW_REDUCE_SUM_F32>(v);
    case SINEW_REDUCE_MIN_F32: return halve<SINEW_REDUCE_MIN_F32>(v);
    case SINEW_REDUCE_MAX_F32: return halve<SINEW_REDUCE_MAX_F32>(v);
    case SINEW_REDUCE_SUM_U32: return halve<SINEW_REDUCE_SUM_U32>(v);
    case SINEW_REDUCE_MIN_U32: return halve<SINEW_REDUCE_MIN_U32>(v);
    case SINEW_REDUCE_MAX_U32: return halve<SINEW_REDUCE_MAX_U32>(v);
    default: return;  // an unknown operator keeps v[0] (the GPU twins do the same)
  }
}

}  // namespace

void indirect_args(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const IndirectArgsParams*>(params);
  if (begin >= end || begin > 0) return;  // one item
  const std::uint32_t n = item_count(bindings, p.count_word, p.capacity);
  std::uint32_t* args = words(bindings, 1) + p.args_word;
  args[0] = static_cast<std::uint32_t>((std::uint64_t{n} + p.group_size - 1) / p.group_size);
  args[1] = 1;
  args[2] = 1;
}

void scan_blocks(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const ScanParams*>(params);
  const std::uint32_t m = level_items(item_count(bindings, p.count_word, p.capacity), p.level_shift);
  const std::uint32_t* data_in = words(bindings, 1) + p.in_offset;
  std::uint32_t* data_out = words(bindings, 2) + p.out_offset;
  std::uint32_t* sums = words(bindings, 3) + p.sums_offset;
  for (std::uint32_t b = begin; b < end; ++b) {
    std::uint32_t running = 0;
    for (std::uint32_t i = b * kBlock; i < (b + 1) * kBlock && i < m; ++i) {
      const std::uint32_t v = data_in[i];  // read before the write: in and out may alias
      data_out[i] = running;
      running += v;
    }
    sums[b] = running;
  }
}

void scan_add(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const ScanParams*>(params);
  const std::uint32_t m = level_items(item_count(bindings, p.count_word, p.capacity), p.level_shift);
  std::uint32_t* data_out = words(bindings, 1) + p.out_offset;
  const std::uint32_t* sums = words(bindings, 2) + p.sums_offset;
  for (std::uint32_t b = begin; b < end; ++b)
    for (std::uint32_t i = b * kBlock; i < (b + 1) * kBlock && i < m; ++i) data_out[i] += sums[b];
}

void compact_scatter(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const CompactParams*>(params);
  std::uint32_t* counts = words(bindings, 0);
  const std::uint32_t n = std::min(counts[p.count_word], p.capacity);
  const std::uint32_t* flags = words(bindings, 1);
  const std::uint32_t* values = words(bindings, 2);
  const std::uint32_t* positions = words(bindings, 3);
  std::uint32_t* kept = words(bindings, 4);
  for (std::uint32_t i = begin; i < end; ++i) {
    if (i < n && flags[i] != 0 && positions[i] < p.out_capacity) kept[positions[i]] = p.emit_index ? i : values[i];
    if (i + 1 == n) counts[p.out_count_word] = positions[i] + (flags[i] != 0 ? 1u : 0u);
    if (n == 0 && i == 0) counts[p.out_count_word] = 0;
  }
}

void radix_histogram(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const RadixParams*>(params);
  const std::uint32_t n = item_count(bindings, p.count_word, p.capacity);
  const std::uint32_t* keys = words(bindings, 1);
  std::uint32_t* hist = words(bindings, 2);
  for (std::uint32_t b = begin; b < end; ++b) {
    std::uint32_t count[SINEW_RADIX_DIGITS] = {};
    for (std::uint32_t i = b * kBlock; i < (b + 1) * kBlock && i < n; ++i) ++count[digit_of(keys, i, p)];
    for (std::uint32_t d = 0; d < SINEW_RADIX_DIGITS; ++d) hist[p.hist_offset + d * p.block_stride + b] = count[d];
  }
}

void radix_scatter(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const RadixParams*>(params);
  const std::uint32_t n = item_count(bindings, p.count_word, p.capacity);
  const std::uint32_t* keys_in = words(bindings, 1);
  const std::uint32_t* payload_in = words(bindings, 2);
  const std::uint32_t* hist = words(bindings, 3);
  std::uint32_t* keys_out = words(bindings, 4);
  std::uint32_t* payload_out = words(bindings, 5);
  for (std::uint32_t b = begin; b < end; ++b) {
    std::uint32_t next[SINEW_RADIX_DIGITS];
    for (std::uint32_t d = 0; d < SINEW_RADIX_DIGITS; ++d) next[d] = hist[p.hist_offset + d * p.block_stride + b];
    for (std::uint32_t i = b * kBlock; i < (b + 1) * kBlock && i < n; ++i) {
      const std::uint32_t to = next[digit_of(keys_in, i, p)]++;
      for (std::uint32_t w = 0; w < p.key_words; ++w) keys_out[p.key_words * to + w] = keys_in[p.key_words * i + w];
      payload_out[to] = payload_in[i];
    }
  }
}

void reduce_blocks(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const ReduceParams*>(params);
  const std::uint32_t m = level_items(item_count(bindings, p.count_word, p.capacity), p.level_shift);
  const std::uint32_t* values = words(bindings, 1);
  std::uint32_t* partials = words(bindings, 2);
  const std::uint32_t id = identity(p.op);
  for (std::uint32_t b = begin; b < end; ++b) {
    std::uint32_t v[kBlock];
    for (std::uint32_t t = 0; t < kBlock; ++t) {
      const std::uint32_t i = b * kBlock + t;
      v[t] = id;
      if (i < m) {
        v[t] = values[p.in_offset + i * p.in_stride];
        if (p.op == SINEW_REDUCE_SUM_SQUARES_F32) v[t] = as_bits(as_float(v[t]) * as_float(v[t]));
      }
    }
    halve(p.op, v);
    partials[p.out_offset + b] = v[0];
  }
}

}  // namespace sinew::kernels
