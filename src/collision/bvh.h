// bvh.h — the CPU reference bounding-volume hierarchy of the broad phase
// (issue 12): built top-down over primitive boxes, refitted bottom-up when
// the primitives move, rebuilt when refitting has let its quality decay;
// pairs of overlapping primitive boxes found BVH against BVH and within one
// BVH (self-collision). Simple and obviously right on purpose: it is the
// oracle the fast paths (Embree on the CPU, Karras's Morton-code BVH in the
// GPU kernels) are checked against, together with brute_force_pairs.
//
// Build: median split of the primitives' centroids along the longest axis
// of their centroid bounds, leaves of at most kLeafSize primitives (the
// classic object-median BVH; Wald, Boulos, Shirley, "Ray tracing
// deformable scenes using dynamic bounding volume hierarchies", TOG 26(1),
// 2007, for refitting and the rebuild heuristic). The median is taken from
// the primitives presorted once along each axis (radix sorts) and split
// stably at every node, as kd-tree builders do (Wald and Havran, "On
// building fast kd-trees for ray tracing, and on doing that in O(N log N)",
// IEEE Symposium on Interactive Ray Tracing 2006): every level is a few
// sequential passes instead of a selection through the centroids (the
// 4,960-triangle surface of a 50,400-tet block: 1.5 -> 0.7 ms, rebuilt
// after each cut). Quality: the sum of the nodes' surface areas over the
// root's (the SAH cost of an overlap query up to constants); rebuild when a
// refit has grown it past a factor of the cost right after the last build.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "collision/aabb.h"

namespace sinew::collision {

/// A pair of primitive indices (first from the first set, second from the
/// second; within one set first < second).
using Pair = std::pair<std::uint32_t, std::uint32_t>;

class Bvh {
 public:
  static constexpr std::uint32_t kLeafSize = 4;

  struct Node {
    Aabb box;
    std::uint32_t left = 0;   ///< inner: index of the first child (the second is left + 1)
    std::uint32_t first = 0;  ///< leaf: first slot in order()
    std::uint32_t count = 0;  ///< leaf: primitives (> 0); inner: 0
  };

  /// Builds over `boxes` (one per primitive; none: an empty hierarchy).
  /// Every node's primitives are one run of slots in order(), its left
  /// child's before its right child's (normal_cones.cpp relies on it);
  /// within a leaf they are in order along x.
  void build(std::span<const Aabb> boxes);
  /// Recomputes every node's box from the primitives' new boxes (same
  /// count as at build) bottom-up; the tree's shape is kept.
  void refit(std::span<const Aabb> boxes);
  /// refit() with the boxes given in leaf order: leaf_boxes[k] is the box
  /// of primitive order()[k] (e.g. LeafVertices::boxes, leaf_vertices.h).
  /// [in,out] leaf_boxes: taken by the tree, which hands back its previous
  /// leaf boxes (a swap, not a copy). Errors (bad_parameter): a count other
  /// than the tree's primitives' (nothing changed then).
  Status refit_leaves(std::vector<Aabb>& leaf_boxes);
  /// Builds anew over the boxes of the last build or refit (leaf_boxes()).
  void rebuild();
  /// Sum of node half-areas over the root's: grows as a refitted tree's
  /// boxes swell and overlap. 0 for an empty tree.
  [[nodiscard]] double cost() const;
  /// cost() over the cost right after the last build.
  [[nodiscard]] double degradation() const;
  /// Refits to `boxes`, then rebuilds if that left degradation() above
  /// `max_degradation` (> 1; 2 by default: a refitted tree whose boxes
  /// have grown to twice the summed area of a fresh one). Returns whether
  /// it rebuilt. A refit costs ~1 ms on the liver surface, a build ~30.
  bool update(std::span<const Aabb> boxes, double max_degradation = 2.0);

  [[nodiscard]] const std::vector<Node>& nodes() const { return nodes_; }
  /// Primitive indices in leaf order: leaf n holds order()[first .. first + count).
  [[nodiscard]] const std::vector<std::uint32_t>& order() const { return order_; }
  /// The primitives' boxes in leaf order (leaf_boxes()[k] = boxes[order()[k]]
  /// as of the last build or refit): traversals read a leaf's boxes from
  /// consecutive memory instead of through order() (the liver's surface,
  /// 2.1M primitive tests: the traversal took 30 ms without this copy, 20
  /// with it).
  [[nodiscard]] const std::vector<Aabb>& leaf_boxes() const { return leaf_boxes_; }
  [[nodiscard]] bool empty() const { return nodes_.empty(); }
  /// A number no other build() in the process has had: what is derived
  /// from the tree's shape (normal_cones.h) is recomputed when it changes.
  [[nodiscard]] std::uint64_t build_id() const { return build_id_; }

