// Finite-difference checks of the constraint gradients the kernels use,
// at random and near-degenerate configurations. The constraint functions are
// templates: they are differentiated in double precision (central
// differences), and the float instances the kernels run are compared with
// the double ones at float rounding level.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "cpu/xpbd_kernels.h"

namespace sinew::kernels {
namespace {

double4 random_point(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng), 1.0};
}

double component(const double4& v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
void nudge(double4& v, int k, double d) { (k == 0 ? v.x : (k == 1 ? v.y : v.z)) += d; }

// Central difference of f with respect to coordinate k of point p[i].
template <class F>
double central_difference(F&& f, double4* p, int i, int k, double step) {
  nudge(p[i], k, step);
  const double plus = f(p);
  nudge(p[i], k, -2.0 * step);
  const double minus = f(p);
  nudge(p[i], k, step);
  return (plus - minus) / (2.0 * step);
}

void check_distance(double4 a, double4 b) {
  double4 p[2] = {a, b};
  auto c = [](const double4* q) { return edge_length(q[0], q[1]); };
  const double len = c(p);
  const double4 ga = edge_length_gradient(p[0], p[1], len);
  // Central differences: truncation error ~ (step / len)^2, cancellation
  // error ~ eps * |coordinates| / step; the tolerance covers both.
  const double step = 1e-4 * len;
  const double coords = std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z), std::abs(b.x), std::abs(b.y), std::abs(b.z)});
  const double fd_tol = 1e-7 + 8 * 2.2e-16 * coords / step;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(central_difference(c, p, 0, k, step), component(ga, k), fd_tol) << "d/da" << k;
    EXPECT_NEAR(central_difference(c, p, 1, k, step), -component(ga, k), fd_tol) << "d/db" << k;
  }
  // The float instance (what the kernel runs) agrees with the double one up
  // to the rounding of a - b in float: a few ulps of the coordinates,
  // relative to the edge length.
  const float4 fa{float(a.x), float(a.y), float(a.z), 1.f}, fb{float(b.x), float(b.y), float(b.z), 1.f};
  const float4 fg = edge_length_gradient(fa, fb, edge_length(fa, fb));
  const double tol = 1e-6 + 8 * 1.2e-7 * coords / len;
  EXPECT_NEAR(fg.x, ga.x, tol);
  EXPECT_NEAR(fg.y, ga.y, tol);
  EXPECT_NEAR(fg.z, ga.z, tol);
}

void check_volume(double4 x0, double4 x1, double4 x2, double4 x3) {
  double4 p[4] = {x0, x1, x2, x3};
  auto c = [](const double4* q) { return tet_volume(q[0], q[1], q[2], q[3]); };
  double4 g[4];
  tet_volume_gradients(p[0], p[1], p[2], p[3], g);
  double scale = 0.0;  // gradient magnitude scale: edge length squared
  for (int i = 0; i < 4; ++i) scale = std::max(scale, dot3(g[i], g[i]));
  scale = std::sqrt(scale);
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(central_difference(c, p, i, k, 1e-5), component(g[i], k), 1e-7 * std::max(scale, 1e-3))
          << "d/dx" << i << "_" << k;
  // Translation invariance: the gradients sum to zero.
  const double4 sum = g[0] + g[1] + g[2] + g[3];
  EXPECT_NEAR(sum.x, 0.0, 1e-12 * std::max(scale, 1.0));
  EXPECT_NEAR(sum.y, 0.0, 1e-12 * std::max(scale, 1.0));
  EXPECT_NEAR(sum.z, 0.0, 1e-12 * std::max(scale, 1.0));
}

TEST(ConstraintGradient, DistanceAtRandomConfigurations) {
  std::mt19937 rng(std::random_device{}());
  for (int trial = 0; trial < 200; ++trial) check_distance(random_point(rng, 1.0), random_point(rng, 1.0));
}

TEST(ConstraintGradient, DistanceNearDegenerate) {
  std::mt19937 rng(std::random_device{}());
  // Very short edges: the direction is still well defined and exact.
  for (int trial = 0; trial < 100; ++trial) {
    const double4 a = random_point(rng, 1.0);
    const double4 d = random_point(rng, 1e-4);
    check_distance(a, double4{a.x + d.x, a.y + d.y, a.z + d.z, 1.0});
  }
}

TEST(ConstraintGradient, VolumeAtRandomConfigurations) {
  std::mt19937 rng(std::random_device{}());
  for (int trial = 0; trial < 200; ++trial)
    check_volume(random_point(rng, 1.0), random_point(rng, 1.0), random_point(rng, 1.0), random_point(rng, 1.0));
}

TEST(ConstraintGradient, VolumeNearDegenerate) {
  std::mt19937 rng(std::random_device{}());
  for (int trial = 0; trial < 100; ++trial) {
    // Nearly flat (x3 close to the plane of the others), nearly collinear
    // and inverted tets: V is a cubic polynomial, its gradient exact everywhere.
    const double4 x0 = random_point(rng, 1.0), x1 = random_point(rng, 1.0), x2 = random_point(rng, 1.0);
    const double4 flat = 0.3 * x0 + 0.3 * x1 + 0.4 * x2 + double4{0, 0, 1e-6, 0};
    check_volume(x0, x1, x2, flat);
    const double4 line = 0.5 * x0 + 0.5 * x1 + double4{1e-6, 0, 0, 0};
    check_volume(x0, x1, line, random_point(rng, 1.0));
    check_volume(x1, x0, x2, random_point(rng, 1.0));  // either orientation
  }
}

TEST(ConstraintGradient, VolumeOfTheUnitCornerTet) {
  // Hand-computed: V = 1/6; grad_1 V = (1/6) e2 x e3 = (1/6, 0, 0).
  const double4 x0{0, 0, 0, 1}, x1{1, 0, 0, 1}, x2{0, 1, 0, 1}, x3{0, 0, 1, 1};
  EXPECT_DOUBLE_EQ(tet_volume(x0, x1, x2, x3), 1.0 / 6.0);
  double4 g[4];
  tet_volume_gradients(x0, x1, x2, x3, g);
  EXPECT_DOUBLE_EQ(g[1].x, 1.0 / 6.0);
  EXPECT_DOUBLE_EQ(g[0].x, -1.0 / 6.0);
  EXPECT_DOUBLE_EQ(g[3].z, 1.0 / 6.0);
}

}  // namespace
}  // namespace sinew::kernels
