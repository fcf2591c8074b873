// tool_surface_test.cpp — the examples' tool surfaces (examples/common/
// tool_surface.h): a capsule's surface bounds a solid, faces outward, and
// lies on the capsule at its pose.
#include "tool_surface.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace {

using sinew::examples::capsule_surface;

// Distance from p to the posed capsule's axis segment.
double axis_distance(const sinew::Vec3d& p, double half_height, const sinew::Pose& pose) {
  const auto axis = sinew::examples::rotate(pose.rotation, {0.0, 1.0, 0.0});
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
    double volume = 0.0;
    for (const auto& t : mesh.triangles) {
      const auto &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
      volume += ((a[0] - pose.position[0]) * ((b[1] - pose.position[1]) * (c[2] - pose.position[2]) -
                                             (b[2] - pose.position[2]) * (c[1] - pose.position[1])) -
                 (a[1] - pose.position[1]) * ((b[0] - pose.position[0]) * (c[2] - pose.position[2]) -
                                             (b[2] - pose.position[2]) * (c[0] - pose.position[0])) +
                 (a[2] - pose.position[2]) * ((b[0] - pose.position[0]) * (c[1] - pose.position[1]) -
                                             (b[1] - pose.position[1]) * (c[0] - pose.position[0]))) /
                6.0;
    }
    const double exact = M_PI * 0.008 * 0.008 * (2.0 * half_height + 4.0 / 3.0 * 0.008);
    EXPECT_GT(volume, 0.9 * exact);
    EXPECT_LT(volume, exact);  // inscribed
  }
}

}  // namespace
