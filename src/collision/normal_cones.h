// normal_cones.h — self-collision culling by normal cones (issue 12, the
// self-collision goal): the parts of a surface that are too flat to touch
// themselves are never traversed against themselves.
//
// Volino and Magnenat-Thalmann, "Efficient self-collision detection on
// smoothly discretized surface animations using geometrical shape
// regularity", Computer Graphics Forum 13(3), 1994; Provot, "Collision and
// self-collision handling in cloth model dedicated to design garments",
// Graphics Interface 1997. A patch of surface whose triangle normals all lie
// within a cone of half-angle theta < 90 degrees around one axis, and whose
// outline projected along that axis does not overlap itself, is the graph
// of a function over the plane across the axis with slope <= tan theta:
// it cannot pass through itself.
//
// What sinew relies on, and why it is enough for its contacts: the solver
// keeps only *facing* contacts (a vertex-triangle contact whose normal is
// within kFacingDegrees of the triangle's normal; mesh_collision.cpp). In a
// graph patch whose normals lie within theta of the axis, the segment
// between any two surface points makes an angle >= 90 - theta with the axis
// (the slope bound along the straight path between their projections),
// while a facing contact's segment makes an angle <= theta + 25.8 degrees.
// With theta <= kFlatDegrees = 30 the two cannot both hold: no facing
// vertex-triangle contact joins two triangles of a flat patch, at any
// distance. Edge-edge contacts inside a flat patch can exist (two nearly
// parallel edges side by side, pushed apart across the surface, not through
// it): those are dropped with the patch (measured in tests/normal_cones_test.cpp).
//
// Assumptions: the papers' outline test (the patch's border, projected
// along the axis, does not overlap itself) is replaced by three cheaper
// conditions, two checked and one assumed. Checked: (1) the patch is one
// piece connected through shared vertices (a BVH node holding two layers of
// a rolled membrane, whose normals point the same way, is never culled) and
// (2) it has no open edge, an edge of one triangle only (a slit whose lips
// shear apart along the axis is flat and connected around the slit's end,
// yet its lips can face each other: found in review, tested in
// tests/normal_cones_test.cpp; a membrane's own border is open too, so the
// nodes along it are always traversed). Assumed: (3) the patch is not a
// ramp that winds over itself (a helicoid of gentle pitch), which a
// connected patch without open edges forms only when the tissue around it
// does. Scenes that may form such ramps turn the culling off
// (MeshCollisionDesc::self_culling).
//
// Contacts are found at the frame's start only (mesh_collision.h), and the
// argument above is about that configuration: the cones are computed from
// the same positions.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "collision/bvh.h"
#include "collision/leaf_vertices.h"

namespace sinew::collision {

class NormalCones {
 public:
  /// The half-angle below which a connected patch counts as flat [degrees].
  static constexpr float kFlatDegrees = 30.0f;

  /// Recomputes every node's cone of `tree` (built over the triangles
  /// `triangles`, three vertex indices per primitive, into `positions`,
  /// xyzw per vertex) and whether it is flat. The nodes' connectivity and
  /// open edges are recomputed when the tree was rebuilt since the last
  /// call (Bvh::build_id), from the triangles' shared vertices and edges. A
  /// zero-area triangle has no normal: the nodes above it are never flat.
  void update(const Bvh& tree, std::span<const std::uint32_t> triangles, std::span<const float> positions);
  /// The same from the positions `leaf` gathered (indexed from `tree` and
  /// `triangles`, leaf_vertices.h): the leaves' normals read nearly
  /// consecutive memory. A `leaf` indexed from another build of the tree
  /// leaves no node flat (nothing culled) rather than cones of stale data.
  void update(const Bvh& tree, std::span<const std::uint32_t> triangles, const LeafVertices& leaf);

  /// Per node of the tree: 1 where its triangles cannot touch themselves.
  [[nodiscard]] std::span<const std::uint8_t> flat() const { return flat_; }
  /// The culling policy of the self traversal (bvh.h, NoCulling): node n
  /// is flat.
  [[nodiscard]] bool self(std::uint32_t n) const { return flat_[n] != 0; }
  /// Nodes a and b (disjoint) cannot touch each other: each is connected
  /// and without open edges, they share a vertex (so their union is
  /// connected) and one cone of
  /// half-angle kFlatDegrees holds both their cones. What cuts the seams:
  /// two flat patches side by side under a curved parent.
  [[nodiscard]] bool pair(std::uint32_t a, std::uint32_t b) const;
  /// Per node: its triangles form one connected (through shared vertices) patch.
  [[nodiscard]] std::span<const std::uint8_t> connected() const { return connected_; }
  /// Per node: the cone's axis (unit) and the cosine of its half-angle,
  /// holding every normal of the node's triangles; where that cone is wider
  /// than kFlatDegrees (or a triangle has no normal) it is not tracked
  /// further: axis 0 and cos -1.
  struct Cone {
    float axis[3];
    float cos;
  };
  [[nodiscard]] std::span<const Cone> cones() const { return cones_; }

 private:
  void connect(const Bvh& tree, std::span<const std::uint32_t> triangles);
  // The cones from the triangles' corners in leaf order (3 per slot) into `positions` (xyzw).
  void refresh(const Bvh& tree, std::span<const std::uint32_t> corners, std::span<const float> positions);
  std::uint64_t build_id_ = 0;
  std::vector<std::uint8_t> flat_, connected_, open_;  // open_: a triangle of the node has an open edge
  std::vector<Cone> cones_;
  std::vector<float> sum_, sin_;  // per node: the unnormalised sum of its unit normals (xyz); sin of the half-angle
  float flat_cos_ = 0.0f;
  std::vector<std::uint32_t> leaves_;  // the tree's leaf nodes
  // The triangles' corners in leaf order (slot k: triangle order()[k]): the
  // leaves read them from consecutive memory (the gather through order()
  // took a third longer on the liver's surface).
  std::vector<std::uint32_t> corners_;
  // Per node, CSR: its boundary vertices (those it shares with triangles
  // outside it), sorted. Two disjoint nodes share a vertex only on both
  // their boundaries.
  std::vector<std::uint32_t> boundary_first_, boundary_;
};

}  // namespace sinew::collision
