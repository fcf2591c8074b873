/* narrow_phase_params.h — the narrow phase of triangle surfaces in a kernel
 * (issue 12, part 2 on the device): the contacts of the candidate pairs a
 * BVH traversal appended (bvh_params.h), on every backend, equal to the
 * host reference collision::triangle_contacts (src/collision/
 * narrow_phase.h). Closest points: Ericson, "Real-Time Collision
 * Detection", 2005, 5.1.5 (point-triangle) and 5.1.9 (segment-segment),
 * written in the operation order of kernels/math/proximity_math.h. Shared
 * by every kernel language (sinew_lang.h).
 *
 * ------------------------------------------------------ narrow_triangle_pairs
 * One item per candidate pair k < n, n = min(counts[pair_count_word],
 * pair_capacity) (the traversal's counter, read when the kernel runs: an
 * indirect dispatch over it, FrameProgram::dispatch_indirect). Pair (ti,
 * tj), after the host's separating-axis reject (kernels/math/
 * triangle_separation.h, where the gap is under half the pair's longest
 * edge), tests each vertex of one triangle against the other triangle and
 * each edge of one against each edge of the other, with the host's
 * ownership rule (collision::TriangleOwnership: a vertex or an edge is
 * tested from its owner's pair, or from every pair around it when its
 * owner shares a vertex with the other triangle), skipping vertices of the
 * other triangle and edges that share a vertex; a feature pair closer than
 * `thickness` [m] makes a contact. Two parallel edges fall back on the
 * normal of the second edge's owner triangle (owners[6 t + 3 + edge]), so
 * whichever pair tests them gives the same contact. The ownership rule
 * leaves some feature pairs to several candidate pairs: the host sorts and
 * removes the duplicates (equal bit for bit: the same inputs, the same
 * operations). A pair holding a zero-area triangle or a non-finite corner
 * (no normal to push along; the host reference's error) makes no contact
 * and adds 1 to counts[bad_word].
 *
 * Each contact takes slot = atomic add of 1 to counts[contact_count_word]
 * and is written when slot < contact_capacity (the host declares the
 * counter with that capacity: overflow is reported with the number there
 * was, never truncated in silence), SINEW_CONTACT_WORDS words at
 * contacts[SINEW_CONTACT_WORDS * slot]:
 *   [0]      kind: 0 vertex-triangle, 1 edge-edge
 *   [1..4]   particles: the vertex, then the triangle's three; or the
 *            first edge's two (lower index first), then the second's
 *   [5..8]   weights (float bits): (1, wa, wb, wc) or (1 - s, s, 1 - t, t)
 *   [9..11]  the unit normal (float bits), from the second primitive
 *            towards the first
 *   [12]     the distance between the closest points [m] (float bits)
 *   [13..15] 0
 * (collision::Contact's fields, in its order.) The slots' order depends
 * on the scheduling.
 * bindings: 0 positions float4 (xyz [m], w unused) [in]
 *           1 triangles uint, 3 vertex indices per triangle [in]
 *           2 owners uint, 6 per triangle [in]: the owners of its corners
 *             0-2, then of its edges c -> c + 1 (TriangleOwnership::owner)
 *           3 pairs uint, 2 per pair (triangle indices) [in]
 *           4 counts uint [in/out]: the pair, contact and bad-pair words
 *           5 contacts uint, SINEW_CONTACT_WORDS per contact [out] */
#ifndef SINEW_NARROW_PHASE_PARAMS_H
#define SINEW_NARROW_PHASE_PARAMS_H

#include "sinew_lang.h"

#define SINEW_CONTACT_WORDS 16u

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(TrianglePairsParams)
  uint pair_capacity;      /* pairs the pairs buffer holds */
  uint pair_count_word;    /* counts[pair_count_word]: pairs found */
  uint contact_capacity;   /* contacts the contacts buffer holds */
  uint contact_count_word; /* counts[contact_count_word]: contacts made (zeroed by the host) */
  uint bad_word;           /* counts[bad_word]: pairs with a zero-area triangle or a non-finite corner (zeroed by the host) */
  float thickness;         /* [m], > 0 */
  uint pad0;
  uint pad1;
SINEW_STRUCT_END(TrianglePairsParams)

#ifdef __cplusplus
}  // namespace sinew::kernels
#endif

#endif /* SINEW_NARROW_PHASE_PARAMS_H */
