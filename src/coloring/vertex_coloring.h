// vertex_coloring.h — colours the vertices of a tet mesh so that no two
// vertices of one colour share a tet: the colours of Vertex Block Descent
// (Chen, Liu, Yang, Yuksel, SIGGRAPH 2024), whose per-vertex steps are then
// independent within a colour (one parallel dispatch each).
//
// Why not greedy_coloring.h: that colours constraints of a fixed arity by
// the particles they share; here the items are vertices and two conflict
// through a shared tet, a graph of varying degree.
#pragma once

#include <cstdint>
#include <span>

#include "coloring/greedy_coloring.h"

namespace sinew {

/// Colours `vertices` (particle indices, each < particle_count, no
/// repeats) so that two of them in one tet of `tets` (4 particle indices
/// per tet) never share a colour. Particles not listed are not coloured
/// and conflict with nothing (pinned particles, never written).
/// Deterministic: first fit in the order given. Coloring::color_of is
/// indexed like `vertices`.
Coloring color_tet_vertices(std::span<const std::uint32_t> tets, std::span<const std::uint32_t> vertices,
                            std::uint32_t particle_count);

}  // namespace sinew
