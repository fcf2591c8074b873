// level_set_test.cpp — signed distance grids (issue 14, part 1): a sphere's
// and a box's within half a voxel of their analytic distances in the band,
// the gradient of unit length away from the medial axis, a cube mesh's
// equal to the analytic box's, the tibia's surface at distance zero, the
// background beyond the bands; bad settings and surfaces named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "sinew/level_set.h"
#include "sinew/mesh.h"

namespace sinew {
namespace {

#if SINEW_HAS_OPENVDB

using P = std::array<double, 3>;

double norm(const P& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// The box [lo, hi]'s exact signed distance, and how far p is from where
// its nearest feature stops being one face (the medial surfaces inside;
// outside, the slabs beyond an edge or corner, where the distance is to
// that edge or corner and curves): there the distance is linear, so its
// trilinear interpolant's gradient is exact.
struct BoxDistance {
  double d, planar;
};
BoxDistance box_distance(const P& lo, const P& hi, const P& p) {
  double outside = 0.0, q[3];
  for (int k = 0; k < 3; ++k) {
    q[k] = std::abs(p[k] - 0.5 * (lo[k] + hi[k])) - 0.5 * (hi[k] - lo[k]);
    outside += q[k] > 0.0 ? q[k] * q[k] : 0.0;
  }
  std::sort(q, q + 3);
  if (outside > 0.0) return {std::sqrt(outside), -q[1]};  // one face nearest while the other two q < 0
  return {q[2], q[2] - q[1]};
}

constexpr double kVoxel = 2.5e-4;  // 0.25 mm

LevelSetSettings settings() { return {.voxel_size = kVoxel, .exterior_band = 1e-3, .interior_band = 1e-3}; }

TEST(LevelSet, ASphereIsWithinHalfAVoxelOfItsDistanceWithAUnitGradient) {
  const P centre{0.001, -0.002, 0.0005};
  // 32 voxels: the trilinear interpolation of central differences is off
  // unit length by about 0.5 (h / r)^2 (1.5e-3 at r = 19 voxels, the
  // inner band of a 20-voxel sphere), so 1e-3 holds from about 23 voxels
  // from the medial axis (the centre) on.
  const double radius = 0.008;
  auto sphere = LevelSet::sphere(centre, radius, settings());
  ASSERT_TRUE(sphere.ok()) << sphere.error().message();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), band(-0.9e-3, 0.9e-3);
  double worst = 0.0, worst_gradient = 0.0;
  for (int n = 0; n < 20000; ++n) {
    P dir{unit(rng), unit(rng), unit(rng)};
    const double l = norm(dir);
    if (l < 0.1 || l > 1.0) continue;
    const double r = radius + band(rng);
    const P p{centre[0] + r * dir[0] / l, centre[1] + r * dir[1] / l, centre[2] + r * dir[2] / l};
    worst = std::max(worst, std::abs(sphere->value(p) - (r - radius)));
    // The gradient where its 32 voxels (the 8 around p and their
    // neighbours) are all in the band.
    if (std::abs(r - radius) < 1e-3 - 3.0 * kVoxel)
      worst_gradient = std::max(worst_gradient, std::abs(norm(sphere->gradient(p)) - 1.0));
  }
  std::printf("sphere: at most %.4f voxels off the distance, |gradient| at most %.2e off 1\n", worst / kVoxel,
              worst_gradient);
  EXPECT_LT(worst, 0.5 * kVoxel);
  EXPECT_LT(worst_gradient, 1e-3);
  // Beyond the bands: the background, a zero gradient.
  EXPECT_FLOAT_EQ(float(sphere->value({centre[0] + radius + 0.01, centre[1], centre[2]})), 1e-3f);
  EXPECT_NEAR(sphere->value(centre), -1e-3, 1e-9);
  EXPECT_EQ(norm(sphere->gradient(centre)), 0.0);
}

TEST(LevelSet, ABoxIsWithinHalfAVoxelOfItsDistanceWithAUnitGradient) {
  const P lo{-0.004, -0.001, -0.003}, hi{0.003, 0.0035, 0.002};
  auto box = LevelSet::box(lo, hi, settings());
  ASSERT_TRUE(box.ok()) << box.error().message();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(-0.0055, 0.0045), y(-0.0025, 0.005), z(-0.0045, 0.0035);
  double worst = 0.0, worst_gradient = 0.0;
  int sampled = 0;
  for (int n = 0; n < 40000; ++n) {
    const P p{x(rng), y(rng), z(rng)};
    const BoxDistance exact = box_distance(lo, hi, p);
    if (std::abs(exact.d) > 0.9e-3) continue;  // the band, less a voxel at its rim
    ++sampled;
    worst = std::max(worst, std::abs(box->value(p) - exact.d));
    if (exact.planar > 2.0 * kVoxel && std::abs(exact.d) < 1e-3 - 2.0 * kVoxel)
      worst_gradient = std::max(worst_gradient, std::abs(norm(box->gradient(p)) - 1.0));
  }
  std::printf("box: %d points in the band, at most %.4f voxels off, |gradient| at most %.2e off 1\n", sampled,
              worst / kVoxel, worst_gradient);
  EXPECT_GT(sampled, 1000);
  EXPECT_LT(worst, 0.5 * kVoxel);
  EXPECT_LT(worst_gradient, 1e-3);
}

// Outside near its edges and corners the box's distance curves with a
// radius of a few voxels, and the trilinear gradient is off by about
// (h / r)^2 / 8 there; the sphere above (r = 20 voxels) covers curved
// distances.

// Build a cube as a surface: OpenVDB's mesh-to-volume gives the analytic
// box's distance.
TEST(LevelSet, ACubeMeshGivesTheBoxDistance) {
  TriMesh cube;
  const double lo = -0.002, size = 0.004;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) cube.vertices.push_back({lo + i * size, lo + j * size, lo + k * size});
  const std::uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    cube.triangles.push_back({f[0], f[1], f[2]});
    cube.triangles.push_back({f[0], f[2], f[3]});
  }
  auto level_set = LevelSet::from_mesh(cube, settings());
  ASSERT_TRUE(level_set.ok()) << level_set.error().message();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.0032, 0.0032);
  double worst = 0.0;
  for (int n = 0; n < 20000; ++n) {
    const P p{u(rng), u(rng), u(rng)};
    const BoxDistance exact = box_distance({lo, lo, lo}, {lo + size, lo + size, lo + size}, p);
    if (std::abs(exact.d) > 0.9e-3) continue;
    worst = std::max(worst, std::abs(level_set->value(p) - exact.d));
  }
  std::printf("cube mesh: at most %.4f voxels off the box's distance\n", worst / kVoxel);
  EXPECT_LT(worst, 0.5 * kVoxel);
}

