// leaf_vertices.cpp — a tree's primitives renumbered in leaf order (see
// leaf_vertices.h).
#include "collision/leaf_vertices.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace sinew::collision {

Status LeafVertices::index(const Bvh& tree, std::span<const std::uint32_t> indices, int arity) {
  if (build_id_ == tree.build_id() && build_id_ != 0) return {};
  if (arity < 1 || arity > 3 || indices.size() != tree.order().size() * std::size_t(arity))
    return Error(ErrorCode::bad_parameter, "leaf vertices: " + std::to_string(indices.size()) + " indices of arity " +
                                               std::to_string(arity) + " for a tree over " +
                                               std::to_string(tree.order().size()) + " primitives");
  build_id_ = tree.build_id();
  arity_ = arity;
  const auto& order = tree.order();
  std::uint32_t largest = 0;
  for (const std::uint32_t v : indices) largest = std::max(largest, v);
  std::vector<std::uint32_t> local(indices.empty() ? 0 : std::size_t{largest} + 1, UINT32_MAX);
  vertices_.clear();
  corners_.resize(indices.size());
  for (std::size_t slot = 0; slot < order.size(); ++slot)
    for (int c = 0; c < arity; ++c) {
      const std::uint32_t v = indices[std::size_t{order[slot]} * std::size_t(arity) + std::size_t(c)];
      if (local[v] == UINT32_MAX) {
        local[v] = static_cast<std::uint32_t>(vertices_.size());
        vertices_.push_back(v);
      }
      corners_[slot * std::size_t(arity) + std::size_t(c)] = local[v];
    }
  positions_.assign(4 * vertices_.size(), 0.0f);
  return {};
}

Status LeafVertices::gather(std::span<const float> positions) {
  const std::size_t available = positions.size() / 4;
  for (std::size_t k = 0; k < vertices_.size(); ++k) {
    const std::size_t v = vertices_[k];
    if (v >= available)
      return Error(ErrorCode::bad_parameter, "a primitive names vertex " + std::to_string(v) + " of " +
                                                 std::to_string(available));
    const float* from = &positions[4 * v];
    float* to = &positions_[4 * k];
    to[0] = from[0], to[1] = from[1], to[2] = from[2], to[3] = from[3];
    // x - x is 0 for a finite x and NaN otherwise: one test per vertex.
    if (!(from[0] - from[0] + from[1] - from[1] + from[2] - from[2] == 0.0f))
      return Error(ErrorCode::bad_parameter, "vertex " + std::to_string(v) + " has a non-finite position");
  }
  return {};
}

void LeafVertices::boxes(float inflate, std::vector<Aabb>& boxes) const {
  const std::size_t arity = static_cast<std::size_t>(arity_);
  boxes.resize(corners_.size() / arity);
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    const float* x = &positions_[4 * std::size_t{corners_[arity * k]}];
    Aabb box{{x[0], x[1], x[2]}, {x[0], x[1], x[2]}};
    for (std::size_t c = 1; c < arity; ++c) {
      x = &positions_[4 * std::size_t{corners_[arity * k + c]}];
      for (int a = 0; a < 3; ++a) box.lo[a] = std::min(box.lo[a], x[a]), box.hi[a] = std::max(box.hi[a], x[a]);
    }
    for (int a = 0; a < 3; ++a) box.lo[a] -= inflate, box.hi[a] += inflate;
    boxes[k] = box;
  }
}

void LeafVertices::gather(std::span<const float> values, std::vector<float>& out) const {
  out.resize(4 * vertices_.size());
  for (std::size_t k = 0; k < vertices_.size(); ++k)
    for (int a = 0; a < 4; ++a) out[4 * k + std::size_t(a)] = values[4 * std::size_t{vertices_[k]} + std::size_t(a)];
}

}  // namespace sinew::collision
