// bvh_test.cpp — the CPU reference broad phase (src/collision/bvh.h):
// candidate pairs from the BVH equal the brute-force O(n^2) set for the same
// inflated boxes, within one surface (self-collision, skipping triangles
// that share a vertex) and between two, on random boxes with degenerate
// cases and on the boundary surfaces of the real meshes (armadillo_4k,
// kidney_57k, liver_382k), before and after the vertices move and the tree
// is refitted; bad input is an error naming the primitive.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <random>
#include <vector>

#include "collision/bvh.h"
#include "collision/parallel_pairs.h"
#if SINEW_HAS_EMBREE
#include "collision/embree_broad_phase.h"
#endif
#include "surface_support.h"

namespace sinew::collision {
namespace {

using test::Surface;
using test::surface_of;

std::vector<Aabb> boxes_of(const Surface& s, float inflate) {
  std::vector<Aabb> boxes;
  const Status status = primitive_boxes(s.positions, s.triangles, 3, inflate, boxes);
  EXPECT_TRUE(status.ok()) << (status.ok() ? "" : status.error().message());
  return boxes;
}

#if SINEW_HAS_EMBREE
std::unique_ptr<EmbreeBoxes> embree_set() {
  auto made = EmbreeBoxes::create();
  EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.error().message());
  return made.ok() ? std::move(*made) : nullptr;
}
#endif

// Moves every vertex by up to `amount` [m] per axis (a deformation: the
// refitted tree must still find exactly the brute-force pairs).
void jiggle(Surface& s, float amount, std::mt19937& rng) {
  std::uniform_real_distribution<float> d(-amount, amount);
  for (std::size_t v = 0; v < s.positions.size() / 4; ++v)
    for (int k = 0; k < 3; ++k) s.positions[4 * v + std::size_t(k)] += d(rng);
}

void expect_self_pairs_equal_brute_force(const Surface& s, float inflate, const char* what) {
  const std::vector<Aabb> boxes = boxes_of(s, inflate);
  Bvh tree;
  tree.build(boxes);
  const SharesVertex skip{s.triangles};
  std::vector<Pair> fast, slow;
  self_overlapping_pairs(tree, skip, fast);
  brute_force_self_pairs(boxes, skip, slow);
  EXPECT_EQ(fast, slow) << what << ": " << fast.size() << " BVH pairs, " << slow.size() << " brute force";
  std::vector<Pair> parallel;
  self_overlapping_pairs_parallel(tree, skip, parallel);
  std::sort(parallel.begin(), parallel.end());
  EXPECT_EQ(parallel, slow) << what << ": the parallel query";
#if SINEW_HAS_EMBREE
  auto set = embree_set();
  ASSERT_TRUE(set);
  ASSERT_TRUE(set->build(boxes).ok());
  std::vector<Pair> embree;
  ASSERT_TRUE(embree_self_pairs(*set, skip, embree).ok());
  EXPECT_EQ(embree, slow) << what << ": " << embree.size() << " Embree pairs, " << slow.size() << " brute force";
#endif
  EXPECT_GT(slow.size(), 0u) << what << ": the inflation should make some non-adjacent triangles candidates";
  std::printf("[ bvh ] %s: %zu triangles, %zu self pairs, %zu nodes\n", what, boxes.size(), slow.size(),
              tree.nodes().size());
}

// Pairs across two box sets from their BVHs and from the brute force.
std::pair<std::vector<Pair>, std::vector<Pair>> cross_pairs(const std::vector<Aabb>& a, const std::vector<Aabb>& b) {
  Bvh ta, tb;
  ta.build(a);
  tb.build(b);
  std::vector<Pair> fast, slow;
  overlapping_pairs(ta, tb, fast);
  brute_force_pairs(a, b, slow);
  return {fast, slow};
}

TEST(Bvh, SelfPairsOnRealSurfacesEqualBruteForce) {
  for (const char* file : {"meshes/tet/armadillo_4k.node", "meshes/tet/kidney_57k.node"}) {
    const Surface s = surface_of(file);
    ASSERT_FALSE(s.triangles.empty());
    expect_self_pairs_equal_brute_force(s, 0.5f * s.mean_edge, file);
  }
}

// The liver's boundary: the largest surface of the three (the
// brute force tests ~1e9 box pairs, a few seconds).
TEST(Bvh, SelfPairsOnTheLiverEqualBruteForce) {
  const Surface s = surface_of("meshes/tet/liver_382k.node");
  ASSERT_FALSE(s.triangles.empty());
  expect_self_pairs_equal_brute_force(s, 0.25f * s.mean_edge, "meshes/tet/liver_382k.node");
}

TEST(Bvh, RefitAfterDeformationStillEqualsBruteForce) {
  std::mt19937 rng(7);
  Surface s = surface_of("meshes/tet/kidney_57k.node");
  ASSERT_FALSE(s.triangles.empty());
  const float inflate = 0.25f * s.mean_edge;
  std::vector<Aabb> boxes = boxes_of(s, inflate);
  Bvh tree;
  tree.build(boxes);
#if SINEW_HAS_EMBREE
  auto set = embree_set();
  ASSERT_TRUE(set);
  ASSERT_TRUE(set->build(boxes).ok());
#endif
  const SharesVertex skip{s.triangles};
  for (int step = 0; step < 3; ++step) {
    jiggle(s, 0.5f * s.mean_edge, rng);
    boxes = boxes_of(s, inflate);
    tree.refit(boxes);
    std::vector<Pair> fast, slow;
    self_overlapping_pairs(tree, skip, fast);
    brute_force_self_pairs(boxes, skip, slow);
    EXPECT_EQ(fast, slow) << "after deformation " << step;
#if SINEW_HAS_EMBREE
    ASSERT_TRUE(set->refit(boxes).ok());
    std::vector<Pair> embree;
    ASSERT_TRUE(embree_self_pairs(*set, skip, embree).ok());
    EXPECT_EQ(embree, slow) << "Embree refitted, after deformation " << step;
#endif
    EXPECT_GT(tree.degradation(), 1.0) << "jiggled boxes swell: the refitted tree's cost grows";
  }
  // The root bounds every box after the refit.
  const Aabb& root = tree.nodes()[0].box;
  for (const Aabb& b : boxes)
    for (int k = 0; k < 3; ++k) {
      ASSERT_LE(root.lo[k], b.lo[k]);
      ASSERT_GE(root.hi[k], b.hi[k]);
    }
}

// update() refits while the tree stays good and rebuilds when refitting
// has let it degrade: the armadillo surface bent a little keeps its tree;
// the same surface with its vertices shuffled (every triangle now spans the
// body) rebuilds, and the pairs stay those of the brute force.
TEST(Bvh, UpdateRebuildsOnlyWhenTheTreeDegrades) {
  std::mt19937 rng(29);
  Surface s = surface_of("meshes/tet/armadillo_4k.node");
  ASSERT_FALSE(s.triangles.empty());
  const float inflate = 0.1f * s.mean_edge;
  std::vector<Aabb> boxes = boxes_of(s, inflate);
  Bvh tree;
  tree.build(boxes);
  jiggle(s, 0.1f * s.mean_edge, rng);
  boxes = boxes_of(s, inflate);
  EXPECT_FALSE(tree.update(boxes)) << "a small deformation: refit only (degradation " << tree.degradation() << ")";
  // Shuffle the vertices' positions: the surface's triangles become long
  // slivers across the organ, the old tree's boxes overlap everywhere.
  std::vector<std::size_t> perm(s.positions.size() / 4);
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  std::vector<float> shuffled(s.positions.size());
  for (std::size_t v = 0; v < perm.size(); ++v)
    for (int k = 0; k < 4; ++k) shuffled[4 * v + std::size_t(k)] = s.positions[4 * perm[v] + std::size_t(k)];
  s.positions = shuffled;
  boxes = boxes_of(s, inflate);
  Bvh refitted = tree;
  refitted.refit(boxes);
  EXPECT_GT(refitted.degradation(), 2.0);
  EXPECT_TRUE(tree.update(boxes)) << "a scrambled surface: rebuilt";
  EXPECT_LE(tree.degradation(), 1.0 + 1e-12);
  std::vector<Pair> a, b, c;
  const SharesVertex skip{s.triangles};
  self_overlapping_pairs(tree, skip, a);
  self_overlapping_pairs(refitted, skip, b);
  brute_force_self_pairs(boxes, skip, c);
  EXPECT_EQ(a, c);
  EXPECT_EQ(b, c) << "a degraded tree is slow, never wrong";
  EXPECT_GE(tree.cost(), 1.0);
}

TEST(Bvh, PairsBetweenTwoSurfacesEqualBruteForce) {
  // The armadillo's surface pushed into the kidney's (both scaled to about
  // the same size): many crossing candidates.
  Surface kidney = surface_of("meshes/tet/kidney_57k.node");
  Surface armadillo = surface_of("meshes/tet/armadillo_4k.node");
  ASSERT_FALSE(kidney.triangles.empty());
  ASSERT_FALSE(armadillo.triangles.empty());
  auto bounds = [](const Surface& s) {
    Aabb b{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (std::size_t v = 0; v < s.positions.size() / 4; ++v)
      for (int k = 0; k < 3; ++k) {
        b.lo[k] = std::min(b.lo[k], s.positions[4 * v + std::size_t(k)]);
        b.hi[k] = std::max(b.hi[k], s.positions[4 * v + std::size_t(k)]);
      }
    return b;
  };
  const Aabb kb = bounds(kidney), ab = bounds(armadillo);
  const float scale = 0.6f * (kb.hi[0] - kb.lo[0]) / (ab.hi[0] - ab.lo[0]);
  for (std::size_t v = 0; v < armadillo.positions.size() / 4; ++v)
    for (int k = 0; k < 3; ++k) {
      float& x = armadillo.positions[4 * v + std::size_t(k)];
      x = (x - 0.5f * (ab.lo[k] + ab.hi[k])) * scale + 0.5f * (kb.lo[k] + kb.hi[k]) + (k == 0 ? 0.3f : 0.0f) * (kb.hi[0] - kb.lo[0]);
    }
  const float inflate = 0.5f * kidney.mean_edge;
  const std::vector<Aabb> a = boxes_of(kidney, inflate), b = boxes_of(armadillo, inflate);
  const auto [fast, slow] = cross_pairs(a, b);
  EXPECT_EQ(fast, slow);
#if SINEW_HAS_EMBREE
  auto ea = embree_set(), eb = embree_set();
  ASSERT_TRUE(ea && eb);
  ASSERT_TRUE(ea->build(a).ok());
  ASSERT_TRUE(eb->build(b).ok());
  std::vector<Pair> embree;
  ASSERT_TRUE(embree_pairs(*ea, *eb, embree).ok());
  EXPECT_EQ(embree, slow) << "Embree";
  // A refit with a different count is an error naming what to do.
  const Status wrong = ea->refit(b);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().message().find("build again"), std::string::npos);
#endif
  EXPECT_GT(slow.size(), 100u) << "the surfaces should cross";
  std::printf("[ bvh ] kidney x armadillo: %zu x %zu triangles, %zu pairs\n", a.size(), b.size(), slow.size());
}

TEST(Bvh, RandomAndDegenerateBoxesEqualBruteForce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int round = 0; round < 20; ++round) {
    const int n = 1 + int(rng() % 700), m = 1 + int(rng() % 300);
    auto make = [&](int count) {
      std::vector<Aabb> boxes(static_cast<std::size_t>(count));
      for (auto& b : boxes) {
        const int kind = int(rng() % 5);
        for (int k = 0; k < 3; ++k) {
          const float c = kind == 0 ? 0.5f : u(rng);  // kind 0: all at one point
          const float h = kind == 1 ? 0.0f : 0.05f * u(rng);  // kind 1: zero-size boxes
          b.lo[k] = c - h;
          b.hi[k] = c + h;
        }
        if (kind == 2 && count > 1) b = boxes[0];  // duplicates of the first box
      }
      return boxes;
    };
    const std::vector<Aabb> a = make(n), b = make(m);
    auto [fast, slow] = cross_pairs(a, b);
    ASSERT_EQ(fast, slow) << "round " << round << ", " << n << " x " << m;
    Bvh ta;
    ta.build(a);
    const auto none = [](std::uint32_t, std::uint32_t) { return false; };
    self_overlapping_pairs(ta, none, fast);
    brute_force_self_pairs(a, none, slow);
    ASSERT_EQ(fast, slow) << "self, round " << round << ", " << n << " boxes";
    std::vector<Pair> parallel;
    self_overlapping_pairs_parallel(ta, none, parallel);
    std::sort(parallel.begin(), parallel.end());
    ASSERT_EQ(parallel, slow) << "parallel self, round " << round;
#if SINEW_HAS_EMBREE
    auto ea = embree_set(), eb = embree_set();
    ASSERT_TRUE(ea && eb);
    ASSERT_TRUE(ea->build(a).ok());
    ASSERT_TRUE(eb->build(b).ok());
    std::vector<Pair> embree;
    ASSERT_TRUE(embree_self_pairs(*ea, none, embree).ok());
    ASSERT_EQ(embree, slow) << "Embree self, round " << round;
    ASSERT_TRUE(embree_pairs(*ea, *eb, embree).ok());
    brute_force_pairs(a, b, slow);
    ASSERT_EQ(embree, slow) << "Embree, round " << round;
#endif
  }
  // Empty sets: no pairs, no crash.
  Bvh empty;
  empty.build({});
  std::vector<Pair> pairs{{1, 2}};
  overlapping_pairs(empty, empty, pairs);
  EXPECT_TRUE(pairs.empty());
}

