// bvh.cpp — the CPU reference BVH (see bvh.h).
#include "collision/bvh.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <iterator>
#include <string>
#include <utility>

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

namespace {

// A float's bits mapped so that unsigned order is the floats' order (-0
// taken as +0, so that equal floats get equal keys; no NaN here: the boxes
// are finite).
std::uint32_t sortable(float x) {
  x += 0.0f;
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return (bits & 0x80000000u) != 0 ? ~bits : bits | 0x80000000u;
}

// [out] order: 0 .. keys.size() - 1 sorted by (keys[i], i): a stable least
// significant digit radix sort, 11 bits a pass.
void sort_by_key(const std::vector<std::uint32_t>& keys, std::vector<std::uint32_t>& order,
                 std::vector<std::uint32_t>& scratch) {
  constexpr int kDigit = 11;
  constexpr std::uint32_t kMask = (1u << kDigit) - 1;
  const std::size_t n = keys.size();
  order.resize(n);
  scratch.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
  std::uint32_t count[1u << kDigit];
  for (int shift = 0; shift < 32; shift += kDigit) {
    std::fill(std::begin(count), std::end(count), 0u);
    for (std::size_t i = 0; i < n; ++i) ++count[(keys[i] >> shift) & kMask];
    std::uint32_t sum = 0;
    for (std::uint32_t& c : count) sum += std::exchange(c, sum);
    for (std::size_t i = 0; i < n; ++i) scratch[count[(keys[order[i]] >> shift) & kMask]++] = order[i];
    order.swap(scratch);
  }
}

}  // namespace

// Per axis, the primitives of every node under construction sorted by
// (centroid along the axis, index): node [first, first + count) holds the
// same primitives in all three lists.
struct Bvh::Presorted {
  std::vector<float> centroids;                // xyz per primitive
  std::array<std::vector<std::uint32_t>, 3> by_axis;
  std::vector<std::uint8_t> right;             // per primitive: in the right child of the node being split
  std::vector<std::uint32_t> scratch;
};

void Bvh::build(std::span<const Aabb> boxes) {
  static std::atomic<std::uint64_t> builds{0};
  build_id_ = ++builds;
  nodes_.clear();
  order_.resize(boxes.size());
  for (std::uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  built_cost_ = 0.0;
  if (boxes.empty()) return;
  const std::size_t n = boxes.size();
  Presorted sorted;
  sorted.centroids.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) sorted.centroids[3 * i + std::size_t(k)] = 0.5f * (boxes[i].lo[k] + boxes[i].hi[k]);
  std::vector<std::uint32_t> keys(n);
  for (int k = 0; k < 3; ++k) {
    for (std::size_t i = 0; i < n; ++i) keys[i] = sortable(sorted.centroids[3 * i + std::size_t(k)]);
    sort_by_key(keys, sorted.by_axis[std::size_t(k)], sorted.scratch);
  }
  sorted.right.assign(n, 0);
  nodes_.reserve(2 * (n / kLeafSize + 1));
  nodes_.emplace_back();
  build_node(sorted, 0, 0, static_cast<std::uint32_t>(n));
  // Each leaf's primitives, in order along x; the nodes' boxes bottom-up.
  order_.swap(sorted.by_axis[0]);
  leaf_boxes_.resize(n);
  for (std::size_t k = 0; k < n; ++k) leaf_boxes_[k] = boxes[order_[k]];
  refit_nodes();
  built_cost_ = cost();
}

// Fills node `index` over the slots [first, first + count) of the sorted
// lists. Children are pushed after their parent, so refit() may walk the
// nodes backwards. The split: the lower half along the longest axis of the
// centroids' bounds (the first such axis), ties in the centroid broken by
// the lower index: the same nodes as a selection of the median (e.g.
// std::nth_element) by that order would make.
void Bvh::build_node(Presorted& sorted, std::uint32_t index, std::uint32_t first, std::uint32_t count) {
  if (count <= kLeafSize) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return;
  }
  const auto centroid = [&](int k, std::uint32_t slot) {
    return sorted.centroids[3 * std::size_t{sorted.by_axis[std::size_t(k)][slot]} + std::size_t(k)];
  };
  int axis = 0;
  float extent[3];
  for (int k = 0; k < 3; ++k) extent[k] = centroid(k, first + count - 1) - centroid(k, first);
  for (int k = 1; k < 3; ++k)
    if (extent[k] > extent[axis]) axis = k;
  const std::uint32_t half = count / 2;
  const std::vector<std::uint32_t>& along = sorted.by_axis[std::size_t(axis)];
  for (std::uint32_t s = first; s < first + count; ++s) sorted.right[along[s]] = s >= first + half;
  // The other two lists split stably: each half stays sorted.
  for (int k = 0; k < 3; ++k) {
    if (k == axis) continue;
    std::uint32_t* list = sorted.by_axis[std::size_t(k)].data() + first;
    std::uint32_t* spill = sorted.scratch.data();
    std::uint32_t left = 0, right = 0;
    for (std::uint32_t s = 0; s < count; ++s) {
      const std::uint32_t p = list[s];
      if (sorted.right[p]) spill[right++] = p;
      else list[left++] = p;
    }
    std::copy(spill, spill + right, list + left);
  }
  const auto left = static_cast<std::uint32_t>(nodes_.size());
  nodes_[index].left = left;
  nodes_[index].count = 0;
  nodes_.emplace_back();
  nodes_.emplace_back();
  build_node(sorted, left, first, half);
  build_node(sorted, left + 1, first + half, count - half);
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
