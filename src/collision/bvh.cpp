// bvh.cpp — the CPU reference BVH (see bvh.h).
#include "collision/bvh.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

namespace sinew::collision {

Status primitive_boxes(std::span<const float> positions, std::span<const std::uint32_t> indices, int arity,
                       float inflate, std::vector<Aabb>& boxes) {
  if (arity < 1 || arity > 3)
    return Error(ErrorCode::bad_parameter, "primitive arity must be 1, 2 or 3 (got " + std::to_string(arity) + ")");
  if (!(inflate >= 0.0f) || !std::isfinite(inflate))
    return Error(ErrorCode::bad_parameter, "the contact distance (box inflation) must be finite and >= 0 (got " +
                                               std::to_string(inflate) + ")");
  if (indices.size() % std::size_t(arity) != 0)
    return Error(ErrorCode::bad_parameter, "primitive indices: " + std::to_string(indices.size()) +
                                               " is not a multiple of the arity " + std::to_string(arity));
  const std::size_t vertices = positions.size() / 4;
  const std::size_t count = indices.size() / std::size_t(arity);
  boxes.resize(count);
  for (std::size_t p = 0; p < count; ++p) {
    Aabb box{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (int c = 0; c < arity; ++c) {
      const std::uint32_t v = indices[p * std::size_t(arity) + std::size_t(c)];
      if (v >= vertices)
        return Error(ErrorCode::bad_parameter, "primitive " + std::to_string(p) + " names vertex " +
                                                   std::to_string(v) + " of " + std::to_string(vertices));
      for (int k = 0; k < 3; ++k) {
        const float x = positions[4 * std::size_t{v} + std::size_t(k)];
        if (!std::isfinite(x))
          return Error(ErrorCode::bad_parameter, "primitive " + std::to_string(p) + ": vertex " + std::to_string(v) +
                                                     " has a non-finite position");
        box.lo[k] = std::min(box.lo[k], x);
        box.hi[k] = std::max(box.hi[k], x);
      }
    }
    for (int k = 0; k < 3; ++k) box.lo[k] -= inflate, box.hi[k] += inflate;
    boxes[p] = box;
  }
  return {};
}

void Bvh::build(std::span<const Aabb> boxes) {
  static std::atomic<std::uint64_t> builds{0};
  build_id_ = ++builds;
  nodes_.clear();
  order_.resize(boxes.size());
  for (std::uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  built_cost_ = 0.0;
  if (boxes.empty()) return;
  std::vector<float> centroids(3 * boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (int k = 0; k < 3; ++k) centroids[3 * i + std::size_t(k)] = 0.5f * (boxes[i].lo[k] + boxes[i].hi[k]);
  nodes_.reserve(2 * (boxes.size() / kLeafSize + 1));
  nodes_.emplace_back();
  build_node(boxes, centroids, 0, 0, static_cast<std::uint32_t>(boxes.size()));
  leaf_boxes_.resize(boxes.size());
  for (std::size_t k = 0; k < boxes.size(); ++k) leaf_boxes_[k] = boxes[order_[k]];
  built_cost_ = cost();
}

// Fills node `index` over order_[first, first + count). Children are pushed
// after their parent, so refit() may walk the nodes backwards.
void Bvh::build_node(std::span<const Aabb> boxes, const std::vector<float>& centroids, std::uint32_t index,
                     std::uint32_t first, std::uint32_t count) {
  Aabb box = boxes[order_[first]];
  float clo[3], chi[3];
  for (int k = 0; k < 3; ++k) clo[k] = chi[k] = centroids[3 * std::size_t{order_[first]} + std::size_t(k)];
  for (std::uint32_t s = first + 1; s < first + count; ++s) {
    box = merge(box, boxes[order_[s]]);
    for (int k = 0; k < 3; ++k) {
      const float c = centroids[3 * std::size_t{order_[s]} + std::size_t(k)];
      clo[k] = std::min(clo[k], c);
      chi[k] = std::max(chi[k], c);
    }
  }
  nodes_[index].box = box;
  if (count <= kLeafSize) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
  const std::uint32_t half = count / 2;
  auto* begin = order_.data() + first;
  std::nth_element(begin, begin + half, begin + count, [&](std::uint32_t a, std::uint32_t b) {
    const float ca = centroids[3 * std::size_t{a} + std::size_t(axis)];
    const float cb = centroids[3 * std::size_t{b} + std::size_t(axis)];
    return ca < cb || (ca == cb && a < b);  // a strict order even among equal centroids
  });
  const auto left = static_cast<std::uint32_t>(nodes_.size());
  nodes_[index].left = left;
  nodes_[index].count = 0;
  nodes_.emplace_back();
  nodes_.emplace_back();
  build_node(boxes, centroids, left, first, half);
  build_node(boxes, centroids, left + 1, first + half, count - half);
}

void Bvh::refit(std::span<const Aabb> boxes) {
  for (std::size_t k = 0; k < leaf_boxes_.size(); ++k) leaf_boxes_[k] = boxes[order_[k]];
  refit_nodes();
}

Status Bvh::refit_leaves(std::vector<Aabb>& leaf_boxes) {
  if (leaf_boxes.size() != leaf_boxes_.size())
    return Error(ErrorCode::bad_parameter, "refit_leaves: " + std::to_string(leaf_boxes.size()) +
                                               " boxes for a tree over " + std::to_string(leaf_boxes_.size()) +
                                               " primitives");
  leaf_boxes_.swap(leaf_boxes);
  refit_nodes();
  return {};
}

void Bvh::rebuild() {
  std::vector<Aabb> boxes(leaf_boxes_.size());
  for (std::size_t k = 0; k < boxes.size(); ++k) boxes[order_[k]] = leaf_boxes_[k];
  build(boxes);
}

void Bvh::refit_nodes() {
  for (std::size_t n = nodes_.size(); n-- > 0;) {
    Node& node = nodes_[n];
    if (node.count > 0) {
      Aabb box = leaf_boxes_[node.first];
      for (std::uint32_t s = 1; s < node.count; ++s) box = merge(box, leaf_boxes_[node.first + s]);
      node.box = box;
    } else {
      node.box = merge(nodes_[node.left].box, nodes_[node.left + 1].box);
    }
  }
}

double Bvh::cost() const {
  if (nodes_.empty()) return 0.0;
  double sum = 0.0;
  for (const Node& n : nodes_) sum += double(half_area(n.box));
  const double root = double(half_area(nodes_[0].box));
  return root > 0.0 ? sum / root : double(nodes_.size());
}

bool Bvh::update(std::span<const Aabb> boxes, double max_degradation) {
  refit(boxes);
  if (degradation() <= max_degradation) return false;
  build(boxes);
  return true;
}

double Bvh::degradation() const { return built_cost_ > 0.0 ? cost() / built_cost_ : 1.0; }

namespace detail {
void sort_unique(std::vector<Pair>& pairs) {
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
}
}  // namespace detail

void overlapping_pairs(const Bvh& a, const Bvh& b, std::vector<Pair>& pairs) {
  pairs.clear();
  detail::traverse(a, b, false, [&](const Bvh::Node& x, const Bvh::Node& y) {
    for (std::uint32_t s = 0; s < x.count; ++s)
      for (std::uint32_t t = 0; t < y.count; ++t)
        if (overlap(a.leaf_boxes()[x.first + s], b.leaf_boxes()[y.first + t]))
          pairs.push_back({a.order()[x.first + s], b.order()[y.first + t]});
  });
  detail::sort_unique(pairs);
}

void brute_force_pairs(std::span<const Aabb> boxes_a, std::span<const Aabb> boxes_b, std::vector<Pair>& pairs) {
  pairs.clear();
  for (std::uint32_t i = 0; i < boxes_a.size(); ++i)
    for (std::uint32_t j = 0; j < boxes_b.size(); ++j)
      if (overlap(boxes_a[i], boxes_b[j])) pairs.push_back({i, j});
}

}  // namespace sinew::collision
