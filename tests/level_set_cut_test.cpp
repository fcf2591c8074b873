// level_set_cut_test.cpp — cutting a level set (issue 14, part 4;
// LevelSet::cut, update_level_set, LevelSet::surface): a burr removes the
// analytically swept volume within the voxel tolerance and nothing outside
// it; a saw turning as it moves is swept as a whole; a device's copy brought
// up to date by the changed leaves alone samples like a fresh upload; the
// surface is the zero level and follows the cut; bad cuts are named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "level_set/device_level_set.h"
#include "sinew/level_set.h"
#include "test_support.h"

namespace sinew::test {
namespace {

#if SINEW_HAS_OPENVDB

constexpr double kVoxel = 1e-4;  // 0.1 mm

// A solid 6 mm cube about the origin, its whole inside stored.
LevelSet solid_cube() {
  auto cube = LevelSet::box({-3e-3, -3e-3, -3e-3}, {3e-3, 3e-3, 3e-3},
                            {.voxel_size = kVoxel, .exterior_band = 4e-4, .interior_band = INFINITY});
  EXPECT_TRUE(cube.ok()) << cube.error().message();
  return *cube;
}

double segment_distance(const std::array<double, 3>& p, const std::array<double, 3>& a,
                        const std::array<double, 3>& b) {
  double d[3], w[3], dd = 0.0, dw = 0.0;
  for (int k = 0; k < 3; ++k) d[k] = b[k] - a[k], w[k] = p[k] - a[k], dd += d[k] * d[k], dw += d[k] * w[k];
  const double u = std::clamp(dw / dd, 0.0, 1.0);
  double r = 0.0;
  for (int k = 0; k < 3; ++k) r += (w[k] - u * d[k]) * (w[k] - u * d[k]);
  return std::sqrt(r);
}

TEST(LevelSetCut, ABurrRemovesTheSweptVolumeAndNothingElse) {
  LevelSet cube = solid_cube();
  const double r = 1e-3;
  const std::array<double, 3> a{-0.7e-3, 0.2e-3, 0.1e-3}, b{0.8e-3, -0.3e-3, 0.25e-3};  // 1.6 mm, inside
  // The voxels' values before, on a lattice around the cut.
  std::vector<std::array<double, 3>> lattice;
  std::vector<double> before;
  for (int i = -25; i <= 25; ++i)
    for (int j = -25; j <= 25; ++j)
      for (int k = -25; k <= 25; ++k) {
        lattice.push_back({i * kVoxel, j * kVoxel, k * kVoxel});
        before.push_back(cube.value(lattice.back()));
      }
  auto report = cube.cut({.kind = CutterShape::Kind::sphere, .radius = r}, {.position = a}, {.position = b});
  ASSERT_TRUE(report.ok()) << report.error().message();
  double length = 0.0;
  for (int k = 0; k < 3; ++k) length += (b[k] - a[k]) * (b[k] - a[k]);
  length = std::sqrt(length);
  const double swept = 4.0 / 3.0 * M_PI * r * r * r + M_PI * r * r * length;
  std::printf("burr: removed %.5f mm^3 of %.5f swept (%.3f%%), %llu voxels in %u leaves\n",
              report->removed_volume * 1e9, swept * 1e9, 100.0 * (report->removed_volume / swept - 1.0),
              (unsigned long long)report->changed_voxels, report->changed_leaves);
  EXPECT_NEAR(report->removed_volume, swept, 0.01 * swept);
  // Nothing is removed farther than a voxel from the sweep (a voxel's
  // inside fraction, clamp(1/2 - value / h, 0, 1), is unchanged there; its
  // distance may shrink: the new face is nearer); everything deeper than a
  // voxel inside the sweep is gone; within the band of the new face the
  // distance is the tool's.
  const auto inside = [](double value) { return std::clamp(0.5 - value / kVoxel, 0.0, 1.0); };
  std::size_t removed_outside = 0, left_inside = 0, wrong_distance = 0;
  for (std::size_t n = 0; n < lattice.size(); ++n) {
    const double tool = segment_distance(lattice[n], a, b) - r;
    const double after = cube.value(lattice[n]);
    if (tool > kVoxel && inside(after) != inside(before[n])) ++removed_outside;
    if (tool < -kVoxel && !(after > 0.0)) ++left_inside;
    if (std::abs(tool) < 3e-4 && std::abs(after + tool) > 1e-6) ++wrong_distance;  // (-tool, to float)
  }
  EXPECT_EQ(removed_outside, 0u);
  EXPECT_EQ(left_inside, 0u);
  EXPECT_EQ(wrong_distance, 0u);
}

TEST(LevelSetCut, ATurningSawIsSweptAsAWhole) {
  LevelSet cube = solid_cube();
  // A 4 x 0.3 x 2 mm blade turned by 60 degrees about y while it moves 1 mm along x.
  const CutterShape saw{.kind = CutterShape::Kind::box, .half_extents = {2e-3, 0.15e-3, 1e-3}};
  const double turn = M_PI / 3.0;
  const Pose from{.position = {-0.5e-3, 0.0, 0.0}};
  const Pose to{.position = {0.5e-3, 0.0, 0.0}, .rotation = {std::cos(turn / 2), 0.0, std::sin(turn / 2), 0.0}};
  auto report = cube.cut(saw, from, to);
  ASSERT_TRUE(report.ok()) << report.error().message();
  // Points the blade passes through at intermediate poses are gone:
  // the blade's tip halfway through the turn.
  const double half = turn / 2;
  const std::array<double, 3> tip{0.0 + 1.9e-3 * std::cos(half), 0.0, -1.9e-3 * std::sin(half)};
  std::printf("saw: removed %.4f mm^3, %llu voxels; halfway tip reads %.3f mm\n", report->removed_volume * 1e9,
              (unsigned long long)report->changed_voxels, cube.value(tip) * 1e3);
  EXPECT_GT(cube.value(tip), 0.0);
  EXPECT_GT(report->removed_volume, 4e-3 * 0.3e-3 * 2e-3);  // at least the blade itself
}

class LevelSetCutDevice : public BackendTest {};

TEST_P(LevelSetCutDevice, TheChangedLeavesBringTheDeviceUpToDate) {
  auto made = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(made.ok()) << made.error().message();
  Device& device = **made;
  LevelSet cube = solid_cube();
  auto grid = upload_level_set(device, cube);
  ASSERT_TRUE(grid.ok()) << grid.error().message();
  std::uint64_t written = 0, changed = 0;
  for (int step = 0; step < 4; ++step) {  // a burr moving 1 mm per tick along x
    const Pose from{.position = {-2e-3 + 1e-3 * step, 1e-3, 0.0}}, to{.position = {-1e-3 + 1e-3 * step, 1e-3, 0.0}};
    auto report = cube.cut({.kind = CutterShape::Kind::sphere, .radius = 1.5e-3}, from, to);
    ASSERT_TRUE(report.ok()) << report.error().message();
    std::uint64_t bytes = 0;
    ASSERT_TRUE(update_level_set(device, *grid, cube, *report, &bytes).ok());
    written += bytes;
    for (const auto& range : report->changed_bytes) changed += range[1];
  }
  // The device's copy against a fresh upload of the host's, at points
  // around the cut.
  auto fresh = upload_level_set(device, cube);
  ASSERT_TRUE(fresh.ok());
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-3.5e-3f, 3.5e-3f);
  std::vector<std::array<float, 3>> points(100000);
  for (auto& p : points) p = {u(rng), u(rng), u(rng)};
  auto updated = sample_level_set(device, *grid, points);
  auto expected = sample_level_set(device, *fresh, points);
  ASSERT_TRUE(updated.ok() && expected.ok());
  std::size_t differ = 0;
  for (std::size_t q = 0; q < points.size(); ++q) differ += (*updated)[q] != (*expected)[q] ? 1 : 0;
  std::printf("[%s] 4 cuts wrote %llu bytes of a %zu-byte grid (%.1f%%); %zu of %zu samples differ from a fresh upload\n",
              GetParam().c_str(), (unsigned long long)written, grid->bytes, 100.0 * double(written) / double(grid->bytes),
              differ, points.size());
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(written, changed);  // the changed leaves, nothing more
  EXPECT_LT(written, grid->bytes / 2);
}

INSTANTIATE_TEST_SUITE_P(Backends, LevelSetCutDevice, ::testing::ValuesIn(backends()), backend_name);

TEST(LevelSetCut, TheSurfaceIsTheZeroLevelAndFollowsTheCut) {
  auto sphere = LevelSet::sphere({0.0, 0.0, 0.0}, 3e-3,
                                 {.voxel_size = kVoxel, .exterior_band = 4e-4, .interior_band = INFINITY});
  ASSERT_TRUE(sphere.ok());
  TriMesh before = sphere->surface();
  double worst = 0.0;
  for (const auto& v : before.vertices) worst = std::max(worst, std::abs(std::hypot(v[0], v[1], v[2]) - 3e-3));
  const SurfaceReport closed = check_closed_surface(before).value();
  std::printf("surface: %zu triangles, vertices at most %.3f voxels off the sphere; %llu open edges\n",
              before.triangles.size(), worst / kVoxel, (unsigned long long)closed.open_edges);
  EXPECT_LT(worst, 0.5 * kVoxel);
  EXPECT_EQ(closed.open_edges, 0u);
  EXPECT_EQ(closed.misoriented_edges, 0u);
  // A burr of 1 mm radius centred on the sphere's surface at +x: the new
  // surface has vertices on the burr's sphere inside the old one.
  ASSERT_TRUE(sphere->cut({.radius = 1e-3}, {.position = {3e-3, 0.0, 0.0}}, {.position = {3e-3, 0.0, 0.0}}).ok());
  const TriMesh after = sphere->surface();
  std::size_t on_burr = 0;
  for (const auto& v : after.vertices)
    if (std::hypot(v[0], v[1], v[2]) < 3e-3 - kVoxel && std::abs(std::hypot(v[0] - 3e-3, v[1], v[2]) - 1e-3) < kVoxel)
      ++on_burr;
  std::printf("after the cut: %zu triangles, %zu vertices on the burr's face\n", after.triangles.size(), on_burr);
  EXPECT_GT(on_burr, 100u);
}

TEST(LevelSetCut, APartOfTheSolidIsAClosedSurfaceCappedByTheBox) {
  // The half of a 3 mm sphere with x >= 0 (a box reaching past it on the
  // other sides): closed and oriented, its vertices within a voxel of the
  // box, its volume half the sphere's and at most the slab of a voxel
  // more (1% for the sphere's own discretisation); a bad box is named.
  const double r = 3e-3;
  auto sphere = LevelSet::sphere({0.0, 0.0, 0.0}, r, {.voxel_size = kVoxel, .exterior_band = 4e-4, .interior_band = INFINITY});
  ASSERT_TRUE(sphere.ok());
  auto half = sphere->surface_in({0.0, -0.01, -0.01, 0.01, 0.01, 0.01});
  ASSERT_TRUE(half.ok()) << half.error().message();
  const SurfaceReport closed = check_closed_surface(*half).value();
  double volume = 0.0, lowest_x = 1.0;
  for (const auto& t : half->triangles) {
    const auto &a = half->vertices[t[0]], &b = half->vertices[t[1]], &c = half->vertices[t[2]];
    volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
               a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
  }
  for (const auto& v : half->vertices) lowest_x = std::min(lowest_x, v[0]);
  const double expected = 2.0 / 3.0 * M_PI * r * r * r;
  std::printf("half sphere: %zu triangles, %llu open and %llu misoriented edges, volume %.4f of the half, lowest x "
              "%.3f voxels\n",
              half->triangles.size(), (unsigned long long)closed.open_edges,
              (unsigned long long)closed.misoriented_edges, volume / expected, lowest_x / kVoxel);
  EXPECT_EQ(closed.open_edges, 0u);
  EXPECT_EQ(closed.misoriented_edges, 0u);
  // The caps stand on the voxels: within a voxel outside the box's face.
  EXPECT_GT(volume, 0.99 * expected);
  EXPECT_LT(volume, 1.01 * expected + M_PI * r * r * kVoxel);
  EXPECT_GT(lowest_x, -kVoxel);
  auto bad = sphere->surface_in({0.0, 0.0, 0.0, 0.0, 1.0, 1.0});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("lo < hi"), std::string::npos) << bad.error().message();
  EXPECT_FALSE(sphere->surface_in({NAN, 0.0, 0.0, 1.0, 1.0, 1.0}).ok());
}

