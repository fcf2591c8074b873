// greedy_coloring.h — colours constraints so that no two constraints of one
// colour share a movable particle. Each colour is then one parallel dispatch
// of a graph-coloured Gauss-Seidel sweep (Fratarcangeli, Tibaldo, Pellacini,
// "Vivace: a Practical Gauss-Seidel Method for Stable Soft Body Dynamics",
// SIGGRAPH Asia 2016), and colour order makes the solve deterministic.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace sinew {

struct Coloring {
  std::vector<std::uint32_t> color_of;     ///< per constraint, in [0, color_count)
  std::vector<std::uint32_t> color_sizes;  ///< constraints per colour
  [[nodiscard]] std::uint32_t color_count() const { return static_cast<std::uint32_t>(color_sizes.size()); }
};

/// Colours constraints that each touch `arity` particles.
/// [in] particles: constraint c touches particles[c*arity .. c*arity+arity).
/// [in] movable: per particle, nonzero when it can move (inverse mass > 0).
///      Two constraints conflict only through a shared movable particle.
/// [in] particle_count: size of `movable`; every index must be below it.
/// Deterministic: first-fit greedy in constraint order, then one balancing
/// pass that moves constraints out of colours larger than the mean into the
/// lowest smaller colour they fit in (the colour count never grows).
Coloring color_constraints(std::span<const std::uint32_t> particles, std::uint32_t arity,
                           std::span<const std::uint8_t> movable);

/// True when every constraint has a colour in range and no two constraints
/// of one colour share a movable particle. (Used by tests and debug checks.)
bool coloring_is_valid(const Coloring& coloring, std::span<const std::uint32_t> particles, std::uint32_t arity,
                       std::span<const std::uint8_t> movable);

}  // namespace sinew
