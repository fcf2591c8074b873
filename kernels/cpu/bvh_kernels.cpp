// bvh_kernels.cpp — CPU references of the kernels that build a BVH on the
// device and find candidate pairs with it (kernels/shared/bvh_params.h):
// Morton codes of box centres, Karras's internal nodes from the sorted
// codes (Karras, HPG 2012, "Maximizing Parallelism in the Construction of
// BVHs, Octrees, and k-d Trees", section 4 and Figure 4), the node boxes
// bottom-up, and one stack traversal per primitive appending overlapping
// pairs through an atomic counter (Karras, "Thinking Parallel, Part II:
// Tree Traversal on the GPU", NVIDIA blog 2012). Written in the GPU twins'
// operation order (kernels/gpu/bvh_*.gpu): integer work, float work
// without fused multiply-add, and comparisons.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>

#include "bvh_params.h"
#include "cpu/cpu_kernels.h"

namespace sinew::kernels {
namespace {

// 10 bits spread to every third bit (x -> x00x00x...).
std::uint32_t spread_bits(std::uint32_t v) {
  v = (v * 0x00010001u) & 0xFF0000FFu;
  v = (v * 0x00000101u) & 0x0F00F00Fu;
  v = (v * 0x00000011u) & 0xC30C30C3u;
  v = (v * 0x00000005u) & 0x49249249u;
  return v;
}

// The cell [0, 1023] of coordinate c in [lo, lo + 1 / inv_extent].
std::uint32_t cell(float c, float lo, float inv_extent) {
  const float t = (c - lo) * inv_extent * 1024.0f;
  if (!(t > 0.0f)) return 0u;  // also NaN: the lowest cell, never a wild code
  if (t >= 1023.0f) return 1023u;
  return static_cast<std::uint32_t>(t);
}

}  // namespace

void bvh_morton_codes(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const MortonParams*>(params);
  const auto* boxes = reinterpret_cast<const float*>(bindings[0]);
  auto* codes = reinterpret_cast<std::uint32_t*>(bindings[1]);
  auto* indices = reinterpret_cast<std::uint32_t*>(bindings[2]);
  for (std::uint32_t i = begin; i < end && i < p.count; ++i) {
    const float* b = boxes + 6 * std::size_t{i};
    const float cx = 0.5f * (b[0] + b[3]), cy = 0.5f * (b[1] + b[4]), cz = 0.5f * (b[2] + b[5]);
    const std::uint32_t x = cell(cx, p.lo_x, p.inv_extent_x), y = cell(cy, p.lo_y, p.inv_extent_y),
                        z = cell(cz, p.lo_z, p.inv_extent_z);
    codes[i] = (spread_bits(x) << 2) | (spread_bits(y) << 1) | spread_bits(z);
    indices[i] = i;
  }
}

namespace {

// Karras's delta: the length of the common prefix of keys i and j, ties
// broken by the positions; -1 outside [0, n).
int delta(const std::uint32_t* codes, int n, int i, int j) {
  if (j < 0 || j >= n) return -1;
  const std::uint32_t a = codes[i], b = codes[j];
  if (a != b) return std::countl_zero(a ^ b);
  return 32 + std::countl_zero(static_cast<std::uint32_t>(i) ^ static_cast<std::uint32_t>(j));
}

}  // namespace

void bvh_karras_nodes(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const KarrasParams*>(params);
  const auto* codes = reinterpret_cast<const std::uint32_t*>(bindings[0]);
  auto* children = reinterpret_cast<std::uint32_t*>(bindings[1]);
  auto* parents = reinterpret_cast<std::uint32_t*>(bindings[2]);
  const int n = static_cast<int>(p.count);
  for (std::uint32_t item = begin; item < end && item + 1 < p.count; ++item) {
    const int i = static_cast<int>(item);
    // The direction of the node's range, and its other end j.
    const int d = delta(codes, n, i, i + 1) - delta(codes, n, i, i - 1) > 0 ? 1 : -1;
    const int delta_min = delta(codes, n, i, i - d);
    int l_max = 2;
    while (delta(codes, n, i, i + l_max * d) > delta_min) l_max *= 2;
    int l = 0;
    for (int t = l_max / 2; t >= 1; t /= 2)
      if (delta(codes, n, i, i + (l + t) * d) > delta_min) l += t;
    const int j = i + l * d;
    // The split: the highest differing bit of the range's keys.
    const int delta_node = delta(codes, n, i, j);
    int s = 0;
    for (int div = 2;; div *= 2) {
      const int t = (l + div - 1) / div;  // ceil(l / div)
      if (delta(codes, n, i, i + (s + t) * d) > delta_node) s += t;
      if (t == 1) break;
    }
    const int gamma = i + s * d + std::min(d, 0);
    const int lo = std::min(i, j), hi = std::max(i, j);
    const std::uint32_t left = lo == gamma ? static_cast<std::uint32_t>(gamma) | SINEW_BVH_LEAF : static_cast<std::uint32_t>(gamma);
    const std::uint32_t right =
        hi == gamma + 1 ? static_cast<std::uint32_t>(gamma + 1) | SINEW_BVH_LEAF : static_cast<std::uint32_t>(gamma + 1);
    children[2 * item] = left;
    children[2 * item + 1] = right;
    const auto slot = [&](std::uint32_t c) { return (c & SINEW_BVH_LEAF) ? (p.count - 1) + (c & ~SINEW_BVH_LEAF) : c; };
    parents[slot(left)] = item;
    parents[slot(right)] = item;
    if (item == 0) parents[0] = SINEW_BVH_NONE;
  }
}

void bvh_refit_pass(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const RefitParams*>(params);
  const auto* children = reinterpret_cast<const std::uint32_t*>(bindings[0]);
  const auto* indices = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* boxes = reinterpret_cast<const float*>(bindings[2]);
  auto* node_boxes = reinterpret_cast<float*>(bindings[3]);
  const auto* ready_in = reinterpret_cast<const std::uint32_t*>(bindings[4]);
  auto* ready_out = reinterpret_cast<std::uint32_t*>(bindings[5]);
  for (std::uint32_t i = begin; i < end && i + 1 < p.count; ++i) {
    if (ready_in[i] != 0u) continue;
    const std::uint32_t a = children[2 * i], b = children[2 * i + 1];
    if ((!(a & SINEW_BVH_LEAF) && ready_in[a] == 0u) || (!(b & SINEW_BVH_LEAF) && ready_in[b] == 0u)) continue;
    const float* ba = (a & SINEW_BVH_LEAF) ? boxes + 6 * std::size_t{indices[a & ~SINEW_BVH_LEAF]} : node_boxes + 6 * std::size_t{a};
    const float* bb = (b & SINEW_BVH_LEAF) ? boxes + 6 * std::size_t{indices[b & ~SINEW_BVH_LEAF]} : node_boxes + 6 * std::size_t{b};
    float* out = node_boxes + 6 * std::size_t{i};
    for (int k = 0; k < 3; ++k) out[k] = ba[k] < bb[k] ? ba[k] : bb[k];
    for (int k = 3; k < 6; ++k) out[k] = ba[k] > bb[k] ? ba[k] : bb[k];
    ready_out[i] = 1u;
  }
}

namespace {

// Closed intervals on every axis (touching boxes overlap, NaN never does):
// collision/aabb.h's overlap() on boxes of 6 floats (lo xyz, hi xyz).
bool boxes_overlap(const float* a, const float* b) {
  return a[0] <= b[3] && b[0] <= a[3] && a[1] <= b[4] && b[1] <= a[4] && a[2] <= b[5] && b[2] <= a[5];
}

// Whether two primitives of 3 vertex ids each (SINEW_BVH_NONE unused)
// share a valid id.
bool share_vertex(const std::uint32_t* a, const std::uint32_t* b) {
  bool shared = false;
  for (int s = 0; s < 3; ++s)
    for (int t = 0; t < 3; ++t) shared = shared || (a[s] != SINEW_BVH_NONE && a[s] == b[t]);
  return shared;
}

// Appends (first, second): a slot from the counter, written within the
// capacity; the counter counts on past it (the host reports the overflow).
// Items run in parallel on the CPU too, hence the atomic.
void append_pair(std::uint32_t* pairs, std::uint32_t* counts, std::uint32_t count_word, std::uint32_t capacity,
                 std::uint32_t first, std::uint32_t second) {
  const std::uint32_t slot = std::atomic_ref<std::uint32_t>(counts[count_word]).fetch_add(1u, std::memory_order_relaxed);
  if (slot < capacity) {
    pairs[2 * std::size_t{slot}] = first;
    pairs[2 * std::size_t{slot} + 1] = second;
  }
}

}  // namespace

void bvh_self_pairs(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SelfPairsParams*>(params);
  const auto* children = reinterpret_cast<const std::uint32_t*>(bindings[0]);
  const auto* indices = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* boxes = reinterpret_cast<const float*>(bindings[2]);
  const auto* node_boxes = reinterpret_cast<const float*>(bindings[3]);
  const auto* vertex_ids = reinterpret_cast<const std::uint32_t*>(bindings[4]);
  auto* pairs = reinterpret_cast<std::uint32_t*>(bindings[5]);
  auto* counts = reinterpret_cast<std::uint32_t*>(bindings[6]);
  for (std::uint32_t s = begin; s < end && s < p.count; ++s) {
    const std::uint32_t i = indices[s];
    const float* box = boxes + 6 * std::size_t{i};
    const std::uint32_t* ids = vertex_ids + 3 * std::size_t{i};
    std::uint32_t stack[SINEW_BVH_STACK];
    std::uint32_t top = 0;
    stack[top++] = 0u;  // the root holds every box: no test
    while (top > 0) {
      const std::uint32_t node = stack[--top];
      for (std::uint32_t side = 0; side < 2; ++side) {
        const std::uint32_t c = children[2 * node + side];
        const std::uint32_t child = c & ~SINEW_BVH_LEAF;
        // A left child's leaves end at its index (Karras's numbering): none
        // after s when child <= s. A right leaf before s is skipped too.
        if (child <= s && (side == 0u || (c & SINEW_BVH_LEAF) != 0u)) continue;
        if ((c & SINEW_BVH_LEAF) != 0u) {
          const std::uint32_t j = indices[child];
          if (!boxes_overlap(box, boxes + 6 * std::size_t{j})) continue;
          if (share_vertex(ids, vertex_ids + 3 * std::size_t{j})) continue;
          append_pair(pairs, counts, p.count_word, p.capacity, i < j ? i : j, i < j ? j : i);
        } else if (boxes_overlap(box, node_boxes + 6 * std::size_t{child}) && top < SINEW_BVH_STACK) {
          stack[top++] = child;  // top < 64 always holds for a Karras tree (bvh_params.h)
        }
      }
    }
  }
}

void bvh_tree_pairs(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const TreePairsParams*>(params);
  const auto* boxes_a = reinterpret_cast<const float*>(bindings[0]);
  const auto* children = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* indices = reinterpret_cast<const std::uint32_t*>(bindings[2]);
  const auto* boxes = reinterpret_cast<const float*>(bindings[3]);
  const auto* node_boxes = reinterpret_cast<const float*>(bindings[4]);
  auto* pairs = reinterpret_cast<std::uint32_t*>(bindings[5]);
  auto* counts = reinterpret_cast<std::uint32_t*>(bindings[6]);
  for (std::uint32_t a = begin; a < end && a < p.count; ++a) {
    const float* box = boxes_a + 6 * std::size_t{a};
    if (!boxes_overlap(box, node_boxes)) continue;  // misses B's root
    std::uint32_t stack[SINEW_BVH_STACK];
    std::uint32_t top = 0;
    stack[top++] = 0u;
    while (top > 0) {
      const std::uint32_t node = stack[--top];
      for (std::uint32_t side = 0; side < 2; ++side) {
        const std::uint32_t c = children[2 * node + side];
        const std::uint32_t child = c & ~SINEW_BVH_LEAF;
        if ((c & SINEW_BVH_LEAF) != 0u) {
          const std::uint32_t b = indices[child];
          if (boxes_overlap(box, boxes + 6 * std::size_t{b})) append_pair(pairs, counts, p.count_word, p.capacity, a, b);
        } else if (boxes_overlap(box, node_boxes + 6 * std::size_t{child}) && top < SINEW_BVH_STACK) {
          stack[top++] = child;
        }
      }
    }
  }
}

}  // namespace sinew::kernels
