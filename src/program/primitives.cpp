// primitives.cpp — the dispatch chains of the device primitives.
//
// Scan: Blelloch (1990) as a multi-level block scan (Harris, Sengupta, Owens,
// "Parallel Prefix Sum (Scan) with CUDA", GPU Gems 3, ch. 39): scan blocks of
// 256 and keep their totals, scan the totals the same way until one block
// is left, then add each block's offset back down the levels.
// Radix sort: Satish, Harris, Garland, "Designing efficient sorting
// algorithms for manycore GPUs" (IPDPS 2009): per pass a digit histogram per
// block, a digit-major scan of the histograms, and a stable scatter.
#include "program/primitives.h"

#include <vector>

#include "primitive_params.h"
#include "stats_params.h"

namespace sinew {
namespace {

constexpr std::uint32_t kBlock = SINEW_PRIMITIVE_BLOCK;

std::uint32_t blocks(std::uint32_t items) { return items / kBlock + (items % kBlock != 0 ? 1u : 0u); }

// Items at each level of a multi-level primitive over `capacity` items:
// capacity, ceil(capacity / 256), ... down to the first level of one block.
std::vector<std::uint32_t> level_capacities(std::uint32_t capacity) {
  std::vector<std::uint32_t> levels{capacity};
  while (blocks(levels.back()) > 1) levels.push_back(blocks(levels.back()));
  return levels;
}

}  // namespace

std::uint32_t scan_scratch_words(std::uint32_t capacity) {
  std::uint32_t words = 0;
  for (std::uint32_t items : level_capacities(capacity)) words += std::max(blocks(items), 1u);
  return words;
}

std::uint32_t append_exclusive_scan(FrameProgram& program, const DeviceCount& n, DeviceWords input,
                                    DeviceWords output, DeviceWords scratch) {
  const std::vector<std::uint32_t> levels = level_capacities(n.capacity);
  kernels::ScanParams p{};
  p.count_word = n.word;
  p.capacity = n.capacity;
  // Level k scans its array A_k into itself (A_0: input -> output) and writes
  // its block totals S_k to the scratch; A_{k+1} = S_k, scanned in place.
  std::vector<DeviceWords> array{output};
  std::uint32_t next = scratch.offset;
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const DeviceWords in = k == 0 ? input : array[k];
    const DeviceWords sums{scratch.buffer, next};
    next += std::max(blocks(levels[k]), 1u);
    p.level_shift = static_cast<std::uint32_t>(8 * k);
    p.in_offset = in.offset;
    p.out_offset = array[k].offset;
    p.sums_offset = sums.offset;
    program.dispatch(Kernel::scan_blocks, std::max(blocks(levels[k]), 1u) * kBlock,
                     {n.buffer, in.buffer, array[k].buffer, sums.buffer}, p);
    program.barrier();
    array.push_back(sums);
  }
  // The top level was one block: its S holds the total of all n items.
  const std::uint32_t total = array.back().offset;
  for (std::size_t k = levels.size() - 1; k-- > 0;) {
    p.level_shift = static_cast<std::uint32_t>(8 * k);
    p.out_offset = array[k].offset;
    p.sums_offset = array[k + 1].offset;
    program.dispatch(Kernel::scan_add, std::max(blocks(levels[k]), 1u) * kBlock,
                     {n.buffer, array[k].buffer, array[k + 1].buffer}, p);
    program.barrier();
  }
  return total;
}

std::uint32_t compact_scratch_words(std::uint32_t capacity) { return capacity + scan_scratch_words(capacity); }

void append_compact(FrameProgram& program, const DeviceCount& n, BufferHandle flags, BufferHandle values,
                    BufferHandle kept, const DeviceCount& kept_count, const std::string& label,
                    BufferHandle scratch) {
  // scratch: [positions: capacity words][scan scratch]
  append_exclusive_scan(program, n, {flags, 0}, {scratch, 0}, {scratch, n.capacity});
  kernels::CompactParams p{};
  p.count_word = n.word;
  p.capacity = n.capacity;
  p.out_count_word = kept_count.word;
  p.out_capacity = kept_count.capacity;
  p.emit_index = values.valid() ? 0u : 1u;
  program.dispatch(Kernel::compact_scatter, std::max(n.capacity, 1u),
                   {n.buffer, flags, values.valid() ? values : flags, scratch, kept}, p);
  program.barrier();
  program.counter(label, kept_count.buffer, kept_count.word, kept_count.capacity);
}

std::uint32_t radix_sort_scratch_words(std::uint32_t capacity) {
  const std::uint32_t hist = SINEW_RADIX_DIGITS * std::max(blocks(capacity), 1u);
  return 1 + hist + scan_scratch_words(hist);
}

