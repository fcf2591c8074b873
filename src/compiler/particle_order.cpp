// particle_order.cpp — Morton order of particles and constraint sorting.
// See particle_order.h for why and the references.
#include "compiler/particle_order.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sinew {
namespace {

// Spreads the low 21 bits of v so that bit i lands on bit 3i.
std::uint64_t spread3(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

}  // namespace

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

ParticleOrder morton_order(std::span<const kernels::float4> positions, std::vector<std::uint32_t> body_first) {
  const auto n = static_cast<std::uint32_t>(positions.size());
  ParticleOrder order = identity_order(n);
  body_first.push_back(0);
  body_first.push_back(n);
  std::sort(body_first.begin(), body_first.end());
  body_first.erase(std::unique(body_first.begin(), body_first.end()), body_first.end());
  std::vector<std::uint64_t> key(n);
  for (std::size_t b = 0; b + 1 < body_first.size(); ++b) {
    const std::uint32_t first = body_first[b], last = body_first[b + 1];
    if (last - first < 2) continue;
    float lo[3] = {positions[first].x, positions[first].y, positions[first].z}, hi[3] = {lo[0], lo[1], lo[2]};
    for (std::uint32_t p = first; p < last; ++p) {
      const float c[3] = {positions[p].x, positions[p].y, positions[p].z};
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], c[k]);
        hi[k] = std::max(hi[k], c[k]);
      }
    }
    // One scale for all three axes (the largest extent), so that the cells
    // of the curve are cubes and a flat body does not get stretched ones.
    const double extent = std::max({double(hi[0]) - lo[0], double(hi[1]) - lo[1], double(hi[2]) - lo[2]});
    const double scale = extent > 0.0 ? double((1u << 21) - 1) / extent : 0.0;
    for (std::uint32_t p = first; p < last; ++p) {
      const float c[3] = {positions[p].x, positions[p].y, positions[p].z};
      std::uint64_t code = 0;
      for (int k = 0; k < 3; ++k)
        code |= spread3(static_cast<std::uint64_t>(std::floor((double(c[k]) - lo[k]) * scale))) << k;
      key[p] = code;
    }
    std::stable_sort(order.user_of.begin() + first, order.user_of.begin() + last,
                     [&](std::uint32_t u, std::uint32_t v) { return key[u] < key[v]; });
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
