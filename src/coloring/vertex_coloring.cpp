// vertex_coloring.cpp — first-fit greedy colouring of a tet mesh's vertices
// (vertex_coloring.h): a vertex takes the smallest colour none of the
// already coloured vertices of its tets has.
#include "coloring/vertex_coloring.h"

#include <vector>

namespace sinew {

Coloring color_tet_vertices(std::span<const std::uint32_t> tets, std::span<const std::uint32_t> vertices,
                            std::uint32_t particle_count) {
  constexpr std::uint32_t kNone = UINT32_MAX;
  // Per particle: its entry in `vertices` (kNone: not coloured), and its tets (CSR).
  std::vector<std::uint32_t> entry(particle_count, kNone);
  for (std::uint32_t e = 0; e < vertices.size(); ++e) entry[vertices[e]] = e;
  std::vector<std::uint32_t> first(std::size_t{particle_count} + 1, 0);
  for (std::uint32_t q : tets) ++first[q + 1];
  for (std::size_t i = 0; i < particle_count; ++i) first[i + 1] += first[i];
  std::vector<std::uint32_t> fill(first.begin(), first.end() - 1), tet_of(tets.size());
  for (std::size_t k = 0; k < tets.size(); ++k) tet_of[fill[tets[k]]++] = static_cast<std::uint32_t>(k / 4);

  Coloring out;
  out.color_of.assign(vertices.size(), kNone);
  std::vector<std::uint32_t> taken;  // taken[c] == e: colour c is used by a neighbour of entry e
  for (std::uint32_t e = 0; e < vertices.size(); ++e) {
    const std::uint32_t v = vertices[e];
    for (std::uint32_t k = first[v]; k < first[v + 1]; ++k)
      for (int c = 0; c < 4; ++c) {
        const std::uint32_t n = entry[tets[std::size_t{tet_of[k]} * 4 + c]];
        if (n != kNone && n != e && out.color_of[n] != kNone) taken[out.color_of[n]] = e;
      }
    std::uint32_t color = 0;
    while (color < taken.size() && taken[color] == e) ++color;
    if (color == taken.size()) {
      taken.push_back(kNone);
      out.color_sizes.push_back(0);
    }
    out.color_of[e] = color;
    ++out.color_sizes[color];
  }
  return out;
}

}  // namespace sinew
