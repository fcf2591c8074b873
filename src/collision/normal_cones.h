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
// Assumptions, stated rather than checked: the outline test of the papers
// is replaced by two cheaper conditions, (1) the patch is one
// connected (through shared vertices) piece (checked: a BVH node holding two layers of a rolled
// membrane, whose normals point the same way, is never culled) and (2) it
// is not a ramp that winds over itself (a helicoid with a gentle pitch,
// which a connected patch of tissue forms only when cut along a slit and
// twisted). Scenes that may form such ramps turn the culling off
// (MeshCollisionDesc::self_culling).
//
// Motion: the solver passes the positions at the frame's start and where
// the frame's velocities take them (`later`); a node is flat only if both
// sets of normals fit in its cone, so a patch that starts to fold within
// the frame is traversed.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "collision/bvh.h"

namespace sinew::collision {

class NormalCones {
 public:
  /// The half-angle below which a connected patch counts as flat [degrees].
  static constexpr float kFlatDegrees = 30.0f;

  /// Recomputes every node's cone of `tree` (built over the triangles
  /// `triangles`, three vertex indices per primitive, into `positions`,
  /// xyzw per vertex) and whether it is flat. `later` (same layout as
  /// positions, or empty) adds the normals at a second configuration. The
  /// node's connectivity is recomputed when the tree was rebuilt since the
  /// last call (Bvh::build_id), from the triangles' shared edges. A zero-area
  /// triangle has no normal: the nodes above it are never flat.
  void update(const Bvh& tree, std::span<const std::uint32_t> triangles, std::span<const float> positions,
              std::span<const float> later = {});

  /// Per node of the tree: 1 where its triangles cannot touch themselves.
  [[nodiscard]] std::span<const std::uint8_t> flat() const { return flat_; }
  /// The culling policy of the self traversal (bvh.h, NoCulling): node n
  /// is flat.
  [[nodiscard]] bool self(std::uint32_t n) const { return flat_[n] != 0; }
  /// Nodes a and b (disjoint) cannot touch each other: each is connected,
  /// they share a vertex (so their union is connected) and one cone of
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
  std::uint64_t build_id_ = 0;
  std::vector<std::uint8_t> flat_, connected_;
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
