// level_set_bounds_test.cpp — level-set factories and cuts on hostile
// sizes end in named errors, never an exception, an int overflow or a loop
// without end (issue 39): a voxel below OpenVDB's smallest, a shape far
// from the origin, a voxel too fine for the shape, a cube beyond float32,
// an open triangle soup, a cut swept across the world.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>

#include "sinew/level_set.h"

namespace sinew {
namespace {

#if SINEW_HAS_OPENVDB

using P = std::array<double, 3>;

// The error's code, and that its message names `what`.
template <class T>
void expect_error(const Result<T>& result, ErrorCode code, const std::string& what) {
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().code(), code) << result.error().message();
  EXPECT_NE(result.error().message().find(what), std::string::npos) << result.error().message();
}

TEST(LevelSetBounds, AVoxelBelowOpenVdbsSmallestIsNamed) {
  // Before: OpenVDB's ArithmeticError escaped (a voxel below ~14.4 um).
  LevelSetSettings s;
  s.voxel_size = 1e-5;
  s.exterior_band = s.interior_band = 3e-5;
  expect_error(LevelSet::sphere({0, 0, 0}, 1e-4, s), ErrorCode::bad_parameter, "voxel_size");
  expect_error(LevelSet::box({0, 0, 0}, {1e-4, 1e-4, 1e-4}, s), ErrorCode::bad_parameter, "voxel_size");
  s.voxel_size = 1.5e-5;  // the smallest allowed builds
  EXPECT_TRUE(LevelSet::sphere({0, 0, 0}, 1e-4, s).ok());
}

TEST(LevelSetBounds, AShapeFarFromTheOriginIsNamed) {
  // Before: voxel indices of 2e15 overflowed int (undefined behaviour).
  const LevelSetSettings s;
  expect_error(LevelSet::sphere({1e12, 0, 0}, 1e-2, s), ErrorCode::bad_parameter, "voxel index");
  expect_error(LevelSet::box({1e12, 0, 0}, {1e12 + 1e-2, 1e-2, 1e-2}, s), ErrorCode::bad_parameter, "voxel index");
}

TEST(LevelSetBounds, AVoxelTooFineForTheShapeIsNamed) {
  // Before: a 1 m sphere at 20 um looped over 1.25e17 voxels.
  LevelSetSettings s;
  s.voxel_size = 2e-5;
  s.exterior_band = s.interior_band = 6e-5;
  expect_error(LevelSet::sphere({0, 0, 0}, 1.0, s), ErrorCode::capacity_exceeded, "2^30");
  expect_error(LevelSet::box({0, 0, 0}, {1, 1, 1}, s), ErrorCode::capacity_exceeded, "2^30");
}

TEST(LevelSetBounds, ACubeBeyondFloatIsNamed) {
  // Before: a cube of 1e39 m (infinite in float) gave 25 garbage voxels.
  LevelSetSettings s;
  expect_error(LevelSet::box({0, 0, 0}, {1e39, 1e39, 1e39}, s), ErrorCode::bad_parameter, "hi");
  s.voxel_size = 1e38;
  s.exterior_band = s.interior_band = 3e38;
  expect_error(LevelSet::box({0, 0, 0}, {1e39, 1e39, 1e39}, s), ErrorCode::bad_parameter, "float32");
  s.exterior_band = 1e39;
  expect_error(LevelSet::sphere({0, 0, 0}, 1e38, s), ErrorCode::bad_parameter, "exterior_band");
}

TEST(LevelSetBounds, AnOpenSoupIsRefusedByItsEdges) {
  // Before: 42.6 s and 2.1 GB searching a 20,000-triangle soup for crossings.
  std::mt19937 rng(39);
  std::uniform_real_distribution<double> u(0.0, 0.05);
  TriMesh soup;
  for (std::uint32_t t = 0; t < 20000; ++t) {
    for (int v = 0; v < 3; ++v) soup.vertices.push_back({u(rng), u(rng), u(rng)});
    soup.triangles.push_back({3 * t, 3 * t + 1, 3 * t + 2});
  }
  const Result<LevelSet> refused = LevelSet::from_mesh(soup, LevelSetSettings{});
  expect_error(refused, ErrorCode::bad_parameter, "60000 open edges");
  // Judged by its edges: the crossing search did not run.
  expect_error(refused, ErrorCode::bad_parameter, "crossings not searched for");
}

TEST(LevelSetBounds, ACutSweptAcrossTheWorldIsNamed) {
  LevelSetSettings s;
  s.interior_band = std::numeric_limits<double>::infinity();
  auto solid = LevelSet::box({0, 0, 0}, {0.01, 0.01, 0.01}, s);
  ASSERT_TRUE(solid.ok()) << solid.error().message();
  CutterShape burr;
  Pose from, to;
  to.position = {1e12, 0, 0};
  expect_error(solid->cut(burr, from, to), ErrorCode::bad_parameter, "voxel index");
  CutterShape saw;
  saw.kind = CutterShape::Kind::box;
  to.position = {1e3, 0, 0};  // 4 million poses half a voxel apart
  expect_error(solid->cut(saw, from, to), ErrorCode::capacity_exceeded, "poses");
  // Within both bounds alone, not together: 2 m is 8,000 poses, each tested
  // at the millions of voxels along the way (before: minutes of work).
  to.position = {2.0, 0, 0};
  expect_error(solid->cut(saw, from, to), ErrorCode::capacity_exceeded, "distance evaluations");
  // A stroke of a few voxels is well within them, and cuts.
  to.position = {0.004, 0.005, 0.005};
  from.position = {-0.004, 0.005, 0.005};
  const auto stroke = solid->cut(saw, from, to);
  ASSERT_TRUE(stroke.ok()) << stroke.error().message();
  EXPECT_GT(stroke->changed_voxels, 0u);
}

#else

TEST(LevelSetBounds, NotBuilt) { GTEST_SKIP() << "built without OpenVDB"; }

#endif

}  // namespace
}  // namespace sinew
