// device_bvh.cpp — the device BVH build as a program (see device_bvh.h).
#include "collision/device_bvh.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "bvh_params.h"
#include "program/primitives.h"

namespace sinew::collision {

Result<DeviceBvh> make_device_bvh(Device& device, std::uint32_t capacity) {
  if (capacity < 2)
    return Error(ErrorCode::bad_parameter, "a device BVH needs a capacity of at least 2 primitives (got " +
                                               std::to_string(capacity) + ")");
  DeviceBvh b;
  b.capacity = capacity;
  const std::size_t n = capacity;
  const struct {
    BufferHandle* handle;
    std::size_t words;
    const char* label;
  } buffers[] = {
      {&b.boxes, 6 * n, "bvh boxes"},          {&b.codes, n, "bvh codes"},
      {&b.indices, n, "bvh indices"},          {&b.children, 2 * (n - 1), "bvh children"},
      {&b.parents, 2 * n - 1, "bvh parents"},  {&b.codes_tmp, n, "bvh codes (sort)"},
      {&b.indices_tmp, n, "bvh indices (sort)"}, {&b.scratch, radix_sort_scratch_words(capacity), "bvh sort scratch"},
      {&b.count, 1, "bvh count"},              {&b.node_boxes, 6 * (n - 1), "bvh node boxes"},
      {&b.ready_a, n - 1, "bvh refit flags a"}, {&b.ready_b, n - 1, "bvh refit flags b"},
  };
  for (const auto& buffer : buffers) {
    auto made = device.create_buffer(buffer.words * 4, buffer.label);
    if (!made) return made.error();
    *buffer.handle = *made;
  }
  return b;
}

Status append_device_bvh_build(FrameProgram& program, const DeviceBvh& bvh, std::uint32_t n,
                               const std::array<float, 3>& lo, const std::array<float, 3>& hi) {
  if (n < 2 || n > bvh.capacity)
    return Error(ErrorCode::bad_parameter, "device BVH build over " + std::to_string(n) +
                                               " primitives: needs 2 .. capacity (" + std::to_string(bvh.capacity) + ")");
  kernels::MortonParams m{};
  m.count = n;
  float* inv[3] = {&m.inv_extent_x, &m.inv_extent_y, &m.inv_extent_z};
  float* low[3] = {&m.lo_x, &m.lo_y, &m.lo_z};
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(lo[k]) || !std::isfinite(hi[k]) || !(hi[k] >= lo[k]))
      return Error(ErrorCode::bad_parameter, "device BVH bounds: axis " + std::to_string(k) +
                                                 " needs finite lo <= hi (got " + std::to_string(lo[k]) + ", " +
                                                 std::to_string(hi[k]) + ")");
    *low[k] = lo[k];
    *inv[k] = hi[k] > lo[k] ? 1.0f / (hi[k] - lo[k]) : 0.0f;  // a flat axis: every centre in cell 0
  }
  program.fill(bvh.count, 0, 1, n);
  program.dispatch(Kernel::bvh_morton_codes, n, {bvh.boxes, bvh.codes, bvh.indices}, m);
  program.barrier();
  append_radix_sort(program, {bvh.count, 0, bvh.capacity}, 32, bvh.codes, bvh.indices, bvh.codes_tmp,
                    bvh.indices_tmp, {bvh.scratch, 0});
  program.barrier();
  kernels::KarrasParams k{};
  k.count = n;
  program.dispatch(Kernel::bvh_karras_nodes, n - 1, {bvh.codes, bvh.children, bvh.parents}, k);
  program.barrier();
  return {};
}

Status append_device_bvh_refit(FrameProgram& program, const DeviceBvh& bvh, std::uint32_t n) {
  if (n < 2 || n > bvh.capacity)
    return Error(ErrorCode::bad_parameter, "device BVH refit over " + std::to_string(n) +
                                               " primitives: needs 2 .. capacity (" + std::to_string(bvh.capacity) + ")");
  // 64 passes: a tree is at most 64 levels deep (bvh_params.h); an even
  // count leaves the flags in ready_a.
  constexpr int kPasses = 64;
  kernels::RefitParams r{};
  r.count = n;
  program.fill(bvh.ready_a, 0, n - 1, 0u);
  program.barrier();
  BufferHandle in = bvh.ready_a, out = bvh.ready_b;
  for (int pass = 0; pass < kPasses; ++pass) {
    program.copy(in, 0, out, 0, n - 1);
    program.barrier();
    program.dispatch(Kernel::bvh_refit_pass, n - 1, {bvh.children, bvh.indices, bvh.boxes, bvh.node_boxes, in, out}, r);
    program.barrier();
    std::swap(in, out);
  }
  return {};
}

