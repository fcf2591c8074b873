// jones_plassmann.h — the colouring the device computes for the frame's
// contacts (device_contact_coloring.h), written sequentially as the oracle
// the kernels are checked against: Jones and Plassmann, "A Parallel Graph
// Coloring Heuristic", SIAM J. Sci. Comput. 14(3), 1993, with hashed
// priorities, colours capped and an overflow set (Box2D v3's
// constraint_graph.c: a constraint that finds no colour below the cap is
// solved apart, after the colours).
//
// Jones-Plassmann colours a vertex once every neighbour of higher priority
// has its colour, with the lowest colour none of them holds: its result is
// the greedy colouring in descending priority, whatever the parallel
// schedule. A round decides the vertices of highest priority among their
// undecided neighbours, so a particle in d contacts takes d rounds; with a
// cap, a contact whose particles' contacts already hold every colour below
// it joins the overflow set at the start of the next round instead of
// waiting for its turn (the colours are the same: it would find none
// free), so a crowded particle takes about cap rounds. Contacts still
// undecided when the rounds run out join the overflow set too.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "sinew/result.h"

namespace sinew {

/// Colours of contacts that each touch 4 particles, at most `colors` of
/// them, and an overflow set.
struct CappedColoring {
  /// Per contact, its colour in [0, colors), or colors: the overflow set.
  std::vector<std::uint32_t> color_of;
  /// Contacts per colour, colors + 1 entries: the last is the overflow set.
  std::vector<std::uint32_t> color_sizes;
  /// Of the overflow set, the contacts that were still undecided after the
  /// last round (the others found every colour below the cap taken).
  std::uint32_t out_of_rounds = 0;
  /// Rounds the colouring used (rounds + 1 when some contacts were still
  /// undecided after the last).
  std::uint32_t rounds_needed = 0;
  /// Colours that hold a contact (the overflow set not counted).
  [[nodiscard]] std::uint32_t used_colors() const;
};

/// The device's colouring (device_contact_coloring.h), sequentially.
/// [in] particles: contact c touches particles[4c .. 4c + 4) (a particle may
///      repeat). [in] movable: per particle, nonzero when it can move;
///      two contacts conflict only through a shared movable particle.
/// [in] colors: the cap, in [1, 128]; [in] rounds: in [1, 254].
/// Errors (bad_parameter): a size that is not 4 per contact, a particle
/// index past `movable`, more than 2^24 contacts, a cap or rounds out of range.
Result<CappedColoring> jones_plassmann_coloring(std::span<const std::uint32_t> particles,
                                                std::span<const std::uint8_t> movable, std::uint32_t colors,
                                                std::uint32_t rounds);

/// True when no two contacts of one colour below the cap share a movable
/// particle, every contact has a colour in [0, colors] and color_sizes
/// counts them. (Tests and debug checks.)
bool capped_coloring_is_valid(const CappedColoring& coloring, std::span<const std::uint32_t> particles,
                              std::span<const std::uint8_t> movable, std::uint32_t colors);

}  // namespace sinew
