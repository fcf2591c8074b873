// leaf_vertices_test.cpp — a tree's primitives renumbered in leaf order
// (collision/leaf_vertices.h): the boxes computed from the gathered
// vertices are bitwise the boxes of the primitives' own order, permuted; a
// tree refitted from them equals one refitted the usual way; the normal
// cones from them equal the cones from the positions; bad input is named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "collision/bvh.h"
#include "collision/leaf_vertices.h"
#include "collision/normal_cones.h"
#include "surface_support.h"

namespace sinew::collision {
namespace {

using test::Surface;
using test::surface_of;

bool same_box(const Aabb& a, const Aabb& b) { return std::memcmp(&a, &b, sizeof(Aabb)) == 0; }

// The surface moved by a smooth field: every vertex somewhere else.
std::vector<float> moved(const Surface& s, float amount) {
  std::vector<float> x = s.positions;
  for (std::size_t v = 0; v < x.size(); v += 4) {
    x[v] += amount * std::sin(0.37f * x[v + 1]);
    x[v + 1] += amount * std::sin(0.23f * x[v + 2]);
    x[v + 2] += amount * std::sin(0.31f * x[v]);
  }
  return x;
}

// Arity 3 (the surface's triangles) and 2 (their first edges, as segments).
class LeafVerticesArity : public testing::TestWithParam<int> {};

TEST_P(LeafVerticesArity, BoxesAndRefitEqualThePrimitivesOrderOnTheKidney) {
  const int arity = GetParam();
  const Surface s = surface_of("meshes/tet/kidney_57k.node");
  ASSERT_FALSE(s.triangles.empty());
  std::vector<std::uint32_t> indices;
  for (std::size_t t = 0; t < s.triangles.size(); t += 3)
    indices.insert(indices.end(), s.triangles.begin() + std::ptrdiff_t(t), s.triangles.begin() + std::ptrdiff_t(t) + arity);
  const float inflate = 0.1f * s.mean_edge;
  std::vector<Aabb> boxes;
  ASSERT_TRUE(primitive_boxes(s.positions, indices, arity, inflate, boxes).ok());
  Bvh reference, leafwise;
  reference.build(boxes);
  leafwise.build(boxes);

  LeafVertices leaf;
  ASSERT_TRUE(leaf.index(leafwise, indices, arity).ok());
  EXPECT_EQ(leaf.build_id(), leafwise.build_id());
  EXPECT_EQ(leaf.corners().size(), indices.size());
  // Every vertex the primitives use, once.
  std::vector<int> seen(s.positions.size() / 4, 0);
  for (const std::uint32_t v : leaf.vertices()) ++seen[v];
  for (const std::uint32_t v : indices) EXPECT_EQ(seen[v], 1) << "vertex " << v;

  const std::vector<float> x = moved(s, 2.0f * s.mean_edge);
  ASSERT_TRUE(primitive_boxes(x, indices, arity, inflate, boxes).ok());
  reference.refit(boxes);
  ASSERT_TRUE(leaf.gather(x).ok());
  std::vector<Aabb> leaf_boxes;
  leaf.boxes(inflate, leaf_boxes);
  ASSERT_EQ(leaf_boxes.size(), boxes.size());
  std::size_t differ = 0;
  for (std::size_t k = 0; k < leaf_boxes.size(); ++k) differ += !same_box(leaf_boxes[k], boxes[leafwise.order()[k]]);
  EXPECT_EQ(differ, 0u) << "leaf-order boxes that are not the primitive's own box";

  ASSERT_TRUE(leafwise.refit_leaves(leaf_boxes).ok());
  ASSERT_EQ(leafwise.nodes().size(), reference.nodes().size());
  differ = 0;
  for (std::size_t n = 0; n < reference.nodes().size(); ++n)
    differ += !same_box(reference.nodes()[n].box, leafwise.nodes()[n].box);
  EXPECT_EQ(differ, 0u) << "nodes whose refitted box differs";
  EXPECT_EQ(leafwise.degradation(), reference.degradation());

  // Rebuilt from its own leaf boxes: the tree a build over the boxes gives.
  const std::uint64_t before = leafwise.build_id();
  leafwise.rebuild();
  reference.build(boxes);
  EXPECT_NE(leafwise.build_id(), before);
  EXPECT_EQ(leafwise.order(), reference.order());
  differ = 0;
  for (std::size_t n = 0; n < reference.nodes().size(); ++n)
    differ += !same_box(reference.nodes()[n].box, leafwise.nodes()[n].box);
  EXPECT_EQ(differ, 0u);
  // A new shape is indexed anew.
  ASSERT_TRUE(leaf.index(leafwise, indices, arity).ok());
  EXPECT_EQ(leaf.build_id(), leafwise.build_id());
  ASSERT_TRUE(leaf.gather(x).ok());
  leaf.boxes(inflate, leaf_boxes);
  for (std::size_t k = 0; k < leaf_boxes.size(); ++k)
    ASSERT_TRUE(same_box(leaf_boxes[k], boxes[leafwise.order()[k]])) << "slot " << k << " after the rebuild";
}

INSTANTIATE_TEST_SUITE_P(TrianglesAndSegments, LeafVerticesArity, testing::Values(3, 2));

TEST(LeafVertices, ConesFromTheGatheredVerticesEqualConesFromThePositions) {
  const Surface s = surface_of("meshes/tet/kidney_57k.node");
  ASSERT_FALSE(s.triangles.empty());
  std::vector<Aabb> boxes;
  ASSERT_TRUE(primitive_boxes(s.positions, s.triangles, 3, 0.1f * s.mean_edge, boxes).ok());
  Bvh tree;
  tree.build(boxes);
  const std::vector<float> x = moved(s, 2.0f * s.mean_edge);
  NormalCones direct, gathered;
  direct.update(tree, s.triangles, x);
  LeafVertices leaf;
  ASSERT_TRUE(leaf.index(tree, s.triangles, 3).ok());
  ASSERT_TRUE(leaf.gather(x).ok());
  gathered.update(tree, s.triangles, leaf);
  std::size_t flat = 0, differ = 0;
  for (std::uint32_t n = 0; n < tree.nodes().size(); ++n) {
    flat += direct.flat()[n];
    const auto& a = direct.cones()[n];
    const auto& b = gathered.cones()[n];
    differ += direct.flat()[n] != gathered.flat()[n] || std::memcmp(&a, &b, sizeof(a)) != 0;
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(flat, tree.nodes().size() / 2) << "a smoothly moved organ is mostly flat patches";
}

TEST(LeafVertices, ANonFinitePositionOrAMissingVertexIsNamed) {
  const std::vector<std::uint32_t> triangles = {0, 1, 2, 1, 3, 2};
  std::vector<float> x = {0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0, 0};
  std::vector<Aabb> boxes;
  ASSERT_TRUE(primitive_boxes(x, triangles, 3, 0.0f, boxes).ok());
  Bvh tree;
  tree.build(boxes);
  LeafVertices leaf;
  ASSERT_TRUE(leaf.index(tree, triangles, 3).ok());
  ASSERT_TRUE(leaf.gather(x).ok());
  for (const float bad : {NAN, INFINITY, -INFINITY}) {
    std::vector<float> y = x;
    y[4 * 3 + 1] = bad;
    const Status s = leaf.gather(y);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message().find("vertex 3 has a non-finite position"), std::string::npos)
        << s.error().message();
  }
  const Status short_positions = leaf.gather(std::span<const float>(x).first(12));
  ASSERT_FALSE(short_positions.ok());
  EXPECT_NE(short_positions.error().message().find("names vertex 3 of 3"), std::string::npos)
      << short_positions.error().message();
}

// Mismatched inputs are errors, and cones from vertices gathered for an
// older shape of the tree cull nothing.
TEST(LeafVertices, MismatchesAreErrorsAndStaleVerticesCullNothing) {
  const Surface s = surface_of("meshes/tet/armadillo_4k.node");
  ASSERT_FALSE(s.triangles.empty());
  std::vector<Aabb> boxes;
  ASSERT_TRUE(primitive_boxes(s.positions, s.triangles, 3, 0.1f * s.mean_edge, boxes).ok());
  Bvh tree;
  tree.build(boxes);
  LeafVertices leaf;
  EXPECT_FALSE(leaf.index(tree, s.triangles, 2).ok()) << "triangles read as segments";
  EXPECT_FALSE(leaf.index(tree, std::span<const std::uint32_t>(s.triangles).first(30), 3).ok());
  EXPECT_FALSE(leaf.index(tree, s.triangles, 4).ok());
  std::vector<Aabb> fewer(boxes.begin(), boxes.end() - 1);
  const Status refit = tree.refit_leaves(fewer);
  ASSERT_FALSE(refit.ok());
  EXPECT_NE(refit.error().message().find("boxes for a tree over"), std::string::npos) << refit.error().message();
  EXPECT_EQ(fewer.size(), boxes.size() - 1) << "nothing swapped";

  ASSERT_TRUE(leaf.index(tree, s.triangles, 3).ok());
  ASSERT_TRUE(leaf.gather(s.positions).ok());
  NormalCones cones;
  cones.update(tree, s.triangles, leaf);
  std::size_t flat = 0;
  for (const std::uint8_t f : cones.flat()) flat += f;
  EXPECT_GT(flat, 0u);
  tree.build(boxes);  // a new shape; leaf still holds the old one's order
  cones.update(tree, s.triangles, leaf);
  flat = 0;
  for (const std::uint8_t f : cones.flat()) flat += f;
  EXPECT_EQ(flat, 0u) << "stale vertices must not cull";
}

}  // namespace
}  // namespace sinew::collision
