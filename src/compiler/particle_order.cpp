// particle_order.cpp — reverse Cuthill-McKee order of particles and the
// constraint order within colours.
// See particle_order.h for why and the references.
#include "compiler/particle_order.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sinew {
bool ParticleOrder::identity() const {
  for (std::size_t p = 0; p < device_of.size(); ++p)
    if (device_of[p] != p) return false;
  return true;
}

ParticleOrder identity_order(std::uint32_t particles) {
  ParticleOrder order;
  order.device_of.resize(particles);
  std::iota(order.device_of.begin(), order.device_of.end(), 0u);
  order.user_of = order.device_of;
  return order;
}

ParticleOrder bandwidth_order(std::uint32_t particles, std::span<const ConstraintList> constraints,
                              std::vector<std::uint32_t> body_first) {
  const std::uint32_t n = particles;
  ParticleOrder order = identity_order(n);
  // Neighbour lists (CSR): every other particle of every constraint.
  std::vector<std::uint32_t> offsets(std::size_t{n} + 1, 0), neighbours;
  for (const ConstraintList& list : constraints)
    for (std::size_t c = 0; c + list.arity <= list.particles.size(); c += list.arity)
      for (std::uint32_t i = 0; i < list.arity; ++i) offsets[list.particles[c + i] + 1] += list.arity - 1;
  for (std::uint32_t p = 0; p < n; ++p) offsets[p + 1] += offsets[p];
  neighbours.resize(offsets[n]);
  std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
  for (const ConstraintList& list : constraints)
    for (std::size_t c = 0; c + list.arity <= list.particles.size(); c += list.arity)
      for (std::uint32_t i = 0; i < list.arity; ++i)
        for (std::uint32_t j = 0; j < list.arity; ++j)
          if (i != j) neighbours[fill[list.particles[c + i]]++] = list.particles[c + j];

  body_first.push_back(0);
  body_first.push_back(n);
  std::sort(body_first.begin(), body_first.end());
  body_first.erase(std::unique(body_first.begin(), body_first.end()), body_first.end());
  auto degree = [&](std::uint32_t p) { return offsets[p + 1] - offsets[p]; };
  std::vector<std::uint32_t> level(n, UINT32_MAX), queue;
  queue.reserve(n);
  // Breadth-first from `root` over unvisited particles of [first, last),
  // neighbours by increasing degree; appends to `queue`, returns the last
  // level's first entry (a candidate peripheral particle).
  auto walk = [&](std::uint32_t root, std::uint32_t first, std::uint32_t last, std::vector<std::uint32_t>& out) {
    std::size_t head = out.size();
    out.push_back(root);
    level[root] = 0;
    std::uint32_t last_level_start = root;
    std::vector<std::uint32_t> next;
    while (head < out.size()) {
      const std::uint32_t p = out[head++];
      next.clear();
      for (std::uint32_t j = offsets[p]; j < offsets[p + 1]; ++j) {
        const std::uint32_t q = neighbours[j];
        if (q < first || q >= last || level[q] != UINT32_MAX) continue;
        level[q] = level[p] + 1;
        next.push_back(q);
      }
      std::stable_sort(next.begin(), next.end(), [&](std::uint32_t a, std::uint32_t b) { return degree(a) < degree(b); });
      for (std::uint32_t q : next) {
        if (level[q] != level[out.back()]) last_level_start = q;
        out.push_back(q);
      }
    }
    return last_level_start;
  };
  std::vector<std::uint32_t> probe;
  for (std::size_t b = 0; b + 1 < body_first.size(); ++b) {
    const std::uint32_t first = body_first[b], last = body_first[b + 1];
    std::vector<std::uint32_t> body;
    for (std::uint32_t start = first; start < last; ++start) {
      if (level[start] != UINT32_MAX) continue;
      // A pseudo-peripheral root: the far end of a walk from `start`.
      probe.clear();
      const std::uint32_t far = walk(start, first, last, probe);
      for (std::uint32_t p : probe) level[p] = UINT32_MAX;
      walk(far, first, last, body);
    }
    std::reverse(body.begin(), body.end());
    std::copy(body.begin(), body.end(), order.user_of.begin() + first);
  }
  for (std::uint32_t slot = 0; slot < n; ++slot) order.device_of[order.user_of[slot]] = slot;
  return order;
}

std::vector<std::uint32_t> constraint_order(std::span<const std::uint32_t> particles, std::uint32_t arity,
                                            std::span<const std::uint32_t> color_of, bool by_first_particle) {
  const std::size_t n = color_of.size();
  std::vector<std::uint64_t> key(n);
  for (std::size_t c = 0; c < n; ++c) {
    const std::uint32_t first =
        by_first_particle ? *std::min_element(particles.begin() + c * arity, particles.begin() + (c + 1) * arity) : 0u;
    key[c] = std::uint64_t{color_of[c]} << 32 | first;
  }
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key[a] < key[b]; });
  return order;
}

}  // namespace sinew