TEST(Bvh, BadInputIsAnErrorNamingThePrimitive) {
  std::vector<float> x = {0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  std::vector<std::uint32_t> tris = {0, 1, 2, 1, 2, 3};
  std::vector<Aabb> boxes;
  EXPECT_TRUE(primitive_boxes(x, tris, 3, 0.01f, boxes).ok());
  x[4 * 3 + 1] = NAN;
  const Status nan = primitive_boxes(x, tris, 3, 0.01f, boxes);
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().message().find("primitive 1"), std::string::npos) << nan.error().message();
  EXPECT_NE(nan.error().message().find("non-finite"), std::string::npos) << nan.error().message();
  x[4 * 3 + 1] = 0.0f;
  tris.back() = 9;
  const Status index = primitive_boxes(x, tris, 3, 0.01f, boxes);
  ASSERT_FALSE(index.ok());
  EXPECT_NE(index.error().message().find("vertex 9"), std::string::npos) << index.error().message();
  tris.back() = 3;
  EXPECT_FALSE(primitive_boxes(x, tris, 3, -1.0f, boxes).ok());
  EXPECT_FALSE(primitive_boxes(x, tris, 3, NAN, boxes).ok());
  EXPECT_FALSE(primitive_boxes(x, tris, 4, 0.0f, boxes).ok());
  tris.pop_back();
  EXPECT_FALSE(primitive_boxes(x, tris, 3, 0.0f, boxes).ok());
}

}  // namespace
}  // namespace sinew::collision
