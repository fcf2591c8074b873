// shape_distance_test.cpp — the deep point of a triangle in an analytic
// shape (collision::triangle_against, src/collision/shape_distance.h)
// against a sampled oracle: random triangles near spheres, capsules, boxes
// and cylinders, and a thin capsule pressed into the middle of a triangle
// far larger than it (a tool between a coarse membrane's vertices: none of
// the search's seven starting points is within reach there).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "collision/shape_distance.h"

namespace sinew::collision {
namespace {

using math::Vec3;

// The least signed distance over a barycentric grid of `n` steps per edge,
// and the grid point's weights.
double sampled(const ColliderDesc& shape, const Vec3& position, const math::Quat& rotation, const Vec3 (&t)[3], int n,
               std::array<double, 3>& at) {
  double best = INFINITY;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const std::array<double, 3> w{double(n - i - j) / n, double(i) / n, double(j) / n};
      const Vec3 p = math::add(math::add(math::mul(t[0], w[0]), math::mul(t[1], w[1])), math::mul(t[2], w[2]));
      const double d = shape_distance(shape, position, rotation, p).distance;
      if (d < best) best = d, at = w;
    }
  return best;
}

TEST(TriangleAgainst, FindsAThinCapsulePressedIntoALargeTrianglesMiddle) {
  ColliderDesc capsule;
  capsule.shape = ColliderShape::capsule;
  capsule.radius = 0.001;
  capsule.half_height = 0.003;
  const math::Quat along_z{std::sqrt(0.5), std::sqrt(0.5), 0.0, 0.0};
  const Vec3 t[3] = {{0.0, 0.0, 0.0}, {0.1, 0.0, 0.0}, {0.0, 0.0, 0.1}};  // 10 cm, in y = 0
  const Vec3 position{0.03, 0.0005, 0.02};                              // 0.5 mm into it from above
  TriangleContact hit;
  ASSERT_TRUE(triangle_against(capsule, position, along_z, t[0], t[1], t[2], 0.001, hit));
  EXPECT_NEAR(hit.distance, -0.0005, 1e-9);
  EXPECT_NEAR(hit.normal[1], -1.0, 1e-6) << "out of the capsule, down through the triangle";
  const Vec3 p = math::add(math::add(math::mul(t[0], hit.weights[0]), math::mul(t[1], hit.weights[1])),
                           math::mul(t[2], hit.weights[2]));
  EXPECT_NEAR(p[0], 0.03, 1e-6);
  EXPECT_LE(std::abs(p[2] - 0.02), capsule.half_height + 1e-5) << "under the capsule's axis";
  // 2 mm above it (1 mm clear of the capsule's surface): out of a 0.5 mm reach, in a 1.5 mm one.
  const Vec3 above{0.03, 0.002, 0.02};
  EXPECT_FALSE(triangle_against(capsule, above, along_z, t[0], t[1], t[2], 0.0005, hit));
  ASSERT_TRUE(triangle_against(capsule, above, along_z, t[0], t[1], t[2], 0.0015, hit));
  EXPECT_NEAR(hit.distance, 0.001, 1e-9);
}

// Random triangles near each convex shape, against a 60-step barycentric
// grid (its spacing bounds how far the grid's best can lie above the true
// least distance): the within-reach decision is exact (never a miss, never
// a triangle clearly beyond reach), and the point returned is never deeper
// than the grid allows; how far it can stop above the least distance (the
// descent is not exact, shape_distance.h) is printed, and bounded at 10% of
// the triangle's longest edge.
TEST(TriangleAgainst, AgreesWithASampledOracleNearEveryConvexShape) {
  std::mt19937 rng(17);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const ColliderShape shapes[] = {ColliderShape::sphere, ColliderShape::capsule, ColliderShape::box,
                                  ColliderShape::cylinder};
  int found = 0, corners = 0;
  double above = 0.0;  // the largest gap above the grid, over the longest edge
  for (int n = 0; n < 800; ++n) {
    ColliderDesc shape;
    shape.shape = shapes[n % 4];
    shape.radius = 0.2 + 0.3 * u(rng);
    shape.half_height = 0.1 + 0.4 * u(rng);
    shape.half_extents = {0.1 + 0.4 * u(rng), 0.1 + 0.4 * u(rng), 0.1 + 0.4 * u(rng)};
    math::Quat q{g(rng), g(rng), g(rng), g(rng)};
    q = math::normalize(q);
    const Vec3 position{g(rng), g(rng), g(rng)};
    // Triangles from 0.1 to 3 across, centred within about a metre of the shape.
    const double size = 0.1 + 2.9 * u(rng);
    const Vec3 centre = math::add(position, Vec3{0.6 * g(rng), 0.6 * g(rng), 0.6 * g(rng)});
    Vec3 t[3];
    for (Vec3& v : t) v = math::add(centre, Vec3{size * g(rng), size * g(rng), size * g(rng)});
    const double reach = 0.3 * u(rng);
    constexpr int kSteps = 60;
    std::array<double, 3> w{};
    const double oracle = sampled(shape, position, q, t, kSteps, w);
    double longest = 0.0;
    for (int k = 0; k < 3; ++k) longest = std::max(longest, math::norm(math::sub(t[(k + 1) % 3], t[k])));
    const double spacing = longest / kSteps;  // the true least distance is within this below the grid's
    TriangleContact hit;
    const bool in = triangle_against(shape, position, q, t[0], t[1], t[2], reach, hit);
    if (oracle < reach - 1e-9) {
      ASSERT_TRUE(in) << "case " << n << ": the grid finds " << oracle << " within the reach " << reach;
    }
    if (oracle > reach + spacing + 1e-9) {
      ASSERT_FALSE(in) << "case " << n;
    }
    if (!in) continue;
    ++found;
    if (std::max({hit.weights[0], hit.weights[1], hit.weights[2]}) > 1.0 - 1e-12) {  // a corner: weights only
      ++corners;
      const int k = int(std::max_element(hit.weights.begin(), hit.weights.end()) - hit.weights.begin());
      ASSERT_LE(shape_distance(shape, position, q, t[k]).distance, oracle + spacing) << "case " << n;
      continue;
    }
    ASSERT_LE(hit.distance, reach + 1e-12) << "case " << n;
    ASSERT_GE(hit.distance, oracle - spacing - 1e-9) << "case " << n << ": deeper than the triangle reaches";
    above = std::max(above, (hit.distance - oracle) / longest);
  }
  EXPECT_GT(found, 100);
  EXPECT_GT(found - corners, 50) << "interior and edge points are checked too";
  EXPECT_LT(above, 0.1);
  std::printf("[ triangle_against ] 800 random triangles: %d within reach (%d at a corner); the point found at most "
              "%.2g of the longest edge above the grid's least distance\n", found, corners, above);
}

}  // namespace
}  // namespace sinew::collision