// The tibia (mm, scaled to m) at 0.5 mm voxels: its vertices lie on the
// zero level within half a voxel, points pushed out along the gradient
// read positive.
TEST(LevelSet, TheTibiaSurfaceIsItsZeroLevel) {
  auto mesh = read_stl(std::string(SINEW_DATA_DIR) + "/meshes/surface/VHF_Left_Bone_Tibia_smooth.stl");
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  scale_mesh(*mesh, 1e-3);
  const double voxel = 5e-4;
  auto tibia = LevelSet::from_mesh(*mesh, {.voxel_size = voxel, .exterior_band = 2e-3, .interior_band = 2e-3});
  ASSERT_TRUE(tibia.ok()) << tibia.error().message();
  double worst = 0.0;
  for (std::size_t v = 0; v < mesh->vertices.size(); v += 7)
    worst = std::max(worst, std::abs(tibia->value(mesh->vertices[v])));
  const auto b = tibia->bounds();
  std::printf("tibia: %llu voxels in %.0f x %.0f x %.0f mm; vertices at most %.3f voxels off zero\n",
              (unsigned long long)tibia->voxels(), (b[3] - b[0]) * 1e3, (b[4] - b[1]) * 1e3, (b[5] - b[2]) * 1e3,
              worst / voxel);
  EXPECT_LT(worst, 0.5 * voxel);
  EXPECT_FALSE(tibia->nanovdb_bytes().empty());
}

