// device_bvh.h — a BVH built in kernels on any backend (issue 12, part 1;
// Karras, "Maximizing Parallelism in the Construction of BVHs, Octrees, and
// k-d Trees", HPG 2012): Morton codes of the primitives' box centres
// (bvh_morton_codes), the stable radix sort of program/primitives.h with
// the primitive indices as payload, then every internal node at once
// (bvh_karras_nodes); the node boxes bottom-up in passes (bvh_refit_pass).
// Bitwise the same on every backend (tests/device_bvh_test.cpp). Then the
// traversals that find candidate pairs (Karras, "Thinking Parallel, Part
// II: Tree Traversal on the GPU", 2012): one item per primitive walks a
// tree with a stack and appends the pairs whose boxes overlap through an
// atomic counter of declared capacity (bvh_self_pairs within one set,
// skipping primitives that share a vertex; bvh_tree_pairs of a set against
// another's tree). The pairs' order in the buffer depends on scheduling;
// the sorted set is the same on every backend and equals the CPU reference
// BVH's and the brute force's (collision/bvh.h).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "backends/backend.h"
#include "collision/bvh.h"
#include "program/primitives.h"

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

/// Appends the self pairs of the first `n` primitives (the n of the last
/// build and refit): every (i, j), i < j primitive indices, whose boxes in
/// bvh.boxes overlap (closed intervals: touching boxes count) and whose
/// vertex ids share none. The counter pair_count.buffer[pair_count.word] is
/// zeroed first and declared a counter of capacity pair_count.capacity
/// named `label`, so a run that finds more pairs fails with
/// capacity_exceeded (the first capacity pairs found are kept; which ones
/// depends on scheduling).
/// [in] vertex_ids: 3 uint per primitive (3 n words), a point's 1, a
///      segment's 2 or a triangle's 3 vertex ids, unused slots 0xFFFFFFFF.
/// [out] pairs: 2 uint per pair, room for pair_count.capacity pairs, in no
///      particular order (read_device_bvh_pairs sorts them); [pre] the
///      counter's word lies outside them.
/// Errors (bad_parameter): n outside 2 .. bvh.capacity, invalid buffers.
Status append_device_bvh_self_pairs(FrameProgram& program, const DeviceBvh& bvh, std::uint32_t n,
                                    BufferHandle vertex_ids, BufferHandle pairs, const DeviceCount& pair_count,
                                    const std::string& label = "bvh self pairs");

/// Appends the pairs of `n_a` primitives of a set A against the tree over
/// the first `n_b` primitives of another set B (built and refitted with
/// that n_b): every (a, b), a of A, b of B, whose boxes overlap; no vertex
/// test (two sets share no vertex). Counting and capacity as above.
/// [in] boxes_a: 6 floats per primitive of A (lo xyz, hi xyz) [m].
/// [out] pairs: 2 uint per pair, room for pair_count.capacity pairs.
/// Errors (bad_parameter): n_b outside 2 .. tree_b.capacity, invalid buffers.
Status append_device_bvh_tree_pairs(FrameProgram& program, BufferHandle boxes_a, std::uint32_t n_a,
                                    const DeviceBvh& tree_b, std::uint32_t n_b, BufferHandle pairs,
                                    const DeviceCount& pair_count, const std::string& label = "bvh tree pairs");

/// Reads the pairs a traversal above appended (after the program ran):
/// the counter at pair_count, then that many pairs. Returns them sorted,
/// or, when the counter exceeds pair_count.capacity, a capacity_exceeded
/// error that states how many pairs there were and the capacity (the
/// capacity to declare for a rerun). Device read errors pass through.
Result<std::vector<Pair>> read_device_bvh_pairs(Device& device, BufferHandle pairs, const DeviceCount& pair_count);

}  // namespace sinew::collision
