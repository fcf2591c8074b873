// level_set_device_test.cpp — level sets sampled inside the kernels (issue
// 14, part 2; src/level_set/device_level_set.h, level_set_sample): the CPU
// reference (PNanoVDB's C mode) equals OpenVDB's own trilinear sampler and
// the host gradient; every backend equals the CPU reference at a million
// points around and away from the tibia's surface.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "level_set/device_level_set.h"
#include "sinew/level_set.h"
#include "sinew/mesh.h"
#include "test_support.h"

namespace sinew::test {
namespace {

#if SINEW_HAS_OPENVDB

class LevelSetDevice : public BackendTest {};

// The tibia at 0.5 mm voxels, 2 mm bands (built once).
const LevelSet& tibia() {
  static const LevelSet level_set = [] {
    auto mesh = read_stl(data_path("meshes/surface/VHF_Left_Bone_Tibia_smooth.stl"));
    EXPECT_TRUE(mesh.ok());
    scale_mesh(*mesh, 1e-3);
    auto made = LevelSet::from_mesh(*mesh, {.voxel_size = 5e-4, .exterior_band = 2e-3, .interior_band = 2e-3});
    EXPECT_TRUE(made.ok()) << made.error().message();
    return *made;
  }();
  return level_set;
}

// n points: half near the surface (a vertex moved up to 2.5 mm), half
// anywhere in the grid's box grown by 5 mm (most in the background).
std::vector<std::array<float, 3>> points_around(std::size_t n, unsigned seed) {
  auto mesh = read_stl(data_path("meshes/surface/VHF_Left_Bone_Tibia_smooth.stl"));
  scale_mesh(*mesh, 1e-3);
  const auto b = tibia().bounds();
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> vertex(0, mesh->vertices.size() - 1);
  std::uniform_real_distribution<double> near(-2.5e-3, 2.5e-3), unit(0.0, 1.0);
  std::vector<std::array<float, 3>> points(n);
  for (std::size_t q = 0; q < n; ++q) {
    if (q % 2 == 0) {
      const auto& v = mesh->vertices[vertex(rng)];
      points[q] = {float(v[0] + near(rng)), float(v[1] + near(rng)), float(v[2] + near(rng))};
    } else {
      for (int k = 0; k < 3; ++k) points[q][k] = float(b[k] - 5e-3 + unit(rng) * (b[k + 3] - b[k] + 1e-2));
    }
  }
  return points;
}

TEST(LevelSetDeviceReference, EqualsOpenVdbsSamplerAndTheHostGradient) {
  auto device = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  auto uploaded = upload_level_set(**device, tibia());
  ASSERT_TRUE(uploaded.ok()) << uploaded.error().message();
  const auto points = points_around(100000, 5);
  auto samples = sample_level_set(**device, *uploaded, points);
  ASSERT_TRUE(samples.ok()) << samples.error().message();
  double value = 0.0, gradient = 0.0;
  for (std::size_t q = 0; q < points.size(); ++q) {
    const std::array<double, 3> p{points[q][0], points[q][1], points[q][2]};
    value = std::max(value, std::abs(double((*samples)[q][0]) - tibia().value(p)));
    const auto g = tibia().gradient(p);
    for (int k = 0; k < 3; ++k) gradient = std::max(gradient, std::abs(double((*samples)[q][k + 1]) - g[k]));
  }
  std::printf("CPU reference against OpenVDB's BoxSampler: values at most %.3g m apart; gradients %.3g apart\n", value,
              gradient);
  // The kernels take p / h in float: off by up to 2^-24 |p| / h voxels,
  // 2e-5 voxels (1e-8 m) at the tibia's 338 mm; OpenVDB's sampler in double.
  EXPECT_LT(value, 1e-7);
  EXPECT_LT(gradient, 1e-4);  // float differences of values over 1 mm
  EXPECT_TRUE(uploaded->destroy(**device).ok());
}

TEST_P(LevelSetDevice, EqualsTheCpuReferenceAtAMillionPoints) {
  auto made = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(made.ok()) << made.error().message();
  Device* device = made->get();
  auto reference = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(reference.ok());
  const auto points = points_around(1000000, 9);
  auto mine = upload_level_set(*device, tibia());
  ASSERT_TRUE(mine.ok()) << mine.error().message();
  auto theirs = upload_level_set(**reference, tibia());
  ASSERT_TRUE(theirs.ok());
  auto got = sample_level_set(*device, *mine, points);
  ASSERT_TRUE(got.ok()) << got.error().message();
  auto expected = sample_level_set(**reference, *theirs, points);
  ASSERT_TRUE(expected.ok());
  double value = 0.0, gradient = 0.0;
  std::size_t differ = 0;
  for (std::size_t q = 0; q < points.size(); ++q) {
    value = std::max(value, double(std::abs((*got)[q][0] - (*expected)[q][0])));
    for (int k = 1; k < 4; ++k) gradient = std::max(gradient, double(std::abs((*got)[q][k] - (*expected)[q][k])));
    differ += (*got)[q] != (*expected)[q] ? 1 : 0;
  }
  std::printf("[%s] a million samples: %zu differ from the CPU reference's; values at most %.3g m, gradients %.3g\n",
              GetParam().c_str(), differ, value, gradient);
  EXPECT_LT(value, 1e-9);
  EXPECT_LT(gradient, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Backends, LevelSetDevice, ::testing::ValuesIn(backends()), backend_name);

#endif

}  // namespace
}  // namespace sinew::test
