/* primitive_params.h — parameters of the device primitives: indirect
 * arguments, exclusive scan, compaction, radix sort and reductions (see
 * src/program/primitives.h for how the host chains them, kernels/cpu/
 * primitive_kernels.cpp for the reference). Shared by every kernel
 * language (sinew_lang.h).
 *
 * Sizes known only on the device. Every primitive reads its item count
 *   n = min(counts[count_word], capacity)
 * from a uint buffer (binding 0, "counts") when it runs, so a count written
 * by an earlier kernel of the same frame is honoured; `capacity` is the
 * most items the buffers hold, and the dispatch is launched for it (items
 * past n return at once). Offsets are in 32-bit words into the buffer bound.
 *
 * Cooperative kernels (group size 256, GROUP in kernels/kernel_list.h)
 * process blocks of SINEW_PRIMITIVE_BLOCK consecutive items, one per work
 * item; block b is items [256 b, 256 b + 256) of its level. */
#ifndef SINEW_PRIMITIVE_PARAMS_H
#define SINEW_PRIMITIVE_PARAMS_H

#include "sinew_lang.h"

#define SINEW_PRIMITIVE_BLOCK 256u
#define SINEW_PRIMITIVE_BLOCK_LOG2 8u
#define SINEW_RADIX_BITS 4u
#define SINEW_RADIX_DIGITS 16u

/* Reduction operators (ReduceParams::op). Float min/max: b < a ? b : a and
 * b > a ? b : a, so a NaN in `a` stays and one in `b` is skipped. Sum of
 * squares squares the inputs of the first level only. u32 sums wrap. */
#define SINEW_REDUCE_SUM_F32 0u
#define SINEW_REDUCE_MIN_F32 1u
#define SINEW_REDUCE_MAX_F32 2u
#define SINEW_REDUCE_SUM_SQUARES_F32 3u
#define SINEW_REDUCE_SUM_U32 4u
#define SINEW_REDUCE_MIN_U32 5u
#define SINEW_REDUCE_MAX_U32 6u

#ifdef __cplusplus
namespace sinew::kernels {
#endif

/* indirect_args: one work item. Writes the work-group counts of an indirect
 * dispatch of the count n = min(counts[count_word], capacity):
 * args[args_word + 0..2] = (ceil(n / group_size), 1, 1) (Vulkan's
 * VkDispatchIndirectCommand).
 * bindings: 0 counts uint [in], 1 args uint [out] */
SINEW_STRUCT_BEGIN(IndirectArgsParams)
  uint count_word;
  uint capacity;
  uint group_size;
  uint args_word;
SINEW_STRUCT_END(IndirectArgsParams)

/* Exclusive scan of uint (wrapping sums), one level of a multi-level scan.
 * Level k holds m = ceil(n / 2^level_shift) items (level_shift = 8 k).
 * scan_blocks: group b scans items [256 b, 256 b + 256) of the level:
 *   data_out[out_offset + i] = sum of data_in[in_offset + j], 256 b <= j < i (i < m),
 *   sums[sums_offset + b] = the block's total (every launched block; 0 past m).
 *   bindings: 0 counts [in], 1 data_in [in], 2 data_out [out], 3 sums [out]
 *   (data_in and data_out may be the same buffer and offset).
 * scan_add: item i < m adds sums[sums_offset + i / 256] to data_out[out_offset + i].
 *   bindings: 0 counts [in], 1 data_out [in/out], 2 sums [in] */
SINEW_STRUCT_BEGIN(ScanParams)
  uint count_word;
  uint capacity;
  uint level_shift;
  uint in_offset;
  uint out_offset;
  uint sums_offset;
  uint pad0;
  uint pad1;
SINEW_STRUCT_END(ScanParams)

/* compact_scatter: one item per input item (launched for max(capacity, 1)).
 * Order-preserving compaction of the items whose flag is 1 (flags are 0
 * or 1), given positions = exclusive scan of the flags:
 *   item i < n with flags[i] != 0: p = positions[i]; if p < out_capacity:
 *     kept[p] = emit_index ? i : values[i];
 *   the last item (i == n - 1, or i == 0 when n == 0) writes the number of
 *   flagged items, out_capacity or not, to counts[out_count_word]: the caller
 *   declares it a counter of capacity out_capacity, so overflow is reported.
 * bindings: 0 counts [in/out], 1 flags [in], 2 values [in] (unread when
 *           emit_index), 3 positions [in], 4 kept [out] */
SINEW_STRUCT_BEGIN(CompactParams)
  uint count_word;
  uint capacity;
  uint out_count_word;
  uint out_capacity;
  uint emit_index;
  uint pad0;
  uint pad1;
  uint pad2;
SINEW_STRUCT_END(CompactParams)

/* One pass of a stable least-significant-digit radix sort, 4-bit digits
 * (digit = (key >> shift) & 15; shift in [0, 64), keys of key_words = 1
 * (uint) or 2 (64-bit keys as (low, high) uint pairs)). Launched for
 * blocks = ceil(capacity / 256) groups; block_stride = that number.
 * radix_histogram: hist[hist_offset + d * block_stride + b] = keys of block b with digit d
 *   (0 for blocks past ceil(n / 256)).
 *   bindings: 0 counts [in], 1 keys [in], 2 hist [out]
 * radix_scatter, after hist is exclusive-scanned in place (16 block_stride
 *   items): key k_i of block b with digit d, the r-th of its block with
 *   that digit, goes to position hist[hist_offset + d * block_stride + b] + r of
 *   keys_out and payload_out (stable).
 *   bindings: 0 counts [in], 1 keys_in [in], 2 payload_in [in],
 *             3 hist (scanned) [in], 4 keys_out [out], 5 payload_out [out] */
SINEW_STRUCT_BEGIN(RadixParams)
  uint count_word;
  uint capacity;
  uint shift;
  uint key_words;
  uint block_stride;
  uint hist_offset;  /* the histograms start at this word of their binding */
  uint pad0;
  uint pad1;
SINEW_STRUCT_END(RadixParams)

/* reduce_blocks: one level of a multi-level reduction in a fixed order
 * (so every backend gives the same bits). Level k holds
 * m = ceil(n / 2^level_shift) items; item i of it is
 * values[in_offset + i * in_stride]. Group b loads items [256 b, 256 b + 256)
 * (the operator's identity past m: 0, +inf, -inf, 0, 0, 0xffffffff, 0),
 * then for s = 128, 64, ..., 1: v[t] = op(v[t], v[t + s]) for t < s, and
 * writes v[0] to partials[out_offset + b].
 * bindings: 0 counts [in], 1 values [in], 2 partials [out] */
SINEW_STRUCT_BEGIN(ReduceParams)
  uint count_word;
  uint capacity;
  uint level_shift;
  uint op;
  uint in_offset;
  uint in_stride;
  uint out_offset;
  uint pad0;
SINEW_STRUCT_END(ReduceParams)

#ifdef __cplusplus
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_PRIMITIVE_PARAMS_H */
