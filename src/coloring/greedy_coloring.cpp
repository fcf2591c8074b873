// greedy_coloring.cpp — deterministic greedy colouring of the constraint
// graph, with a balancing pass.
//
// Greedy (first-fit) colouring uses at most max-degree + 1 colours but gives
// very uneven colour sizes: the first colours are large, the last hold a few
// constraints each. On a GPU every colour costs a dispatch however small, so
// the balancing pass (in the spirit of Lu, Halappanavar, Chavarría-Miranda,
// Gebremedhin, Panyala, Kalyanaraman, "Balanced Coloring for Parallel
// Computing Applications", IPDPS 2015: "shuffling") evens the sizes without
// adding colours.
#include "coloring/greedy_coloring.h"

#include <algorithm>

namespace sinew {
namespace {

constexpr std::uint32_t kNone = UINT32_MAX;

// CSR adjacency: for each movable particle, the constraints touching it.
struct ParticleToConstraints {
  std::vector<std::uint32_t> offsets;
  std::vector<std::uint32_t> constraints;
};

ParticleToConstraints build_adjacency(std::span<const std::uint32_t> particles, std::uint32_t arity,
                                      std::span<const std::uint8_t> movable) {
  ParticleToConstraints adj;
  adj.offsets.assign(movable.size() + 1, 0);
  for (std::uint32_t p : particles)
    if (movable[p]) ++adj.offsets[p + 1];
  for (std::size_t i = 1; i < adj.offsets.size(); ++i) adj.offsets[i] += adj.offsets[i - 1];
  adj.constraints.resize(adj.offsets.back());
  std::vector<std::uint32_t> fill(adj.offsets.begin(), adj.offsets.end() - 1);
  for (std::size_t k = 0; k < particles.size(); ++k)
    if (movable[particles[k]]) adj.constraints[fill[particles[k]]++] = static_cast<std::uint32_t>(k / arity);
  return adj;
}

// Marks in `stamp` (stamp[colour] == mark) the colours that constraint c may
// not take: those of constraints sharing a movable particle with it.
void mark_forbidden(std::uint32_t c, std::uint32_t mark, std::span<const std::uint32_t> particles,
                    std::uint32_t arity, std::span<const std::uint8_t> movable, const ParticleToConstraints& adj,
                    const std::vector<std::uint32_t>& color_of, std::vector<std::uint32_t>& stamp) {
  for (std::uint32_t k = 0; k < arity; ++k) {
    const std::uint32_t p = particles[c * arity + k];
    if (!movable[p]) continue;
    for (std::uint32_t j = adj.offsets[p]; j < adj.offsets[p + 1]; ++j) {
      const std::uint32_t other = adj.constraints[j];
      if (other == c || color_of[other] == kNone) continue;
      if (color_of[other] >= stamp.size()) stamp.resize(color_of[other] + 1, kNone);
      stamp[color_of[other]] = mark;
    }
  }
}

}  // namespace

Coloring color_constraints(std::span<const std::uint32_t> particles, std::uint32_t arity,
                           std::span<const std::uint8_t> movable) {
  const auto n = static_cast<std::uint32_t>(particles.size() / arity);
  const ParticleToConstraints adj = build_adjacency(particles, arity, movable);
  Coloring out;
  out.color_of.assign(n, kNone);
  std::vector<std::uint32_t> stamp;  // stamp[colour] == c: colour forbidden for constraint c

  // 1. First fit: the lowest colour no neighbour has.
  for (std::uint32_t c = 0; c < n; ++c) {
    mark_forbidden(c, c, particles, arity, movable, adj, out.color_of, stamp);
    std::uint32_t color = 0;
    while (color < stamp.size() && stamp[color] == c) ++color;
    out.color_of[c] = color;
    if (color >= out.color_sizes.size()) out.color_sizes.resize(color + 1, 0);
    ++out.color_sizes[color];
  }

  // 2. Balance: move constraints from colours above the mean size into the
  // lowest colour below the mean that no neighbour has.
  const std::uint32_t colors = out.color_count();
  if (colors < 2) return out;
  const std::uint32_t target = (n + colors - 1) / colors;
  stamp.assign(colors, kNone);
  for (std::uint32_t c = 0; c < n; ++c) {
    const std::uint32_t from = out.color_of[c];
    if (out.color_sizes[from] <= target) continue;
    mark_forbidden(c, c, particles, arity, movable, adj, out.color_of, stamp);
    for (std::uint32_t to = 0; to < colors; ++to) {
      if (to == from || stamp[to] == c || out.color_sizes[to] >= target) continue;
      out.color_of[c] = to;
      --out.color_sizes[from];
      ++out.color_sizes[to];
      break;
    }
  }
  return out;
}

bool coloring_is_valid(const Coloring& coloring, std::span<const std::uint32_t> particles, std::uint32_t arity,
                       std::span<const std::uint8_t> movable) {
  const std::size_t n = particles.size() / arity;
  if (coloring.color_of.size() != n) return false;
  std::vector<std::uint32_t> counted(coloring.color_count(), 0);
  for (std::uint32_t color : coloring.color_of) {
    if (color >= coloring.color_count()) return false;
    ++counted[color];
  }
  if (counted != coloring.color_sizes) return false;
  // For every colour, each movable particle may be touched once.
  std::vector<std::uint32_t> owner(movable.size(), kNone);  // owner[p]: colour that last touched p
  std::vector<std::uint32_t> order(n);
  for (std::uint32_t c = 0; c < n; ++c) order[c] = c;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return coloring.color_of[a] < coloring.color_of[b]; });
  for (std::uint32_t c : order) {
    const std::uint32_t color = coloring.color_of[c];
    for (std::uint32_t k = 0; k < arity; ++k) {
      const std::uint32_t p = particles[c * arity + k];
      if (!movable[p]) continue;
      if (owner[p] == color) return false;
      owner[p] = color;
    }
  }
  return true;
}

}  // namespace sinew
