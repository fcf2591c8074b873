// topology_queries.h — which tets a topology change takes, found at the
// body's current positions: the tets a swept blade touches (cut), the tets
// stretched past a strain (tear), and the tets a heated tip has touched
// long enough (cautery). Each returns indices into the mesh's tets, among
// the live ones, in ascending order; topology_editor.h removes them.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/scene.h"

namespace sinew {

using Point3 = std::array<double, 3>;

/// A tet's six edges, as pairs of its corners.
inline constexpr int kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

/// The current position of the body's vertex v: xyzw in the user's
/// particle order (Simulation::read_positions), the body's vertex 0 at `first`.
struct BodyPositions {
  std::span<const float> xyzw;
  std::uint32_t first = 0;
  [[nodiscard]] Point3 at(std::uint32_t v) const {
    const float* p = &xyzw[4 * (std::size_t{first} + v)];
    return {p[0], p[1], p[2]};
  }
};

/// Whether triangle abc and tet (p0, p1, p2, p3) share a point: no
/// separating axis among the triangle's normal, the tet's four face
/// normals and the 18 cross products of their edges (the separating axis
/// test for convex polyhedra: C. Ericson, "Real-Time Collision Detection",
/// 2005, section 5.2.1). Touching counts as sharing.
bool triangle_touches_tet(const std::array<Point3, 3>& tri, const std::array<Point3, 4>& tet);

/// The live tets that the quad a0, b0, b1, a1 (a blade's segment a-b swept
/// from pose 0 to pose 1, as two triangles) touches.
std::vector<std::uint32_t> tets_cut(const TetMesh& mesh, std::span<const std::uint8_t> alive, const BodyPositions& x,
                                    const Point3& a0, const Point3& b0, const Point3& a1, const Point3& b1);

/// The live tets with an edge longer than (1 + strain) times its rest length.
std::vector<std::uint32_t> tets_torn(const TetMesh& mesh, std::span<const std::uint8_t> alive, const BodyPositions& x,
                                     double strain);

/// The whole segments of a line body stretched past (1 + strain) times
/// their rest length (its vertices at `x`).
std::vector<std::uint32_t> segments_torn(const LineBodyDesc& line, std::span<const std::uint8_t> whole,
                                         const BodyPositions& x, double strain);

/// Adds `seconds` to heat[t] of every live tet whose centroid is within
/// `radius` of `centre`, and returns those whose heat reached `dwell`.
std::vector<std::uint32_t> tets_burned(const TetMesh& mesh, std::span<const std::uint8_t> alive,
                                       const BodyPositions& x, const Point3& centre, double radius, double seconds,
                                       double dwell, std::vector<double>& heat);

}  // namespace sinew