TEST(LevelSet, ABoxFilledInsideStoresEveryVoxelInside) {
  LevelSetSettings s = settings();
  s.interior_band = INFINITY;
  const P lo{0.0, 0.0, 0.0}, hi{0.004, 0.004, 0.004};
  auto filled = LevelSet::box(lo, hi, s);
  ASSERT_TRUE(filled.ok()) << filled.error().message();
  EXPECT_NEAR(filled->value({0.002, 0.002, 0.002}), -0.002, 1e-7);  // the centre, 2 mm deep: beyond a 1 mm band
  auto banded = LevelSet::box(lo, hi, settings());
  ASSERT_TRUE(banded.ok());
  EXPECT_GT(filled->voxels(), banded->voxels());
}

TEST(LevelSet, BadSettingsAndSurfacesAreNamed) {
  const auto message = [](const Result<LevelSet>& r) { return r.ok() ? std::string() : r.error().message(); };
  LevelSetSettings s = settings();
  s.voxel_size = 0.0;
  EXPECT_NE(message(LevelSet::sphere({0, 0, 0}, 0.01, s)).find("voxel_size"), std::string::npos);
  s = settings();
  s.exterior_band = 1e-5;
  EXPECT_NE(message(LevelSet::sphere({0, 0, 0}, 0.01, s)).find("exterior_band"), std::string::npos);
  s = settings();
  s.interior_band = NAN;
  EXPECT_NE(message(LevelSet::sphere({0, 0, 0}, 0.01, s)).find("interior_band"), std::string::npos);
  EXPECT_NE(message(LevelSet::sphere({0, NAN, 0}, 0.01, settings())).find("centre"), std::string::npos);
  EXPECT_NE(message(LevelSet::sphere({0, 0, 0}, -1.0, settings())).find("radius"), std::string::npos);
  EXPECT_NE(message(LevelSet::box({0, 0, 0}, {1e-3, 0, 1e-3}, settings())).find("axis 1"), std::string::npos);

  TriMesh open;
  open.vertices = {{0, 0, 0}, {1e-3, 0, 0}, {0, 1e-3, 0}, {0, 0, 1e-3}};
  open.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}};  // a tetrahedron missing a face
  EXPECT_NE(message(LevelSet::from_mesh(open, settings())).find("3 open edges"), std::string::npos)
      << message(LevelSet::from_mesh(open, settings()));
  TriMesh tet = open;
  tet.triangles.push_back({0, 3, 2});
  EXPECT_TRUE(LevelSet::from_mesh(tet, settings()).ok()) << message(LevelSet::from_mesh(tet, settings()));
  TriMesh crossed = tet;  // a second tetrahedron through the first
  for (int v = 0; v < 4; ++v)
    crossed.vertices.push_back({tet.vertices[v][0] + 2e-4, tet.vertices[v][1] + 2e-4, tet.vertices[v][2] + 2e-4});
  for (const auto& t : tet.triangles) crossed.triangles.push_back({t[0] + 4, t[1] + 4, t[2] + 4});
  EXPECT_NE(message(LevelSet::from_mesh(crossed, settings())).find("crossing each other"), std::string::npos)
      << message(LevelSet::from_mesh(crossed, settings()));
  TriMesh nan = tet;
  nan.vertices[2][1] = NAN;
  EXPECT_NE(message(LevelSet::from_mesh(nan, settings())).find("vertex 2 is not finite"), std::string::npos);
  EXPECT_NE(message(LevelSet::from_mesh(TriMesh{}, settings())).find("empty"), std::string::npos);
}

#else

TEST(LevelSet, WithoutOpenVdbEveryBuildSaysSo) {
  auto sphere = LevelSet::sphere({0, 0, 0}, 0.01, {});
  ASSERT_FALSE(sphere.ok());
  EXPECT_EQ(sphere.error().code(), ErrorCode::backend_unavailable);
  EXPECT_NE(sphere.error().message().find("SINEW_OPENVDB"), std::string::npos);
}

#endif

}  // namespace
}  // namespace sinew
