// particle_order.h — the order particles live in on the device, chosen for
// memory locality, and the constraint order that follows it.
//
// Meshers number vertices in the order their algorithm met them (TetGen,
// Gmsh: front insertion, refinement), so a tet's four vertices are often
// thousands of slots apart and every colour of a Gauss-Seidel sweep touches
// particles all over memory. Renumbering the particles by reverse
// Cuthill-McKee (a breadth-first walk of the mesh graph) puts each
// particle's neighbours within a narrow band of slots; sorting the
// constraints of each colour by their smallest particle then makes a sweep
// walk the particles forward, a few streams the prefetcher follows, and the
// threads of the CPU backend, which split a colour into contiguous halves,
// touch nearly disjoint slots. Measured on 2 cores (organ_step, 10 substeps
// x 1 iteration, medians of 5 runs of 20 frames): kidney_57k 10.2 -> 6.0 ms
// per frame, liver_382k 64 -> 56 ms; a Morton (Z-curve) order by position
// did 7.2 and 47, and slowed the structured cube by 14% where RCM keeps its
// speed (its lexicographic numbering is already banded).
//
// Neither changes a result bit: the colouring still runs in the scene's
// constraint order, and a colour's constraints share no movable particle,
// so their order within it does not matter (tests/reorder_test.cpp checks
// the positions are bitwise equal with and without reordering on every
// backend).
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

/// The particles of `arity` particles each constraint touches.
struct ConstraintList {
  std::span<const std::uint32_t> particles;
  std::uint32_t arity;
};

/// Reverse Cuthill-McKee order of each body's particles (Cuthill, McKee,
/// "Reducing the bandwidth of sparse symmetric matrices", ACM 1969; George,
/// "Computer implementation of the finite element method", 1971): a
/// breadth-first walk of the graph whose edges join particles that share a
/// constraint, from a pseudo-peripheral particle, neighbours by increasing
/// degree, the whole walk reversed. Components are walked one after the
/// other. [in] body_first: the first particle of each body (any order,
/// duplicates allowed); a body runs up to the next body's first particle or
/// the end, and no particle leaves its body's range.
ParticleOrder bandwidth_order(std::uint32_t particles, std::span<const ConstraintList> constraints,
                              std::vector<std::uint32_t> body_first);

/// The identity order (no reordering).
ParticleOrder identity_order(std::uint32_t particles);

/// The order a block's constraints are stored in: colour by colour (colour
/// of constraint c: color_of[c]), and within a colour by smallest particle
/// index when `by_first_particle`, else in their given order. Returns the
/// constraint at each position. [in] particles: `arity` per constraint.
std::vector<std::uint32_t> constraint_order(std::span<const std::uint32_t> particles, std::uint32_t arity,
                                            std::span<const std::uint32_t> color_of, bool by_first_particle);

}  // namespace sinew