TEST(LevelSetCut, BadCutsAreNamed) {
  LevelSet cube = solid_cube();
  const auto message = [&](const CutterShape& shape, const Pose& from, const Pose& to) {
    auto r = cube.cut(shape, from, to);
    return r.ok() ? std::string() : r.error().message();
  };
  EXPECT_NE(message({.radius = 0.0}, {}, {}).find("radius"), std::string::npos);
  EXPECT_NE(message({.kind = CutterShape::Kind::box, .half_extents = {1e-3, -1.0, 1e-3}}, {}, {}).find("half_extents"),
            std::string::npos);
  EXPECT_NE(message({}, {.position = {NAN, 0, 0}}, {}).find("from position"), std::string::npos);
  EXPECT_NE(message({}, {}, {.rotation = {2, 0, 0, 0}}).find("to rotation is not a unit quaternion"),
            std::string::npos);
  auto banded = LevelSet::sphere({0, 0, 0}, 3e-3, {.voxel_size = kVoxel, .exterior_band = 4e-4, .interior_band = 4e-4});
  ASSERT_TRUE(banded.ok());
  auto r = banded->cut({}, {}, {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message().find("interior_band = +infinity"), std::string::npos) << r.error().message();
}

#endif

}  // namespace
}  // namespace sinew::test
