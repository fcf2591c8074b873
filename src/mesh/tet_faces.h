// tet_faces.h — a tet's four faces wound outward, shared by the boundary
// extraction (boundary_surface.cpp), the mesh collision's and the topology
// editor's boundaries kept through cuts.
#pragma once

#include <array>

namespace sinew {

/// For a positively oriented tet (a, b, c, d), its faces as corner indices
/// with normals pointing away from the fourth vertex: (a,c,b), (a,b,d),
/// (a,d,c), (b,c,d). Face f is opposite corner 3 - f.
inline constexpr std::array<std::array<int, 3>, 4> kOutwardFaces{{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};

}  // namespace sinew
