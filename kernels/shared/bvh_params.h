/* bvh_params.h — the BVH built in kernels (issue 12, part 1: Karras,
 * "Maximizing Parallelism in the Construction of BVHs, Octrees, and k-d
 * Trees", HPG 2012): primitives sorted by the Morton code of their box
 * centre (the radix sort of kernels/shared/primitive_params.h), then every
 * internal node found independently from the sorted codes. Shared by every
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
 *           5 ready_out uint per internal node [out] */
#ifndef SINEW_BVH_PARAMS_H
#define SINEW_BVH_PARAMS_H

#include "sinew_lang.h"

#define SINEW_BVH_LEAF 0x80000000u
#define SINEW_BVH_NONE 0xFFFFFFFFu

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

#ifdef __cplusplus
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_BVH_PARAMS_H */
