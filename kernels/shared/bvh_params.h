/* bvh_params.h — the BVH built and traversed in kernels (issue 12, part 1:
 * Karras, "Maximizing Parallelism in the Construction of BVHs, Octrees, and
 * k-d Trees", HPG 2012): primitives sorted by the Morton code of their box
 * centre (the radix sort of kernels/shared/primitive_params.h), then every
 * internal node found independently from the sorted codes; the candidate
 * pairs found by one independent traversal per primitive (Karras, "Thinking
 * Parallel, Part II: Tree Traversal on the GPU", NVIDIA blog 2012: a stack
 * per thread, pairs appended through an atomic counter). Shared by every
 * kernel language (sinew_lang.h).
 *
 * ------------------------------------------------------------ bvh_morton_codes
 * One item per primitive i < count.
 * bindings: 0 boxes float, 6 per primitive (lo xyz, hi xyz) [in]
 *           1 codes uint [out]: the 30-bit Morton code of the box centre,
 *             10 bits per axis after scaling the scene's bounds [lo, lo +
 *             1 / inv_extent] to [0, 1023] (clamped: a centre outside the
 *             given bounds takes the nearest cell, never another code)
 *           2 indices uint [out]: i (the sort's values)
 *
 * ------------------------------------------------------------ bvh_karras_nodes
 * One item per internal node i < count - 1 (count >= 2 sorted codes).
 * Keys are the codes with ties broken by position (delta = 32 + clz(i ^ j)
 * for equal codes), so duplicate codes still give a valid binary tree.
 * bindings: 0 sorted codes uint [in]
 *           1 children uint, 2 per internal node [out]: the left and right
 *             child; an internal node's index, or a leaf's (sorted
 *             position) | SINEW_BVH_LEAF
 *           2 parents uint [out]: internal node c's parent at [c], sorted
 *             leaf c's at [count - 1 + c]; the root's (node 0) is
 *             SINEW_BVH_NONE
 *
 * ------------------------------------------------------------ bvh_refit_pass
 * One item per internal node i < count - 1: one pass of the bottom-up box
 * computation. A node whose two children were ready before this pass
 * (`ready_in`; leaves always are) writes its box, the union of theirs, and
 * marks itself in `ready_out`, which the host has made a copy of
 * `ready_in` first. Reading the flags of the previous pass only, never the
 * ones being written, needs no atomics and is the same on every backend;
 * a tree's depth is at most 64 (each level lengthens the common prefix of
 * the 32-bit code and 32-bit position keys), so 64 passes finish any tree.
 * bindings: 0 children uint [in], 1 indices uint (sorted position ->
 *           primitive) [in], 2 boxes float, 6 per primitive [in],
 *           3 node boxes float, 6 per internal node [in/out],
 *           4 ready_in uint per internal node [in],
 *           5 ready_out uint per internal node [out]
 *
 * ------------------------------------------------------------ the traversals
 * Candidate pairs of a built and refitted tree: one item walks the tree
 * from the root with a stack of internal nodes (leaves are tested when
 * met, never pushed). 64 entries are enough: after a node at depth d is
 * expanded the stack holds at most one pending sibling for each depth 1 ..
 * d and its two children, d + 2 entries; an internal node's delta (the
 * common prefix of its range's 64-bit keys, 0 .. 63) exceeds its parent's,
 * so internal nodes lie at depths 0 .. 63 and d + 2 <= 64
 * (SINEW_BVH_STACK). Two boxes overlap when their closed intervals do on
 * every axis (touching boxes overlap; a NaN never does), the test of
 * src/collision/aabb.h in every language, so each backend finds the same
 * set. Every pair found takes slot = atomic add of 1 to counts[count_word]
 * and is written to pairs[2 slot], pairs[2 slot + 1] only when slot <
 * capacity; the counter keeps counting past the capacity, so the host
 * declares it a counter of that capacity and overflow is reported with the
 * number of pairs there were, never truncated in silence. The pairs' order
 * in the buffer depends on the scheduling: sort them on the host.
 *
 * ------------------------------------------------------------ bvh_self_pairs
 * One item per sorted leaf position s < count: its primitive i =
 * indices[s] against the leaves at positions t > s (each unordered pair
 * once; Karras numbers a left child by the last leaf of its range, so a
 * left child c <= s holds no such leaf and is skipped without a test).
 * Emits (min(i, j), max(i, j)), j = indices[t], when the boxes overlap and
 * the two primitives share no vertex id (self-collision skips neighbours).
 * bindings: 0 children uint [in], 1 indices uint [in], 2 boxes float, 6 per
 *           primitive [in], 3 node boxes float, 6 per internal node [in],
 *           4 vertex ids uint, 3 per primitive [in]: a point's 1, a
 *             segment's 2 or a triangle's 3 vertex ids, unused slots
 *             SINEW_BVH_NONE (never equal to anything),
 *           5 pairs uint, 2 per pair [out], 6 counts uint [in/out]
 *
 * ------------------------------------------------------------ bvh_tree_pairs
 * One item per primitive a < count of another set A: its box against the
 * tree over set B (tree_count >= 2 leaves); emits (a, b) for every
 * primitive b of B whose box overlaps (no order or vertex condition: two
 * bodies share no vertex).
 * bindings: 0 boxes of A float, 6 per primitive [in], 1 children of B's
 *           tree uint [in], 2 indices uint [in], 3 boxes of B float, 6 per
 *           primitive [in], 4 node boxes float, 6 per internal node [in],
 *           5 pairs uint, 2 per pair [out], 6 counts uint [in/out] */
#ifndef SINEW_BVH_PARAMS_H
#define SINEW_BVH_PARAMS_H

#include "sinew_lang.h"

#define SINEW_BVH_LEAF 0x80000000u
#define SINEW_BVH_NONE 0xFFFFFFFFu
#define SINEW_BVH_STACK 64u /* a traversal's stack of internal nodes (see above) */

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(MortonParams)
  uint count;
  float lo_x;
  float lo_y;
  float lo_z;
  float inv_extent_x; /* 1 / (hi - lo) per axis [1/m]; 0 for a flat axis */
  float inv_extent_y;
  float inv_extent_z;
  uint pad0;
SINEW_STRUCT_END(MortonParams)

SINEW_STRUCT_BEGIN(KarrasParams)
  uint count; /* sorted codes (leaves), >= 2 */
  uint pad0;
  uint pad1;
  uint pad2;
SINEW_STRUCT_END(KarrasParams)

SINEW_STRUCT_BEGIN(RefitParams)
  uint count; /* leaves, >= 2 */
  uint pad0;
  uint pad1;
  uint pad2;
SINEW_STRUCT_END(RefitParams)

SINEW_STRUCT_BEGIN(SelfPairsParams)
  uint count;      /* leaves, >= 2 */
  uint capacity;   /* pairs the pairs buffer holds */
  uint count_word; /* the counter: counts[count_word], 0 before the dispatch */
  uint pad0;
SINEW_STRUCT_END(SelfPairsParams)

SINEW_STRUCT_BEGIN(TreePairsParams)
  uint count;      /* primitives of set A (items) */
  uint tree_count; /* leaves of set B's tree, >= 2 */
  uint capacity;   /* pairs the pairs buffer holds */
  uint count_word; /* the counter: counts[count_word], 0 before the dispatch */
SINEW_STRUCT_END(TreePairsParams)

#ifdef __cplusplus
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_BVH_PARAMS_H */
