// particle_order.h — the order particles live in on the device, chosen for
// memory locality, and the constraint order that follows it.
//
// Meshers number vertices in the order their algorithm met them (TetGen,
// Gmsh: front insertion, refinement), so a tet's four vertices are often
// thousands of slots apart and every colour of a Gauss-Seidel sweep touches
// particles all over memory. Sorting the particles along a space-filling
// curve (Morton, "A computer oriented geodetic data base and a new technique
// in file sequencing", IBM 1966; its use for mesh locality: Pascucci &
// Frank, "Global static indexing for real-time exploration of very large
// regular grids", SC 2001) puts neighbours in space next to each other in
// memory; sorting the constraints of each colour by their smallest particle
// then makes a sweep walk the particles roughly in order. Neither changes a
// result bit: the colouring still runs in the scene's constraint order, and
// a colour's constraints share no movable particle, so their order within
// it does not matter (tests/reorder_test.cpp checks the positions are
// bitwise equal with and without reordering on every backend).
//
// The user never sees this order: read_positions, read_velocities, vertex
// references and every other API stay in the scene's numbering (a body's
// vertex v is particle body_first_particle + v); only the device buffers use
// the device order.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "math/vec4.h"

namespace sinew {

/// A permutation of the particles that keeps every body's range: device
/// slot of user particle p is device_of[p], and user_of[device_of[p]] == p.
struct ParticleOrder {
  std::vector<std::uint32_t> device_of;  ///< per user particle: its device slot
  std::vector<std::uint32_t> user_of;    ///< per device slot: the user particle
  [[nodiscard]] bool identity() const;
};

/// Morton (Z-curve) order of each body's particles by position, ties kept in
/// user order. [in] body_first: the first particle of each body (any order,
/// duplicates allowed); a body runs up to the next body's first particle or
/// the end. Particles never move between bodies.
ParticleOrder morton_order(std::span<const kernels::float4> positions, std::vector<std::uint32_t> body_first);

/// The identity order (no reordering).
ParticleOrder identity_order(std::uint32_t particles);

/// The order a block's constraints are stored in: colour by colour (colour
/// of constraint c: color_of[c]), and within a colour by smallest particle
/// index when `by_first_particle`, else in their given order. Returns the
/// constraint at each position. [in] particles: `arity` per constraint.
std::vector<std::uint32_t> constraint_order(std::span<const std::uint32_t> particles, std::uint32_t arity,
                                            std::span<const std::uint32_t> color_of, bool by_first_particle);

}  // namespace sinew
