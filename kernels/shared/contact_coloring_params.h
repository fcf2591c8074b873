/* contact_coloring_params.h — the contacts' colouring on the device
 * (src/coloring/device_contact_coloring.h): Jones and Plassmann, "A Parallel
 * Graph Coloring Heuristic", SIAM J. Sci. Comput. 14(3), 1993, with hashed
 * priorities, capped colours and an overflow set (as Box2D v3's
 * constraint_graph.c). Shared by every kernel language (sinew_lang.h).
 *
 * Two contacts conflict when they share a movable particle (inverse mass
 * w > 0 in the positions' w). Every contact c has a priority prio(c), a
 * bijection of [0, 2^24) (SINEW_COLOR_PRIORITY below), so no two contacts
 * tie. In round r every contact not yet decided claims each of its movable
 * particles with the key (r + 1) 2^24 + prio(c) (atomic max); a contact that
 * holds all its particles' claims is decided in that round: it takes the
 * lowest colour below `colors` that none of its particles' masks holds
 * (the colours of its neighbours decided before it), or the overflow set
 * (colour `colors`) when none is free, and sets its colour in its
 * particles' masks. Two contacts decided in one round share no movable
 * particle, so a contact's neighbours of higher priority are exactly those
 * decided before it: the result is the sequential greedy colouring in
 * descending priority (src/coloring/jones_plassmann.h), whatever the order
 * the items run in. Contacts still undecided after `rounds` rounds join the
 * overflow set too (counted apart). The round's key makes an earlier
 * round's claims lose against this round's, so the owners are never reset.
 *
 * The table (one uint buffer, binding "table"), with C = colors + 1:
 *   [0, C)        contacts per colour; word colors: the overflow set
 *   [C, 2C)       each colour's first slot in `order` (after
 *                 the table step and the sort)
 *   2C            n, the contacts to colour (written before the frame)
 *   2C + 1, 2C+2  the sizes of the two round lists (ping-pong)
 *   2C + 3        contacts that joined the overflow set for lack of rounds
 * so xpbd_solve_mesh_contacts reads colour k's count at word k and its
 * first slot at word C + k, as from the host's table.
 *
 * ------------------------------------------------------- contact_coloring
 * One kernel, one step per dispatch (`step`; one registry entry for the
 * five). bindings: 0 table uint [in/out], 1 particles uint4 per contact
 * (its four particles, repeats allowed) [in], 2 positions float4 per
 * particle (w: inverse mass) [in], 3 colour uint per contact [out],
 * 4 lists uint (2 capacity: list 0, then list 1) [in/out], 5 order uint
 * per contact [out], 6 owner uint per particle [in/out], 7 masks uint
 * (mask_words per particle) [in/out].
 *   init    one item per contact i < n (launched for the capacity):
 *           colour[i] = none, lists[i] = i (round 0's list: every
 *           contact), order[i] = i, its particles' owners and masks 0;
 *           item 0 zeroes the counts and firsts, sets list 0's size to n
 *           and list 1's and the rounds' overflow to 0.
 *   claim   one item per contact of list `list_in` (lists[list_in *
 *           capacity + j], j < table[2C + 1 + list_in]: an indirect
 *           dispatch): a contact whose movable particles' masks hold every
 *           colour below the cap joins the overflow set now (it would find
 *           none free when its turn came; so a particle in more contacts
 *           than the cap does not take a round for each); the others put
 *           their key into each movable particle's owner (atomic max).
 *   decide  the same items: a contact that holds every movable particle's
 *           claim takes its colour (or the overflow set) as above, counts
 *           itself in the table and sets its colour's bit in its movable
 *           particles' masks; the others, but those the claims sent to the
 *           overflow set, are appended to the other list (its size zeroed
 *           by the program before the round).
 *   finish  one item per contact left in list `list_in` after the last
 *           round: the overflow set, counted in word colors and in 2C + 3.
 *   table   one item: the firsts, table[C + k] = sum of table[j], j < k. */
#ifndef SINEW_CONTACT_COLORING_PARAMS_H
#define SINEW_CONTACT_COLORING_PARAMS_H

#include "sinew_lang.h"

/* At most this many colours below the overflow set, and rounds: the key
 * holds the round in its top 8 bits (round + 1 <= 255), a mask 4 words. */
#define SINEW_COLOR_MAX_COLORS 128u
#define SINEW_COLOR_MAX_ROUNDS 254u
#define SINEW_COLOR_MAX_CONTACTS 16777216u /* 2^24: priorities are 24-bit and distinct */
#define SINEW_COLOR_NONE 0xFFFFFFFFu
/* ContactColoringParams::step */
#define SINEW_COLOR_STEP_INIT 0u
#define SINEW_COLOR_STEP_CLAIM 1u
#define SINEW_COLOR_STEP_DECIDE 2u
#define SINEW_COLOR_STEP_FINISH 3u
#define SINEW_COLOR_STEP_TABLE 4u

/* The priority of contact i < 2^24: a bijection of [0, 2^24) that scatters
 * neighbouring indices (odd multipliers and xor-shifts are each invertible
 * modulo 2^24). Written once as a macro chain so that C++, OpenCL C and
 * GLSL compute the very same bits. */
#define SINEW_COLOR_MASK24 0x00FFFFFFu
#define SINEW_COLOR_MIX_A(i) (((i) * 0x9E3779B1u) & SINEW_COLOR_MASK24)
#define SINEW_COLOR_MIX_B(h) ((h) ^ ((h) >> 12u))
#define SINEW_COLOR_MIX_C(h) (((h) * 0x2C1B3C6Du) & SINEW_COLOR_MASK24)
#define SINEW_COLOR_MIX_D(h) ((h) ^ ((h) >> 13u))

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(ContactColoringParams)
  uint capacity;    /* contacts the buffers hold; n = min(table[2C], capacity) */
  uint colors;      /* colours below the overflow set, in [1, SINEW_COLOR_MAX_COLORS] */
  uint mask_words;  /* ceil(colors / 32): uint words of each particle's mask */
  uint round;       /* this round, from 0 (claim, decide) */
  uint list_in;     /* 0 or 1: the list this round reads (claim, decide, finish) */
  uint step;        /* SINEW_COLOR_STEP_* */
  uint pad1;
  uint pad2;
SINEW_STRUCT_END(ContactColoringParams)

#ifdef __cplusplus
/* prio(i) (see above), for the CPU kernels and the host's reference. */
constexpr uint contact_color_priority(uint i) {
  const uint a = SINEW_COLOR_MIX_A(i);
  const uint b = SINEW_COLOR_MIX_B(a);
  const uint c = SINEW_COLOR_MIX_C(b);
  return SINEW_COLOR_MIX_D(c);
}
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_CONTACT_COLORING_PARAMS_H */