Status append_device_bvh_self_pairs(FrameProgram& program, const DeviceBvh& bvh, std::uint32_t n,
                                    BufferHandle vertex_ids, BufferHandle pairs, const DeviceCount& pair_count,
                                    const std::string& label) {
  if (n < 2 || n > bvh.capacity)
    return Error(ErrorCode::bad_parameter, "device BVH self pairs over " + std::to_string(n) +
                                               " primitives: needs 2 .. capacity (" + std::to_string(bvh.capacity) + ")");
  if (!vertex_ids.valid() || !pairs.valid() || !pair_count.buffer.valid())
    return Error(ErrorCode::bad_parameter, "device BVH self pairs: the vertex ids, pairs and counter buffers must be valid");
  kernels::SelfPairsParams p{};
  p.count = n;
  p.capacity = pair_count.capacity;
  p.count_word = pair_count.word;
  program.fill(pair_count.buffer, pair_count.word, 1, 0u);
  program.barrier();
  program.dispatch(Kernel::bvh_self_pairs, n,
                   {bvh.children, bvh.indices, bvh.boxes, bvh.node_boxes, vertex_ids, pairs, pair_count.buffer}, p);
  program.barrier();
  program.counter(label, pair_count.buffer, pair_count.word, pair_count.capacity);
  return {};
}

Status append_device_bvh_tree_pairs(FrameProgram& program, BufferHandle boxes_a, std::uint32_t n_a,
                                    const DeviceBvh& tree_b, std::uint32_t n_b, BufferHandle pairs,
                                    const DeviceCount& pair_count, const std::string& label) {
  if (n_b < 2 || n_b > tree_b.capacity)
    return Error(ErrorCode::bad_parameter, "device BVH tree pairs against a tree over " + std::to_string(n_b) +
                                               " primitives: needs 2 .. capacity (" + std::to_string(tree_b.capacity) +
                                               ")");
  if (!boxes_a.valid() || !pairs.valid() || !pair_count.buffer.valid())
    return Error(ErrorCode::bad_parameter, "device BVH tree pairs: the boxes, pairs and counter buffers must be valid");
  kernels::TreePairsParams p{};
  p.count = n_a;
  p.tree_count = n_b;
  p.capacity = pair_count.capacity;
  p.count_word = pair_count.word;
  program.fill(pair_count.buffer, pair_count.word, 1, 0u);
  program.barrier();
  if (n_a > 0)  // no items: the counter stays 0
    program.dispatch(Kernel::bvh_tree_pairs, n_a,
                     {boxes_a, tree_b.children, tree_b.indices, tree_b.boxes, tree_b.node_boxes, pairs, pair_count.buffer},
                     p);
  program.barrier();
  program.counter(label, pair_count.buffer, pair_count.word, pair_count.capacity);
  return {};
}

Result<std::vector<Pair>> read_device_bvh_pairs(Device& device, BufferHandle pairs, const DeviceCount& pair_count) {
  std::uint32_t found = 0;
  if (Status s = device.read_buffer(pair_count.buffer, std::size_t{pair_count.word} * 4, &found, 4); !s) return s.error();
  if (found > pair_count.capacity)
    return Error(ErrorCode::capacity_exceeded, "device BVH pairs: " + std::to_string(found) +
                                                   " pairs found, more than the capacity of " +
                                                   std::to_string(pair_count.capacity) +
                                                   " (the first ones were kept; declare a capacity of at least " +
                                                   std::to_string(found) + ")");
  std::vector<std::uint32_t> words(2 * std::size_t{found});
  if (found > 0)
    if (Status s = device.read_buffer(pairs, 0, words.data(), words.size() * 4); !s) return s.error();
  std::vector<Pair> result(found);
  for (std::size_t k = 0; k < found; ++k) result[k] = {words[2 * k], words[2 * k + 1]};
  std::sort(result.begin(), result.end());
  return result;
}

}  // namespace sinew::collision
