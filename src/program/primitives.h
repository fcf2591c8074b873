// primitives.h — device primitives appended to a frame program: exclusive
// scan, order-preserving compaction, stable radix sort and reductions, on
// counts known only on the device. Each is a short chain of the cooperative
// kernels of kernels/shared/primitive_params.h with barriers between them;
// the same chain runs on every backend, so a GPU result is checked word for
// word against the CPU reference kernels.
//
// Every primitive takes its item count from a device word (DeviceCount): n =
// min(buffer[word], capacity) when the frame runs. Buffers are sized for the
// capacity; scratch buffers are the caller's (sizes from the *_scratch_words
// functions), so a scene allocates once and the frame allocates nothing.
// Offsets and sizes are in 32-bit words.
#pragma once

#include <cstdint>
#include <string>

#include "backends/backend.h"

namespace sinew {

/// An item count that lives on the device: buffer[word] (uint), at most capacity.
struct DeviceCount {
  BufferHandle buffer;
  std::uint32_t word = 0;
  std::uint32_t capacity = 0;
};

/// A range of words in a device buffer.
struct DeviceWords {
  BufferHandle buffer;
  std::uint32_t offset = 0;  ///< first word
};

/// Scratch words an exclusive scan of `capacity` items needs.
std::uint32_t scan_scratch_words(std::uint32_t capacity);

/// Appends output[i] = input[0] + ... + input[i - 1] (uint, wrapping) for
/// i < n; output may be input (in place). [in] scratch: scan_scratch_words
/// words. Returns the scratch word that holds the total of all n items
/// after the scan (scratch.offset + that).
std::uint32_t append_exclusive_scan(FrameProgram& program, const DeviceCount& n, DeviceWords input,
                                    DeviceWords output, DeviceWords scratch);

/// Scratch words a compaction of `capacity` items needs (positions + scan).
std::uint32_t compact_scratch_words(std::uint32_t capacity);

/// Appends an order-preserving compaction: kept[0..k) = values[i] (or i
/// when `values` is invalid) for the i < n whose flags[i] is 1 (flags are
/// 0 or 1), in increasing i; k is written to kept_count.buffer[word] and
/// declared a counter of capacity kept_count.capacity named `label`, so a
/// frame whose k exceeds it reports capacity_exceeded (items past the
/// capacity are dropped). Whole buffers (offset 0); [in] scratch:
/// compact_scratch_words words. [pre] kept_count.word != n.word in one buffer.
void append_compact(FrameProgram& program, const DeviceCount& n, BufferHandle flags, BufferHandle values,
                    BufferHandle kept, const DeviceCount& kept_count, const std::string& label, BufferHandle scratch);

/// Scratch words a radix sort of `capacity` keys needs (histograms, their
/// scan and one count word).
std::uint32_t radix_sort_scratch_words(std::uint32_t capacity);

/// Appends a stable ascending sort of n keys (key_bits 32: one uint each;
/// 64: (low, high) uint pairs) and their uint payloads, in place in
/// keys/payload; keys_tmp and payload_tmp hold as many (ping-pong, even
/// pass count so the result ends where it started). [in] scratch:
/// radix_sort_scratch_words words; all offsets 0 (whole buffers).
/// [in] significant_bits: keys below 2^significant_bits need only that
/// many bits sorted (fewer passes); 0: all key_bits.
void append_radix_sort(FrameProgram& program, const DeviceCount& n, std::uint32_t key_bits, BufferHandle keys,
                       BufferHandle payload, BufferHandle keys_tmp, BufferHandle payload_tmp, DeviceWords scratch,
                       std::uint32_t significant_bits = 0);

/// Reduction operators (SINEW_REDUCE_* in primitive_params.h).
enum class ReduceOp : std::uint32_t {
  sum_f32 = 0,
  min_f32 = 1,
  max_f32 = 2,
  sum_squares_f32 = 3,
  sum_u32 = 4,
  min_u32 = 5,
  max_u32 = 6,
};

/// Scratch words a reduction of `capacity` items needs.
std::uint32_t reduce_scratch_words(std::uint32_t capacity);

/// Appends result = op over values[offset + i * stride], i < n, in the fixed
/// order of reduce_blocks (so every backend gives the same bits); the
/// operator's identity when n == 0. The result lands in the scratch at the
/// returned word; copy it where it is wanted (FrameProgram::copy).
std::uint32_t append_reduce(FrameProgram& program, const DeviceCount& n, ReduceOp op, DeviceWords values,
                            std::uint32_t stride, DeviceWords scratch);

/// How reduce_dd_blocks reads the first level's items (SINEW_DD_* in stats_params.h).
enum class DdItems : std::uint32_t { pairs = 0, floats = 1, squares = 2 };

/// Scratch words a double-float reduction of `capacity` items needs.
std::uint32_t reduce_dd_scratch_words(std::uint32_t capacity);

/// Appends a double-float sum (~48 bits, fixed order, the same bits on
/// every backend) of the items values[offset + i * stride], i < n, read as
/// `items`; returns the scratch word of the result's (hi, lo) pair: the sum
/// is double(hi) + double(lo).
std::uint32_t append_reduce_dd(FrameProgram& program, const DeviceCount& n, DdItems items, DeviceWords values,
                               std::uint32_t stride, DeviceWords scratch);

}  // namespace sinew
