/* bvh_pairs.h — helpers of the BVH traversals (bvh_self_pairs.gpu,
 * bvh_tree_pairs.gpu), twins of the ones in kernels/cpu/bvh_kernels.cpp:
 * the closed-interval box test and the shared-vertex test. Comparisons
 * only, so nothing here rounds and nothing needs PRECISE. */
#ifndef SINEW_BVH_PAIRS_H
#define SINEW_BVH_PAIRS_H

#include "bvh_params.h"

/* Closed intervals on every axis (touching boxes overlap, NaN never does):
 * collision/aabb.h's overlap(), in its order. */
bool bvh_boxes_overlap(float3 a_lo, float3 a_hi, float3 b_lo, float3 b_hi) {
  return a_lo.x <= b_hi.x && b_lo.x <= a_hi.x && a_lo.y <= b_hi.y && b_lo.y <= a_hi.y && a_lo.z <= b_hi.z &&
         b_lo.z <= a_hi.z;
}

/* Whether two primitives' vertex ids (3 each, SINEW_BVH_NONE unused)
 * share a valid id. */
bool bvh_share_vertex(uint4 a, uint4 b) {
  const uint ids_a[3] = {a.x, a.y, a.z};
  const uint ids_b[3] = {b.x, b.y, b.z};
  bool shared_id = false;
  for (int s = 0; s < 3; ++s)
    for (int t = 0; t < 3; ++t) shared_id = shared_id || (ids_a[s] != SINEW_BVH_NONE && ids_a[s] == ids_b[t]);
  return shared_id;
}

#endif /* SINEW_BVH_PAIRS_H */
