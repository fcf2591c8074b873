// jones_plassmann.cpp — the sequential form of the device's contact
// colouring (see jones_plassmann.h; Jones and Plassmann, SIAM J. Sci.
// Comput. 14(3), 1993): round by round, the contacts that every colour
// below the cap has left join the overflow set, then those of highest
// priority on each of their movable particles take the lowest colour their
// particles' earlier contacts leave free.
#include "coloring/jones_plassmann.h"

#include <algorithm>
#include <numeric>
#include <string>

#include "contact_coloring_params.h"

namespace sinew {
namespace {
constexpr std::uint32_t kUndecided = UINT32_MAX;
}  // namespace

std::uint32_t CappedColoring::used_colors() const {
  std::uint32_t used = 0;
  for (std::size_t k = 0; k + 1 < color_sizes.size(); ++k) used += color_sizes[k] > 0 ? 1u : 0u;
  return used;
}

Result<CappedColoring> jones_plassmann_coloring(std::span<const std::uint32_t> particles,
                                                std::span<const std::uint8_t> movable, std::uint32_t colors,
                                                std::uint32_t rounds) {
  if (particles.size() % 4 != 0)
    return Error(ErrorCode::bad_parameter, "contact colouring: " + std::to_string(particles.size()) +
                                               " particle indices are not 4 per contact");
  const std::size_t n = particles.size() / 4;
  if (n > SINEW_COLOR_MAX_CONTACTS)
    return Error(ErrorCode::bad_parameter, "contact colouring: " + std::to_string(n) + " contacts, at most 2^24");
  if (colors < 1 || colors > SINEW_COLOR_MAX_COLORS)
    return Error(ErrorCode::bad_parameter, "contact colouring: a cap of " + std::to_string(colors) +
                                               " colours, outside [1, " + std::to_string(SINEW_COLOR_MAX_COLORS) + "]");
  if (rounds < 1 || rounds > SINEW_COLOR_MAX_ROUNDS)
    return Error(ErrorCode::bad_parameter, "contact colouring: " + std::to_string(rounds) + " rounds, outside [1, " +
                                               std::to_string(SINEW_COLOR_MAX_ROUNDS) + "]");
  for (std::size_t i = 0; i < particles.size(); ++i)
    if (particles[i] >= movable.size())
      return Error(ErrorCode::bad_parameter, "contact colouring: contact " + std::to_string(i / 4) + " names particle " +
                                                 std::to_string(particles[i]) + " of " +
                                                 std::to_string(movable.size()));
  // Round by round, as the kernels run it, but one contact at a time.
  CappedColoring out;
  out.color_of.assign(n, kUndecided);
  out.color_sizes.assign(colors + 1, 0);
  const std::uint32_t words = (colors + 31) / 32;
  std::vector<std::uint32_t> masks(movable.size() * words, 0);  // per particle: the colours its contacts hold
  std::vector<std::uint32_t> owner(movable.size());             // per particle: the highest undecided priority + 1
  std::vector<std::uint32_t> undecided(n);
  std::iota(undecided.begin(), undecided.end(), 0u);
  const auto taken = [&](const std::uint32_t* v, std::uint32_t k) {
    for (int q = 0; q < 4; ++q)
      if (movable[v[q]] && (masks[std::size_t{v[q]} * words + k / 32] >> (k % 32) & 1u) != 0) return true;
    return false;
  };
  for (std::uint32_t round = 0; round < rounds && !undecided.empty(); ++round) {
    out.rounds_needed = round + 1;
    // Contacts that find every colour taken join the overflow set now:
    // the masks only gain colours.
    std::erase_if(undecided, [&](std::uint32_t c) {
      const std::uint32_t* v = &particles[4 * std::size_t{c}];
      for (std::uint32_t k = 0; k < colors; ++k)
        if (!taken(v, k)) return false;
      out.color_of[c] = colors;
      ++out.color_sizes[colors];
      return true;
    });
    for (std::uint32_t c : undecided)
      for (int k = 0; k < 4; ++k) owner[particles[4 * std::size_t{c} + k]] = 0;
    for (std::uint32_t c : undecided)
      for (int k = 0; k < 4; ++k) {
        const std::uint32_t v = particles[4 * std::size_t{c} + k];
        if (movable[v]) owner[v] = std::max(owner[v], kernels::contact_color_priority(c) + 1);
      }
    // The contacts of highest priority on each of their movable particles
    // share none: their colours do not depend on one another.
    std::vector<std::uint32_t> next;
    std::vector<std::uint32_t> winners;
    for (std::uint32_t c : undecided) {
      bool holds = true;
      for (int k = 0; k < 4; ++k) {
        const std::uint32_t v = particles[4 * std::size_t{c} + k];
        holds = holds && (!movable[v] || owner[v] == kernels::contact_color_priority(c) + 1);
      }
      (holds ? winners : next).push_back(c);
    }
    for (std::uint32_t c : winners) {
      const std::uint32_t* v = &particles[4 * std::size_t{c}];
      std::uint32_t chosen = 0;
      while (chosen < colors && taken(v, chosen)) ++chosen;
      out.color_of[c] = chosen;
      ++out.color_sizes[chosen];
      if (chosen < colors)
        for (int q = 0; q < 4; ++q)
          if (movable[v[q]]) masks[std::size_t{v[q]} * words + chosen / 32] |= 1u << (chosen % 32);
    }
    undecided = std::move(next);
  }
  // Still undecided when the rounds ran out: the overflow set too.
  for (std::uint32_t c : undecided) {
    out.color_of[c] = colors;
    ++out.color_sizes[colors];
    ++out.out_of_rounds;
  }
  if (!undecided.empty()) out.rounds_needed = rounds + 1;
  return out;
}

bool capped_coloring_is_valid(const CappedColoring& coloring, std::span<const std::uint32_t> particles,
                              std::span<const std::uint8_t> movable, std::uint32_t colors) {
  const std::size_t n = particles.size() / 4;
  if (coloring.color_of.size() != n || coloring.color_sizes.size() != std::size_t{colors} + 1) return false;
  std::vector<std::uint32_t> sizes(colors + 1, 0);
  // Per movable particle, the last colour seen there (colours visited in order).
  std::vector<std::uint32_t> seen(movable.size(), UINT32_MAX);
  std::vector<std::uint32_t> by_color(n);
  std::iota(by_color.begin(), by_color.end(), 0u);
  for (std::uint32_t k : coloring.color_of)
    if (k > colors) return false;
  std::stable_sort(by_color.begin(), by_color.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return coloring.color_of[a] < coloring.color_of[b]; });
  for (std::uint32_t c : by_color) {
    const std::uint32_t k = coloring.color_of[c];
    ++sizes[k];
    if (k == colors) continue;
    for (int q = 0; q < 4; ++q) {
      const std::uint32_t p = particles[4 * std::size_t{c} + q];
      if (p >= movable.size()) return false;
      if (!movable[p]) continue;
      // A repeated particle within one contact is no conflict.
      bool repeat = false;
      for (int r = 0; r < q; ++r) repeat = repeat || particles[4 * std::size_t{c} + r] == p;
      if (repeat) continue;
      if (seen[p] == k) return false;
      seen[p] = k;
    }
  }
  return sizes == coloring.color_sizes;
}

}  // namespace sinew
