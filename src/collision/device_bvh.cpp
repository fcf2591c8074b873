// device_bvh.cpp — the device BVH build as a program (see device_bvh.h).
#include "collision/device_bvh.h"

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

}  // namespace sinew::collision