void append_radix_sort(FrameProgram& program, const DeviceCount& n, std::uint32_t key_bits, BufferHandle keys,
                       BufferHandle payload, BufferHandle keys_tmp, BufferHandle payload_tmp, DeviceWords scratch,
                       std::uint32_t significant_bits) {
  const std::uint32_t stride = std::max(blocks(n.capacity), 1u);
  const std::uint32_t hist_words = SINEW_RADIX_DIGITS * stride;
  // scratch: [count of histogram words][histograms][their scan's scratch]
  const DeviceCount hist_count{scratch.buffer, scratch.offset, hist_words};
  const DeviceWords hist{scratch.buffer, scratch.offset + 1};
  const DeviceWords hist_scratch{scratch.buffer, scratch.offset + 1 + hist_words};
  program.fill(scratch.buffer, scratch.offset, 1, hist_words);
  program.barrier();
  kernels::RadixParams p{};
  p.count_word = n.word;
  p.capacity = n.capacity;
  p.key_words = key_bits / 32;
  p.block_stride = stride;
  p.hist_offset = hist.offset;
  BufferHandle from_keys = keys, from_payload = payload, to_keys = keys_tmp, to_payload = payload_tmp;
  // Passes over the significant digits, an even number of them (the
  // ping-pong ends in keys/payload again).
  const std::uint32_t bits = significant_bits > 0 && significant_bits < key_bits ? significant_bits : key_bits;
  std::uint32_t passes = (bits + SINEW_RADIX_BITS - 1) / SINEW_RADIX_BITS;
  passes += passes % 2;
  for (std::uint32_t shift = 0; shift < passes * SINEW_RADIX_BITS; shift += SINEW_RADIX_BITS) {
    p.shift = shift;
    program.dispatch(Kernel::radix_histogram, stride * kBlock, {n.buffer, from_keys, hist.buffer}, p);
    program.barrier();
    append_exclusive_scan(program, hist_count, hist, hist, hist_scratch);
    program.dispatch(Kernel::radix_scatter, stride * kBlock,
                     {n.buffer, from_keys, from_payload, hist.buffer, to_keys, to_payload}, p);
    program.barrier();
    std::swap(from_keys, to_keys);
    std::swap(from_payload, to_payload);
  }
}

std::uint32_t reduce_scratch_words(std::uint32_t capacity) {
  std::uint32_t words = 0;
  for (std::uint32_t items : level_capacities(capacity)) words += std::max(blocks(items), 1u);
  return words;
}

namespace {

// The levels of a reduction: level 0 reduces the n values into one partial
// per block of 256 (`partial_words` words each) in the scratch, each level
// above reduces the partials below it, until one is left; `dispatch(k, in,
// in_stride, out)` appends level k's kernel. Returns the result's scratch word.
template <class Dispatch>
std::uint32_t append_reduction_levels(FrameProgram& program, std::uint32_t capacity, DeviceWords values,
                                      std::uint32_t stride, std::uint32_t partial_words, DeviceWords scratch,
                                      Dispatch dispatch) {
  const std::vector<std::uint32_t> levels = level_capacities(capacity);
  DeviceWords in = values;
  std::uint32_t next = scratch.offset;
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const DeviceWords partials{scratch.buffer, next};
    next += partial_words * std::max(blocks(levels[k]), 1u);
    dispatch(static_cast<std::uint32_t>(k), in, k == 0 ? stride : partial_words, partials,
             std::max(blocks(levels[k]), 1u) * kBlock);
    program.barrier();
    in = partials;
  }
  return in.offset;
}

}  // namespace

std::uint32_t append_reduce(FrameProgram& program, const DeviceCount& n, ReduceOp op, DeviceWords values,
                            std::uint32_t stride, DeviceWords scratch) {
  kernels::ReduceParams p{};
  p.count_word = n.word;
  p.capacity = n.capacity;
  return append_reduction_levels(
      program, n.capacity, values, stride, 1, scratch,
      [&](std::uint32_t k, DeviceWords in, std::uint32_t in_stride, DeviceWords out, std::uint32_t items) {
        p.level_shift = 8 * k;
        // Sum of squares squares the inputs; the levels above add them up.
        p.op = k > 0 && op == ReduceOp::sum_squares_f32 ? SINEW_REDUCE_SUM_F32 : static_cast<std::uint32_t>(op);
        p.in_offset = in.offset;
        p.in_stride = in_stride;
        p.out_offset = out.offset;
        program.dispatch(Kernel::reduce_blocks, items, {n.buffer, in.buffer, out.buffer}, p);
      });
}

std::uint32_t reduce_dd_scratch_words(std::uint32_t capacity) { return 2 * reduce_scratch_words(capacity); }

std::uint32_t append_reduce_dd(FrameProgram& program, const DeviceCount& n, DdItems items, DeviceWords values,
                               std::uint32_t stride, DeviceWords scratch) {
  kernels::ReduceDdParams p{};
  p.count_word = n.word;
  p.capacity = n.capacity;
  return append_reduction_levels(
      program, n.capacity, values, stride, 2, scratch,
      [&](std::uint32_t k, DeviceWords in, std::uint32_t in_stride, DeviceWords out, std::uint32_t launched) {
        p.level_shift = 8 * k;
        p.mode = k == 0 ? static_cast<std::uint32_t>(items) : SINEW_DD_PAIRS;
        p.in_offset = in.offset;
        p.in_stride = in_stride;
        p.out_offset = out.offset;
        program.dispatch(Kernel::reduce_dd_blocks, launched, {n.buffer, in.buffer, out.buffer}, p);
      });
}

}  // namespace sinew
