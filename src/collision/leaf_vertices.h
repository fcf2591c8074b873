// leaf_vertices.h — a tree's primitives renumbered in its leaf order, with
// their vertices' positions gathered to match: the per-frame passes over the
// leaves (the primitives' boxes for the refit, the normal cones) then read
// consecutive memory (issue 12, the self-collision goal).
//
// Why: meshers number vertices in the order their algorithm met them, so a
// leaf's three triangles name vertices thousands of slots apart, and a pass
// over the leaves reads three scattered vertices per triangle (the liver's
// boundary surface, 105,266 triangles: 316k scattered reads per pass,
// twice a frame with the cones). Gathering each vertex once, in the order
// the leaves first name it, leaves 53k scattered reads per frame; the
// passes after it walk the gathered copy nearly in order, because a leaf's
// neighbours in the tree are its neighbours in space. (The structure is
// the same as a mesh renumbered for locality, kept beside the tree: the
// tree's order is not the solver's, which is chosen for the constraints,
// particle_order.h.)
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "collision/bvh.h"
#include "sinew/result.h"

namespace sinew::collision {

class LeafVertices {
 public:
  /// Renumbers from `tree`, built over primitives of `arity` (1-3) corners
  /// each given by `indices` (vertex indices into the positions gather()
  /// will read), when the tree was rebuilt since the last call
  /// (Bvh::build_id); otherwise does nothing. Errors (bad_parameter): an
  /// arity outside 1-3, or indices that are not `arity` per primitive of
  /// the tree.
  Status index(const Bvh& tree, std::span<const std::uint32_t> indices, int arity);

  /// Copies the positions (xyzw per vertex) of the vertices the tree's
  /// primitives use into positions(), in local order. Errors: a vertex
  /// index past `positions`, or a non-finite position (naming the vertex
  /// in the caller's numbering).
  Status gather(std::span<const float> positions);
  /// Copies four floats per vertex of `values` (e.g. velocities, xyzw) the
  /// same way. [out] out: four per local vertex. `values` must hold every
  /// vertex gather() accepted.
  void gather(std::span<const float> values, std::vector<float>& out) const;

  /// The primitives' boxes in leaf order (slot k: primitive
  /// tree.order()[k]) from positions(), each grown by `inflate` [m] on
  /// every side: what Bvh::refit_leaves takes. No checks beyond gather()'s.
  /// [out] boxes.
  void boxes(float inflate, std::vector<Aabb>& boxes) const;

  /// Per leaf slot k (primitive tree.order()[k]), its `arity` corners as
  /// local vertex indices.
  [[nodiscard]] std::span<const std::uint32_t> corners() const { return corners_; }
  /// The gathered positions, xyzw per local vertex.
  [[nodiscard]] std::span<const float> positions() const { return positions_; }
  /// Local vertex -> the caller's vertex index.
  [[nodiscard]] std::span<const std::uint32_t> vertices() const { return vertices_; }
  /// The build_id of the tree last indexed (0: none yet).
  [[nodiscard]] std::uint64_t build_id() const { return build_id_; }

 private:
  std::uint64_t build_id_ = 0;
  int arity_ = 3;
  std::vector<std::uint32_t> corners_, vertices_;
  std::vector<float> positions_;
};

}  // namespace sinew::collision
