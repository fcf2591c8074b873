// device_bvh.h — a BVH built in kernels on any backend (issue 12, part 1;
// Karras, "Maximizing Parallelism in the Construction of BVHs, Octrees, and
// k-d Trees", HPG 2012): Morton codes of the primitives' box centres
// (bvh_morton_codes), the stable radix sort of program/primitives.h with
// the primitive indices as payload, then every internal node at once
// (bvh_karras_nodes); the node boxes bottom-up in passes (bvh_refit_pass).
// Bitwise the same on every backend (tests/device_bvh_test.cpp). Not yet:
// the traversal, which the broad phase on the device needs next.
#pragma once

#include <array>
#include <cstdint>

#include "backends/backend.h"

namespace sinew::collision {

/// The device buffers of one BVH over at most `capacity` primitives.
struct DeviceBvh {
  std::uint32_t capacity = 0;
  BufferHandle boxes;     ///< [in] 6 floats per primitive (lo xyz, hi xyz) [m], written by the caller
  BufferHandle codes;     ///< [out] sorted Morton codes
  BufferHandle indices;   ///< [out] the primitive at each sorted position (the leaves' order)
  BufferHandle children;  ///< [out] 2 per internal node (bvh_params.h: SINEW_BVH_LEAF marks leaves)
  BufferHandle parents;   ///< [out] internal nodes, then leaves (bvh_params.h)
  BufferHandle node_boxes;  ///< [out] 6 floats per internal node (after a refit)
  BufferHandle ready_a, ready_b;  // the refit's flags, one per internal node (ping-pong)
  BufferHandle codes_tmp, indices_tmp, scratch, count;  // the sort's
};

/// Creates the buffers for up to `capacity` >= 2 primitives.
Result<DeviceBvh> make_device_bvh(Device& device, std::uint32_t capacity);

/// Appends the build over the first `n` boxes (2 <= n <= capacity), their
/// centres quantised within [lo, hi] [m] (centres outside are clamped to
/// the nearest cell: still a valid tree, only a looser one). Errors name a
/// bad n or bounds.
Status append_device_bvh_build(FrameProgram& program, const DeviceBvh& bvh, std::uint32_t n,
                               const std::array<float, 3>& lo, const std::array<float, 3>& hi);

/// Appends the node boxes' computation from the primitives' current boxes
/// over the tree of the last build (same n): 64 passes
/// of bvh_refit_pass, enough for any tree (bvh_params.h). After a build, or
/// each substep when only the boxes moved.
Status append_device_bvh_refit(FrameProgram& program, const DeviceBvh& bvh, std::uint32_t n);

}  // namespace sinew::collision
