// rest_close.h — the pairs of one surface's triangles that are already
// closer than the contact thickness in the starting shape, and the self
// traversal's skip test that leaves them out (issue 12, self-collision).
//
// Why: a tet mesh's boundary has places where two triangles that share no
// vertex lie closer than the thickness at rest (across a sliver, in a
// crease; the liver's surface has 683 facing vertex-triangle contacts under
// 1 mm in its starting shape). Contacts between them would push the
// surface apart at the first frame. Such pairs are never in contact
// (MeshCollisionDesc::thickness, SceneInfo::rest_close_triangle_pairs), so
// the traversal skips them with the pairs that share a vertex, on its own
// threads, instead of searching a list for every candidate afterwards.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "collision/bvh.h"
#include "sinew/result.h"

namespace sinew::collision {

/// The pairs (i < j, sorted) of triangles of `triangles` (three vertex
/// indices each into `positions`, xyzw per vertex) that share no vertex
/// and are closer than `thickness` [m] (triangle_distance). [out] pairs.
/// Errors: a non-finite position, a bad vertex index, a bad thickness.
Status rest_close_pairs(std::span<const float> positions, std::span<const std::uint32_t> triangles, float thickness,
                        std::vector<Pair>& pairs);

/// A set of primitive pairs, stored by first primitive (compressed rows),
/// so that a lookup reads one short run.
class PairSet {
 public:
  PairSet() = default;
  /// [in] sorted: pairs with i < j, sorted by i (rest_close_pairs'
  /// output); primitives: more than any index. A pair out of order or out
  /// of range is a programming error (asserted).
  PairSet(std::span<const Pair> sorted, std::uint32_t primitives);
  /// Whether (i, j) is in the set; i < j.
  [[nodiscard]] bool contains(std::uint32_t i, std::uint32_t j) const {
    if (std::size_t{i} + 1 >= first_.size()) return false;
    for (std::uint32_t k = first_[i]; k < first_[i + 1]; ++k)
      if (second_[k] == j) return true;
    return false;
  }
  /// The pairs, sorted by first primitive (each row in the order given).
  [[nodiscard]] std::vector<Pair> pairs() const {
    std::vector<Pair> out;
    out.reserve(second_.size());
    for (std::size_t i = 0; i + 1 < first_.size(); ++i)
      for (std::uint32_t k = first_[i]; k < first_[i + 1]; ++k) out.push_back({static_cast<std::uint32_t>(i), second_[k]});
    return out;
  }
  [[nodiscard]] std::size_t size() const { return second_.size(); }
  [[nodiscard]] bool empty() const { return second_.empty(); }

 private:
  std::vector<std::uint32_t> first_, second_;
};

/// The self traversal's skip test: primitives that share a vertex, or
/// whose pair is listed (the rest-close pairs; none when `listed` is null).
/// Called with i < j.
template <int Arity>
struct SharesVertexOrListed {
  SharesVertexOf<Arity> shares;
  const PairSet* listed = nullptr;
  bool operator()(std::uint32_t i, std::uint32_t j) const {
    return shares(i, j) || (listed != nullptr && listed->contains(i, j));
  }
};

}  // namespace sinew::collision
