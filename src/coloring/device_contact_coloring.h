// device_contact_coloring.h — the frame's contacts coloured on the device
// (kernels/shared/contact_coloring_params.h): Jones and Plassmann, "A
// Parallel Graph Coloring Heuristic", SIAM J. Sci. Comput. 14(3), 1993,
// with hashed priorities, at most `colors` colours and an overflow set
// (Box2D v3's constraint_graph.c), then the contacts sorted by colour
// (the stable radix sort of program/primitives.h), so that a solve reads
// colour k's contacts at order[first_k, first_k + count_k) and takes its
// count from a device word (an indirect dispatch), never from the host.
//
// Why Jones-Plassmann with hashed priorities: its result is the greedy
// colouring in descending priority (coloring/jones_plassmann.h), whatever
// order the work items run in, so every backend gives the same bits and
// the host has a sequential oracle. Each round costs two dispatches over
// the contacts still undecided (an indirect dispatch over a list the
// previous round appended to); a contact is decided in the round after
// its last neighbour of higher priority, so the rounds a set needs are at
// least the most contacts on one movable particle. Why a cap: every colour
// is a dependent dispatch in every sweep; a contact that finds every
// colour below the cap taken by its neighbours, or is undecided when the
// rounds run out, joins the overflow set, solved after the colours one by
// one (counted: the table's word `colors` and out_of_rounds_word()).
#pragma once

#include <cstdint>
#include <vector>

#include "backends/backend.h"
#include "coloring/jones_plassmann.h"

namespace sinew {

/// The device buffers of the colouring of at most `capacity` contacts over
/// `particles` particles.
struct DeviceContactColoring {
  std::uint32_t capacity = 0;   ///< contacts
  std::uint32_t particles = 0;  ///< particles of the positions the contacts index
  std::uint32_t colors = 0;     ///< the cap: colours below the overflow set
  std::uint32_t rounds = 0;     ///< Jones-Plassmann rounds in the program
  /// The table (contact_coloring_params.h): per colour and the overflow set
  /// its count (words [0, colors]) and first slot (words [colors + 1,
  /// 2 colors + 2)), the contacts to colour n at count_word() (written by
  /// whoever makes the contacts: the host, or a kernel of the same frame).
  BufferHandle table;
  BufferHandle order;  ///< [out] the contact (its index) at each slot, colour-sorted, stable
  BufferHandle colour;  ///< the contacts' colours; [out] after the sort, per slot (sorted)
  BufferHandle lists, owner, masks, colour_tmp, order_tmp, scratch;  // the rounds' and the sort's
  [[nodiscard]] std::uint32_t table_colors() const { return colors + 1; }  ///< colours in the table, overflow included
  [[nodiscard]] std::uint32_t count_word() const { return 2 * (colors + 1); }
  [[nodiscard]] std::uint32_t out_of_rounds_word() const { return count_word() + 3; }
  [[nodiscard]] std::uint32_t table_words() const { return count_word() + 4; }
};

/// Creates the buffers. [in] capacity: contacts, in [1, 2^24]; particles
/// >= 1; colors in [1, 128]; rounds in [1, 254]. Errors name a value out
/// of range (bad_parameter) or a failed allocation.
Result<DeviceContactColoring> make_device_contact_coloring(Device& device, std::uint32_t capacity,
                                                           std::uint32_t particles, std::uint32_t colors,
                                                           std::uint32_t rounds);

/// Destroys its buffers.
Status destroy_device_contact_coloring(Device& device, DeviceContactColoring& coloring);

/// Appends the colouring of the n = table[count_word()] contacts (at most
/// the capacity: a larger n is a capacity_exceeded error naming "contacts
/// to colour") and their sort by colour: afterwards the table holds each
/// colour's count and first slot and `order` the contacts slot by slot.
/// [in] contacts: uint4 per contact, its four particles (repeats allowed);
/// [in] positions: float4 per particle, w the inverse mass (movable: w > 0).
/// Declares as counters the contacts to colour, the two round lists' sizes
/// and the overflow set ("contacts in the overflow set", capacity: all).
/// About 2 rounds + 15 dispatches.
void append_device_contact_coloring(FrameProgram& program, const DeviceContactColoring& coloring,
                                    BufferHandle contacts, BufferHandle positions);

/// Reads a colouring back (tests, benchmarks): the colour of each of the n
/// contacts from the table and `order`, the sizes and the contacts out of
/// rounds. [out] order: the slots' contacts (when not null). Errors: a
/// read failure, or a table and order that disagree (internal).
Result<CappedColoring> read_device_contact_coloring(Device& device, const DeviceContactColoring& coloring,
                                                    std::vector<std::uint32_t>* order = nullptr);

}  // namespace sinew
