// tool_surface_test.cpp — the display surfaces of tools and colliders
// (sinew/display_surfaces.h): a capsule's surface bounds a solid, faces
// outward, and lies on the capsule at its pose; boxes and cylinders close.
#include "sinew/display_surfaces.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace {

using sinew::capsule_surface;

// Distance from p to the posed capsule's axis segment.
double axis_distance(const sinew::Vec3d& p, double half_height, const sinew::Pose& pose) {
  const auto axis = sinew::rotate(pose.rotation, {0.0, 1.0, 0.0});
  double along = 0.0;
  for (int k = 0; k < 3; ++k) along += (p[k] - pose.position[k]) * axis[k];
  along = std::clamp(along, -half_height, half_height);
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double d = p[k] - (pose.position[k] + along * axis[k]);
    d2 += d * d;
  }
  return std::sqrt(d2);
}

// The signed volume of a closed surface (positive when wound outward).
double signed_volume(const sinew::TriMesh& mesh, const sinew::Pose& pose) {
  double volume = 0.0;
  for (const auto& t : mesh.triangles) {
    std::array<std::array<double, 3>, 3> p{};
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) p[i][k] = mesh.vertices[t[i]][k] - pose.position[k];
    volume += (p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) - p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
               p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0])) /
              6.0;
  }
  return volume;
}

::testing::AssertionResult closed(const sinew::TriMesh& mesh) {
  auto report = sinew::check_closed_surface(mesh);
  if (!report) return ::testing::AssertionFailure() << report.error().message();
  if (report->open_edges || report->nonmanifold_edges || report->misoriented_edges || report->degenerate_triangles)
    return ::testing::AssertionFailure() << "open, non-manifold, misoriented or degenerate";
  return ::testing::AssertionSuccess();
}

TEST(ToolSurface, BoxAndCylinderAreClosedOutwardWithTheirVolume) {
  const double s = std::sqrt(0.5);
  const sinew::Pose pose{.position = {0.1, -0.2, 0.3}, .rotation = {s, s, 0.0, 0.0}};
  const sinew::TriMesh box = sinew::box_surface({0.01, 0.02, 0.03}, pose);
  EXPECT_TRUE(closed(box));
  EXPECT_NEAR(signed_volume(box, pose), 8 * 0.01 * 0.02 * 0.03, 1e-12);
  const sinew::TriMesh cylinder = sinew::cylinder_surface(0.01, 0.02, pose);
  EXPECT_TRUE(closed(cylinder));
  const double exact = M_PI * 0.01 * 0.01 * 0.04;
  EXPECT_GT(signed_volume(cylinder, pose), 0.95 * exact);
  EXPECT_LT(signed_volume(cylinder, pose), exact);  // inscribed
}

TEST(ToolSurface, CapsuleAndBallAreClosedOutwardAndOnTheShape) {
  const double s = std::sqrt(0.5);
  const sinew::Pose pose{.position = {0.1, -0.2, 0.3}, .rotation = {s, 0.0, 0.0, s}};
  for (const double half_height : {0.02, 0.0}) {
    const sinew::TriMesh mesh = capsule_surface(0.008, half_height, pose);
    auto report = sinew::check_closed_surface(mesh);
    ASSERT_TRUE(report) << report.error().message();
    EXPECT_EQ(report->open_edges, 0u);
    EXPECT_EQ(report->nonmanifold_edges, 0u);
    EXPECT_EQ(report->misoriented_edges, 0u);
    EXPECT_EQ(report->degenerate_triangles, 0u);
    for (const auto& v : mesh.vertices) EXPECT_NEAR(axis_distance(v, half_height, pose), 0.008, 1e-12);
    // Outward: the signed volume (divergence theorem) is positive and
    // close to the capsule's.
    const double volume = signed_volume(mesh, pose);
    const double exact = M_PI * 0.008 * 0.008 * (2.0 * half_height + 4.0 / 3.0 * 0.008);
    EXPECT_GT(volume, 0.9 * exact);
    EXPECT_LT(volume, exact);  // inscribed
  }
}

}  // namespace
