// embree_broad_phase.h — the fast CPU broad phase (issue 12): Embree 3's
// BVH over the same inflated primitive boxes as the reference
// (collision/bvh.h), pairs from rtcCollide. Embree reports candidate pairs
// of primitives whose leaves may overlap; every candidate is re-tested here
// with the reference's exact box test (and skip rule), so the pair sets are
// equal to the brute force's, not approximately (tests/bvh_test.cpp).
// Built only with SINEW_EMBREE (the libembree-dev package).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "collision/bvh.h"

namespace sinew::collision {

/// One set of primitive boxes as an Embree scene (user geometry whose
/// bounds are the boxes). The boxes are read through the span given to
/// build()/refit(), which must stay valid until the next call.
class EmbreeBoxes {
 public:
  /// An empty set; errors if Embree cannot make a device.
  static Result<std::unique_ptr<EmbreeBoxes>> create();
  ~EmbreeBoxes();
  EmbreeBoxes(const EmbreeBoxes&) = delete;
  EmbreeBoxes& operator=(const EmbreeBoxes&) = delete;

  /// Builds Embree's BVH over `boxes` from scratch.
  Status build(std::span<const Aabb> boxes);
  /// The same primitives moved: Embree refits its BVH (same count as at build).
  Status refit(std::span<const Aabb> boxes);

  [[nodiscard]] std::span<const Aabb> boxes() const { return boxes_; }

 private:
  friend Status embree_pairs(const EmbreeBoxes&, const EmbreeBoxes&, std::vector<Pair>&);
  template <class Skip>
  friend Status embree_self_pairs(const EmbreeBoxes&, Skip, std::vector<Pair>&);
  EmbreeBoxes() = default;
  Status commit(bool rebuild);
  // Every candidate (i, j) of the two scenes (i from a, j from b), unsorted.
  static Status collide(const EmbreeBoxes& a, const EmbreeBoxes& b, std::vector<Pair>& candidates);

  struct Handles;
  std::unique_ptr<Handles> handles_;
  std::span<const Aabb> boxes_;
};

/// Every (i, j) with a.boxes()[i] overlapping b.boxes()[j]. [out] pairs, sorted.
Status embree_pairs(const EmbreeBoxes& a, const EmbreeBoxes& b, std::vector<Pair>& pairs);

/// Every (i, j), i < j, of one set with overlapping boxes and !skip(i, j).
/// [out] pairs, sorted.
template <class Skip>
Status embree_self_pairs(const EmbreeBoxes& set, Skip skip, std::vector<Pair>& pairs) {
  std::vector<Pair> candidates;
  if (Status s = EmbreeBoxes::collide(set, set, candidates); !s) return s;
  pairs.clear();
  const auto boxes = set.boxes();
  for (auto [i, j] : candidates) {
    if (i == j) continue;
    if (i > j) std::swap(i, j);
    if (overlap(boxes[i], boxes[j]) && !skip(i, j)) pairs.push_back({i, j});
  }
  detail::sort_unique(pairs);
  return {};
}

}  // namespace sinew::collision