 private:
  void refit_nodes();  // every node's box from leaf_boxes_, bottom-up
  struct Presorted;  // the build's scratch (bvh.cpp)
  void build_node(Presorted& sorted, std::uint32_t index, std::uint32_t first, std::uint32_t count);
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;
  std::vector<Aabb> leaf_boxes_;
  double built_cost_ = 0.0;
  std::uint64_t build_id_ = 0;
};

/// The traversals' default: nothing is culled. A culling policy (e.g.
/// NormalCones, normal_cones.h) says which nodes cannot touch themselves
/// (self) and which pairs of disjoint nodes of one tree cannot touch each
/// other (pair); the self traversal skips their primitive pairs.
struct NoCulling {
  [[nodiscard]] bool self(std::uint32_t) const { return false; }
  [[nodiscard]] bool pair(std::uint32_t, std::uint32_t) const { return false; }
};

/// Every (i, j) with primitive i of `a` overlapping primitive j of `b`, for
/// the boxes of each tree's last build() or refit(): a traversal of both
/// trees. [out] pairs, sorted.
void overlapping_pairs(const Bvh& a, const Bvh& b, std::vector<Pair>& pairs);

/// Every (i, j), i < j, of one tree's primitives with overlapping boxes (as
/// of its last build or refit), skipping pairs for which skip(i, j) is true
/// (e.g. triangles sharing a vertex) and the pairs `cull` rules out (see
/// NoCulling). [out] pairs, sorted.
template <class Skip, class Cull = NoCulling>
void self_overlapping_pairs(const Bvh& tree, Skip skip, std::vector<Pair>& pairs, const Cull& cull = {});

/// The oracles: every pair tested, O(n m) and O(n^2 / 2). [out] pairs, sorted.
void brute_force_pairs(std::span<const Aabb> boxes_a, std::span<const Aabb> boxes_b, std::vector<Pair>& pairs);
template <class Skip>
void brute_force_self_pairs(std::span<const Aabb> boxes, Skip skip, std::vector<Pair>& pairs);

/// skip() for primitives of `Arity` vertices each (3: triangles, 2:
/// segments): whether primitives i and j share a vertex. The arity is a
/// template parameter so the comparisons unroll into one branch: with a
/// run-time arity the loop's unpredictable exits took twice as long (the
/// liver surface's 768,000 overlapping pairs: 9.2 against 4.6 ms).
template <int Arity>
struct SharesVertexOf {
  std::span<const std::uint32_t> indices;  ///< Arity per primitive
  bool operator()(std::uint32_t i, std::uint32_t j) const {
    const std::uint32_t* a = indices.data() + std::size_t{i} * Arity;
    const std::uint32_t* b = indices.data() + std::size_t{j} * Arity;
    bool shared = false;
    for (int p = 0; p < Arity; ++p)
      for (int q = 0; q < Arity; ++q) shared |= a[p] == b[q];
    return shared;
  }
};
using SharesVertex = SharesVertexOf<3>;

// ---- templates

namespace detail {
// Visits every pair of leaves whose boxes overlap, from the node pair
// (i, j): within one tree (self = true, a == b: node i with itself visits
// each unordered pair of its distinct leaves once and every leaf with
// itself) or across two. `cull` (self only): the nodes and node pairs
// never visited.
template <class Visit, class Cull = NoCulling>
void traverse_from(const Bvh& a, const Bvh& b, bool self, std::uint32_t i0, std::uint32_t j0, Visit visit,
                   const Cull& cull = {}) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{i0, j0}};
  const auto& na = a.nodes();
  const auto& nb = b.nodes();
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    const Bvh::Node& x = na[i];
    const Bvh::Node& y = nb[j];
    if (self && i == j) {  // a node against itself: its children against themselves and each other
      if (cull.self(i)) continue;
      if (x.count > 0) {
        visit(x, x);
        continue;
      }
      stack.push_back({x.left, x.left});
      stack.push_back({x.left + 1, x.left + 1});
      stack.push_back({x.left, x.left + 1});
      continue;
    }
    if (!overlap(x.box, y.box)) continue;
    if (self && cull.pair(i, j)) continue;
    if (x.count > 0 && y.count > 0) {
      visit(x, y);
    } else if (y.count > 0 || (x.count == 0 && half_area(x.box) >= half_area(y.box))) {
      stack.push_back({x.left, j});  // descend the larger (or the only inner) node
      stack.push_back({x.left + 1, j});
    } else {
      stack.push_back({i, y.left});
      stack.push_back({i, y.left + 1});
    }
  }
}

// The whole traversal, from the roots.
template <class Visit>
void traverse(const Bvh& a, const Bvh& b, bool self, Visit visit) {
  if (a.empty() || b.empty()) return;
  traverse_from(a, b, self, 0, 0, visit);
}

void sort_unique(std::vector<Pair>& pairs);
}  // namespace detail

template <class Skip, class Cull>
void self_overlapping_pairs(const Bvh& tree, Skip skip, std::vector<Pair>& pairs, const Cull& cull) {
  pairs.clear();
  if (tree.empty()) return;
  const auto& order = tree.order();
  const auto& leaf = tree.leaf_boxes();
  detail::traverse_from(tree, tree, true, 0, 0, [&](const Bvh::Node& x, const Bvh::Node& y) {
    const bool same = &x == &y;
    for (std::uint32_t s = 0; s < x.count; ++s)
      for (std::uint32_t t = same ? s + 1 : 0; t < y.count; ++t) {
        if (!overlap(leaf[x.first + s], leaf[y.first + t])) continue;
        std::uint32_t i = order[x.first + s], j = order[y.first + t];
        if (i > j) std::swap(i, j);
        if (!skip(i, j)) pairs.push_back({i, j});
      }
  }, cull);
  detail::sort_unique(pairs);
}

template <class Skip>
void brute_force_self_pairs(std::span<const Aabb> boxes, Skip skip, std::vector<Pair>& pairs) {
  pairs.clear();
  const auto n = static_cast<std::uint32_t>(boxes.size());
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = i + 1; j < n; ++j)
      if (overlap(boxes[i], boxes[j]) && !skip(i, j)) pairs.push_back({i, j});
}

}  // namespace sinew::collision
