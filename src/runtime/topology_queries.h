// topology_queries.h — which elements a topology change takes, found at the
// body's current positions: the tets or triangles a swept blade touches
// (cut), those stretched past a strain (tear), and those a heated tip has
// touched long enough (cautery). Each returns indices into the body's
// elements, among the live ones, in ascending order; topology_editor.h
// removes them.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/scene.h"

namespace sinew {

using Point3 = std::array<double, 3>;

/// A tet's six edges and a triangle's three, as pairs of their corners.
inline constexpr int kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
inline constexpr int kTriangleEdges[3][2] = {{0, 1}, {1, 2}, {0, 2}};
/// The edges of an element of `arity` corners (4: a tet, 3: a triangle).
inline std::span<const int[2]> element_edges(std::uint32_t arity) {
  if (arity == 4) return kTetEdges;
  return kTriangleEdges;
}

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

/// A body's elements as the queries see them: its rest vertices [m], its
/// elements' corners (`arity` each: 4 for a tet body, 3 for a tri body),
/// which of them are alive, and (for elements_torn) each vertex's elements
/// (compressed rows: vertex v's are around[around_first[v] ..
/// around_first[v + 1]]).
struct ElementView {
  std::span<const Vec3d> rest;
  std::span<const std::uint32_t> corners;
  std::uint32_t arity = 4;
  std::span<const std::uint8_t> alive;
  std::span<const std::uint32_t> around_first, around;
  [[nodiscard]] std::size_t size() const { return alive.size(); }
  [[nodiscard]] const std::uint32_t* of(std::size_t e) const { return &corners[e * arity]; }
};

/// Whether triangle abc and a convex element (a tet's 4 corners, or a
/// triangle's 3) share a point: no separating axis among the faces'
/// normals, the cross products of their edges and, for the flat ones,
/// each edge crossed with its own face's normal (which separates two
/// triangles in one plane). The separating axis test for convex
/// polyhedra: C. Ericson, "Real-Time Collision Detection", 2005, section
/// 5.2.1. Touching counts as sharing.
bool triangle_touches_element(const std::array<Point3, 3>& tri, std::span<const Point3> element);

/// The live elements that the quad a0, b0, b1, a1 (a blade's segment a-b
/// swept from pose 0 to pose 1, as two triangles) touches.
std::vector<std::uint32_t> elements_cut(const ElementView& body, const BodyPositions& x, const Point3& a0,
                                        const Point3& b0, const Point3& a1, const Point3& b1);

/// A body's edges, each once (vertex pairs, lower first), with their rest
/// lengths squared [m^2]: what elements_torn measures.
struct EdgeList {
  std::vector<std::array<std::uint32_t, 2>> edges;
  std::vector<double> rest2;
};
EdgeList unique_edges(const ElementView& body);

/// The live elements with an edge longer than (1 + strain) times its rest
/// length, in ascending order. Each edge is measured once (a tet mesh's
/// edge is in about five tets, so this reads a fifth of what a pass over
/// the tets would), then the live elements around a stretched one are
/// listed. [in] edges: unique_edges(body).
std::vector<std::uint32_t> elements_torn(const ElementView& body, const EdgeList& edges, const BodyPositions& x,
                                         double strain);

/// The whole segments of a line body stretched past (1 + strain) times
/// their rest length (its vertices at `x`).
std::vector<std::uint32_t> segments_torn(const LineBodyDesc& line, std::span<const std::uint8_t> whole,
                                         const BodyPositions& x, double strain);

/// Adds `seconds` to heat[e] of every live element whose centroid is
/// within `radius` of `centre`, and returns those whose heat reached `dwell`.
std::vector<std::uint32_t> elements_burned(const ElementView& body, const BodyPositions& x, const Point3& centre,
                                           double radius, double seconds, double dwell, std::vector<double>& heat);

}  // namespace sinew
