/* sph_flow_params.h — particles that come and go, and boundaries that move
 * (issue 15, parts 3 and 4): the kernels a fluid's step runs before its
 * neighbour grid, so the particle count n = counts[count_word] changes on
 * the device every step and the host never needs to know it to go on.
 *
 * Every particle's velocity w holds its id as bits: a fluid particle's id
 * (bit 31 clear) counts up from 0 as particles are made; a boundary
 * particle's id is 0x80000000 | b, b its index in the fluid's boundary.
 *
 * The state buffer (uint words, kept across steps):
 *   0 the next fluid id          1 fluid particles emitted in all
 *   2 fluid particles removed in all
 *   3 the particles the last step asked for, n + emitted (the counter
 *     "sph particles": above the capacity the step reports
 *     capacity_exceeded, and the particles past it were not made)
 *   4 lattice points blocked in all (sph_emit_flags)
 *   5 .. 7 unused
 *   8 + e emitter e's phase (float bits): the fraction of a layer's
 *         spacing its flow has moved since its last layer, in [0, 1)
 *
 * An emitter (16 floats): 0..2 its disc's centre [m], 3 rate (layers per
 * step, v dt / spacing, <= 1), 4..6 the flow's unit direction d, 7 the
 * speed v [m/s], 8..10 and 12..14 unit tangents t1, t2 (d, t1, t2
 * orthonormal), 11 its first lattice point (uint bits), 15 its lattice
 * points (uint bits). Lattice points (float4): u, v [m] along t1, t2, the
 * emitter's index (uint bits), 0.
 *
 * ------------------------------------------------------ sph_boundary_move
 * One item per particle s < n: a boundary particle (id bit 31) takes its
 * position and velocity from the boundary's arrays, indexed by b; its w
 * (-psi) and id stay.
 * bindings: 0 counts uint [in]
 *           1 points float4 [in/out]
 *           2 velocity float4 [in/out]
 *           3 boundary_position float4 per boundary particle [in] [m]
 *           4 boundary_velocity float4 per boundary particle [in] [m/s]
 * ------------------------------------------------------ sph_sink_flags
 * One item per particle s < n: flags[s] = 0 for a fluid particle (w > 0)
 * strictly inside a sink, d2 < r^2 with d2 = (dx dx + dy dy) + dz dz in
 * float, else 1.
 * bindings: 0 counts uint [in]
 *           1 points float4 [in]
 *           2 sinks float4 [in]: centre [m], radius^2 [m^2]
 *           3 flags uint [out]
 * ------------------------------------------------------ sph_pack
 * One item per kept particle k < counts[kept_word] (the compaction's
 * count): the particle kept[k] copied to slot k of the packed arrays.
 * Item 0 adds n - kept to state word 2 (removed).
 * bindings: 0 counts uint [in]: [count_word] n, [kept_word] the kept
 *           1 kept uint [in]: the kept particles' indices, in order
 *           2 points float4 [in]      3 velocity float4 [in]
 *           4 packed_points float4 [out]   5 packed_velocity float4 [out]
 *           6 state uint [in/out]
 * ------------------------------------------------------ sph_emit_flags
 * One item per lattice point i < pattern: flags[i] = 1 when its emitter e
 * fires this step (phase_e + rate_e >= 1) and no fluid particle (w > 0)
 * lies within clear = 0.75 spacing of its place (below), else 0; a
 * firing point that is blocked adds 1 to state word 4. Placing a particle
 * on top of another would make a density spike that blows the fluid
 * apart; a submerged source makes only what it finds room for. The
 * particles are searched on the last step's grid: after sph_step, points
 * are in that grid's sorted order, and the 27 cells around the place's
 * cell, floor(x inv_cell), held every particle then within h of it. The
 * CFL bound keeps a step's motion within 0.4 h, so a particle within
 * 0.75 spacing now is found when 0.75 spacing + 0.4 h <= h, that is
 * support >= 1.25 spacings (checked at create). The first step searches
 * no grid (its ranges are zeroed): initial particles on an emitter's
 * lattice are the caller's to avoid.
 * Test: d2 = (dx dx + dy dy) + dz dz < clear2 in float.
 * bindings: 0 counts uint [in]
 *           1 points float4 [in]     2 sorted_cells uint4 [in] (last grid's)
 *           3 ranges uint [in] (last grid's, 3 per bucket)
 *           4 emitters float [in]    5 pattern float4 [in]
 *           6 state uint [in/out]    7 flags uint [out]
 * ------------------------------------------------------ sph_emit
 * One item per lattice point i < pattern with flags[i] = 1: its particle
 * goes to slot n + o (o: the flags set before i) if that is below the
 * capacity, at
 *   centre + u t1 + v t2 + ((phase_e + rate_e) - 1) spacing d
 * (the layer has moved that far past the disc since it crossed it, so
 * layers stay one spacing apart), with velocity v d, mass rest_mass and
 * id state[0] + o. Written in that order of operations:
 *   x = ((c.x + u t1.x) + v t2.x) + depth d.x.
 * bindings: 0 counts uint [in]
 *           1 points float4 [out]     2 velocity float4 [out]
 *           3 emitters float [in]     4 pattern float4 [in]
 *           5 state uint [in]         6 flags uint [in]
 * ------------------------------------------------------ sph_emit_commit
 * One item: the step's emission made official. total = the flags set;
 * state[3] = n + total (the counter); counts[count_word] = min(n + total,
 * capacity); state[0] += total; state[1] += what was made; every phase
 * += rate, less 1 when it fired.
 * bindings: 0 counts uint [in/out]
 *           1 emitters float [in]
 *           2 state uint [in/out]
 *           3 flags uint [in] */
#ifndef SINEW_SPH_FLOW_PARAMS_H
#define SINEW_SPH_FLOW_PARAMS_H

#include "sinew_lang.h"

#define SINEW_SPH_BOUNDARY_ID 0x80000000u /* a boundary particle's id bit */
#define SINEW_SPH_STATE_PHASES 8u        /* the state word of emitter 0's phase */
#define SINEW_SPH_EMITTER_FLOATS 16u

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(SphFlowParams)
  uint count_word;  /* counts[count_word]: the particles n (fluid and boundary) */
  uint kept_word;   /* sph_pack: counts[kept_word], the compaction's count */
  uint capacity;    /* particle slots */
  uint emitters;    /* emitter records */
  uint pattern;     /* lattice points of all emitters */
  uint sinks;       /* sink records */
  float spacing;    /* the fluid's particle spacing [m] */
  float rest_mass;  /* a fluid particle's mass [kg] */
  float inv_cell;   /* sph_emit_flags: the neighbour grid's 1 / cell [1/m] */
  uint table_mask;  /* ... its buckets - 1 */
  float clear2;     /* ... (0.75 spacing)^2 in float [m^2] */
  uint pad;
SINEW_STRUCT_END(SphFlowParams)

#ifdef __cplusplus
}  // namespace sinew::kernels
#endif

#endif /* SINEW_SPH_FLOW_PARAMS_H */
