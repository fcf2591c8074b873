// rest_close_test.cpp — the pairs of a surface's triangles closer than the
// thickness in its starting shape (src/collision/rest_close.h): equal to a
// search over every pair, and skipped by the self traversal exactly as
// removing them from its pairs afterwards would (armadillo and kidney
// surfaces, a thickness of half an edge: many close pairs).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "collision/narrow_phase.h"
#include "collision/parallel_pairs.h"
#include "collision/rest_close.h"
#include "surface_support.h"

namespace sinew::collision {
namespace {

class RestClose : public ::testing::TestWithParam<std::string> {};

TEST_P(RestClose, PairsEqualASearchOverEveryPairAndTheSkipEqualsRemovingThemAfterwards) {
  const test::Surface s = test::surface_of(GetParam());
  ASSERT_FALSE(s.triangles.empty());
  const float thickness = 0.5f * s.mean_edge;
  std::vector<Pair> close;
  ASSERT_TRUE(rest_close_pairs(s.positions, s.triangles, thickness, close).ok());

  // Every pair that shares no vertex, by its distance.
  const auto n = static_cast<std::uint32_t>(s.triangles.size() / 3);
  const SharesVertex shares{s.triangles};
  std::vector<Aabb> boxes;
  ASSERT_TRUE(primitive_boxes(s.positions, s.triangles, 3, 0.0f, boxes).ok());
  std::vector<Pair> every;
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = i + 1; j < n; ++j) {
      // Boxes farther apart than the thickness along an axis cannot hold a
      // closer pair: only a shortcut for the test's time.
      bool far = false;
      for (int k = 0; k < 3; ++k)
        far = far || boxes[i].lo[k] > boxes[j].hi[k] + thickness || boxes[j].lo[k] > boxes[i].hi[k] + thickness;
      if (!far && !shares(i, j) &&
          triangle_distance(s.positions, &s.triangles[3 * std::size_t{i}], &s.triangles[3 * std::size_t{j}]) < thickness)
        every.push_back({i, j});
    }
  EXPECT_EQ(close, every);
  EXPECT_GT(close.size(), 100u) << "the test needs close pairs";

  // The set answers like the sorted list, at listed pairs and at others.
  const PairSet set(close, n);
  EXPECT_EQ(set.size(), close.size());
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::uint32_t> pick(0, n - 1);
  for (int q = 0; q < 20000; ++q) {
    std::uint32_t i = pick(rng), j = pick(rng);
    if (q % 2 == 0) std::tie(i, j) = close[std::size_t(q / 2) % close.size()];
    if (i == j) continue;
    if (i > j) std::swap(i, j);
    ASSERT_EQ(set.contains(i, j), std::binary_search(close.begin(), close.end(), Pair{i, j})) << i << " " << j;
  }

  // A frame's self pairs (boxes inflated by half the thickness, so every
  // listed pair is a candidate): skipping the listed pairs in the traversal
  // equals removing them from its result.
  ASSERT_TRUE(primitive_boxes(s.positions, s.triangles, 3, 0.5f * thickness, boxes).ok());
  Bvh tree;
  tree.build(boxes);
  std::vector<Pair> all, skipped;
  self_overlapping_pairs_parallel(tree, shares, all);
  self_overlapping_pairs_parallel(tree, SharesVertexOrListed<3>{shares, &set}, skipped);
  detail::sort_unique(all);
  detail::sort_unique(skipped);
  std::vector<Pair> removed;
  std::set_difference(all.begin(), all.end(), close.begin(), close.end(), std::back_inserter(removed));
  EXPECT_EQ(skipped, removed);
  EXPECT_EQ(all.size() - skipped.size(), close.size()) << "every listed pair was a candidate";
  std::printf("[ rest-close ] %s: %zu triangles, %zu pairs closer than half an edge, %zu of %zu candidates left\n",
              GetParam().c_str(), std::size_t{n}, close.size(), skipped.size(), all.size());
}

INSTANTIATE_TEST_SUITE_P(Surfaces, RestClose,
                         ::testing::Values("meshes/tet/armadillo_4k.node", "meshes/tet/kidney_57k.node"),
                         [](const ::testing::TestParamInfo<std::string>& param) { return param.index == 0 ? std::string("armadillo") : std::string("kidney"); });

TEST(RestClose, BadThicknessAndPositionsAreNamed) {
  const std::vector<float> x = {0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 2, 1, 0, 0};
  const std::vector<std::uint32_t> tris = {0, 1, 2, 3, 4, 5};
  std::vector<Pair> close;
  const Status zero = rest_close_pairs(x, tris, 0.0f, close);
  ASSERT_FALSE(zero.ok());
  EXPECT_NE(zero.error().message().find("thickness"), std::string::npos) << zero.error().message();
  std::vector<float> nan = x;
  nan[4 * 4 + 1] = NAN;
  const Status bad = rest_close_pairs(nan, tris, 0.5f, close);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("vertex 4"), std::string::npos) << bad.error().message();
  ASSERT_TRUE(rest_close_pairs(x, tris, 1.5f, close).ok());
  EXPECT_EQ(close, (std::vector<Pair>{{0, 1}})) << "1 apart: closer than 1.5";
  ASSERT_TRUE(rest_close_pairs(x, tris, 0.5f, close).ok());
  EXPECT_TRUE(close.empty()) << "1 apart: not closer than 0.5";
}

}  // namespace
}  // namespace sinew::collision
