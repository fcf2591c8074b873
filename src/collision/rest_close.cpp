// rest_close.cpp — triangles closer than the thickness in the starting
// shape, and their set (see rest_close.h).
#include "collision/rest_close.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "collision/narrow_phase.h"
#include "collision/parallel_pairs.h"

namespace sinew::collision {

Status rest_close_pairs(std::span<const float> positions, std::span<const std::uint32_t> triangles, float thickness,
                        std::vector<Pair>& pairs) {
  pairs.clear();
  if (!(thickness > 0.0f) || !std::isfinite(thickness))
    return Error(ErrorCode::bad_parameter,
                 "the collision thickness must be finite and > 0 [m] (got " + std::to_string(thickness) + ")");
  // Boxes inflated by half the thickness overlap for every pair closer
  // than it; primitive_boxes checks the indices and positions.
  std::vector<Aabb> boxes;
  if (Status s = primitive_boxes(positions, triangles, 3, 0.5f * thickness, boxes); !s) return s;
  Bvh tree;
  tree.build(boxes);
  std::vector<Pair> candidates;
  self_overlapping_pairs_parallel(tree, SharesVertex{triangles}, candidates);
  for (const auto& [i, j] : candidates)
    if (triangle_distance(positions, &triangles[3 * std::size_t{i}], &triangles[3 * std::size_t{j}]) < thickness)
      pairs.push_back({i, j});
  std::sort(pairs.begin(), pairs.end());
  return {};
}

PairSet::PairSet(std::span<const Pair> sorted, std::uint32_t primitives) : first_(std::size_t{primitives} + 1, 0) {
  second_.reserve(sorted.size());
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    const auto [i, j] = sorted[k];
    assert(i < j && j < primitives && (k == 0 || sorted[k - 1].first <= i));
    ++first_[std::size_t{i} + 1];
    second_.push_back(j);
  }
  for (std::size_t k = 1; k < first_.size(); ++k) first_[k] += first_[k - 1];
}

}  // namespace sinew::collision
