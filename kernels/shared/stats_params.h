/* stats_params.h — the per-frame statistics reduced on the device
 * (FrameStats: residuals, kinetic energy, volume change; the tools' contact
 * reactions), so a frame reads back a few words instead of whole buffers.
 * Shared by every kernel language (sinew_lang.h).
 *
 * Precision. The host used to sum these in double precision; the tests hold
 * them to that (a falling particle's kinetic energy within 1e-9 J). Devices
 * need not have fp64, so the map kernels below compute each term as a
 * double-float (hi, lo) pair — an unevaluated sum of two floats carrying
 * ~48 significant bits (Dekker 1971; Hida, Li, Bailey, "Library for
 * double-double and quad-double arithmetic", 2007) — and reduce_dd_blocks
 * sums such pairs with error-free transformations in a fixed tree order,
 * so every backend gives the same bits and the host adds the few results
 * in double. Every float operation is exact-rounded, never fused
 * (FP_CONTRACT OFF, GLSL precise, -ffp-contract=off on the CPU).
 *
 * Terms are written as float2 (hi, lo), two words per term. */
#ifndef SINEW_STATS_PARAMS_H
#define SINEW_STATS_PARAMS_H

#include "sinew_lang.h"

/* reduce_dd_blocks modes: what item i of the first level is. */
#define SINEW_DD_PAIRS 0u        /* a (hi, lo) pair at values[in_offset + i * in_stride] */
#define SINEW_DD_FLOATS 1u       /* a float at values[in_offset + i * in_stride] */
#define SINEW_DD_SQUARES 2u      /* the exact square of that float */

/* Terms of stats_tool_terms per (particle, tool) slot: the touching mass
 * and the six entries xx, xy, xz, yy, yz, zz of the inertia it lends the
 * tool about its centre. */
#define SINEW_TOOL_TERMS 7u

#ifdef __cplusplus
namespace sinew::kernels {
#endif

/* The map kernels, one item each:
 * stats_kinetic_energy: item i < count (particles):
 *   terms[i] = m |v|^2 / 2 with m = 1 / w (0 when w == 0).
 *   bindings: 0 position float4 [in], 1 velocity float4 [in], 2 terms float2 [out]
 * stats_surface_volume: item i < count (boundary triangles of the tet bodies):
 *   terms[i] = dot(x0 - r, cross(x1 - r, x2 - r)) [m^3] for the triangle
 *   (x0, x1, x2) wound outward and r the position of a particle of its body:
 *   summed over a body's closed boundary this is 6 times the sum of its
 *   tets' signed volumes for any r (the divergence theorem; interior faces
 *   cancel), with ~10x fewer terms than tets, each of size (body size)^3
 *   because r moves with the body.
 *   bindings: 0 position float4 [in], 1 faces uint4 (x0, x1, x2, r particle indices) [in],
 *             2 terms float2 [out]
 * stats_tool_terms: item i < count (particles * tools, the contact impulse
 *   slots of contact_params.h): slot +4 holds (r, m) of a particle touching
 *   the tool; terms[SINEW_TOOL_TERMS i + k] = m, then m (|r|^2 delta_ij - r_i r_j)
 *   for ij = xx, xy, xz, yy, yz, zz (all 0 when m <= 0).
 *   bindings: 0 contact impulses float4 [in], 1 terms float2 [out]
 * stats_inverted_tets: item i < count (the tet bodies' tets, each wound so
 *   that its rest volume is positive; a removed tet as (a, a, a, a)):
 *   flags[i] = 1 when dot(x1 - x0, cross(x2 - x0, x3 - x0)), computed as
 *   stats_surface_volume computes its terms (double-float, so every backend
 *   finds the same sign), is negative, else 0; summed with reduce_blocks
 *   (sum_u32) into FrameStats::inverted_tets.
 *   bindings: 0 position float4 [in], 1 tets uint4 [in], 2 flags uint [out] */
SINEW_STRUCT_BEGIN(StatsParams)
  uint count;
  uint pad0;
  uint pad1;
  uint pad2;
SINEW_STRUCT_END(StatsParams)

/* reduce_dd_blocks: one level of a double-float sum in a fixed order, like
 * reduce_blocks (primitive_params.h): level k holds m = ceil(n / 2^level_shift)
 * items, n = min(counts[count_word], capacity); the first level's items are
 * read per `mode` (SINEW_DD_*), the levels above always pairs (mode
 * SINEW_DD_PAIRS, in_stride 2). Group b loads items [256 b, 256 b + 256)
 * (0 past m), halves the block with v[t] = dd_add(v[t], v[t + s]) for
 * s = 128, ..., 1 and writes v[0] as (hi, lo) to partials[out_offset + 2 b].
 * bindings: 0 counts [in], 1 values [in], 2 partials [out] */
SINEW_STRUCT_BEGIN(ReduceDdParams)
  uint count_word;
  uint capacity;
  uint level_shift;
  uint mode;
  uint in_offset;
  uint in_stride;
  uint out_offset;
  uint pad0;
SINEW_STRUCT_END(ReduceDdParams)

#ifdef __cplusplus
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_STATS_PARAMS_H */
