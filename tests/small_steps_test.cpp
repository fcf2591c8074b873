// small_steps_test.cpp — float32 positions and many substeps (issue 11,
// part 4). A velocity derived as (x - x_prev) / h carries ~ulp(|x|) / h of
// rounding, which grows as h shrinks: a 1 m chain swinging for a second
// gave runs at 32, 64, 128 and 256 substeps per 60 Hz frame that differed
// by 1.6e-2, 6.8e-2 and 4.8e-2 of its length from the next (more substeps
// moved the answer further). xpbd_update_velocity now carries the predicted
// velocity exactly and adds only the constraints' correction (see
// kernels/cpu/xpbd_kernels.cpp): the same runs differ by 3.4e-3, 3.5e-3 and
// 1.2e-2. The test: 8, 32 and 128 substeps converge towards one answer.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_support.h"

namespace sinew {
namespace {

class SmallSteps : public test::BackendTest {};

// A 20-link chain 1 m long pinned at its top, released 57 degrees from the
// vertical: it swings through the origin's neighbourhood and down to 1 m.
std::vector<float> swing(int substeps, const std::string& backend) {
  LineBodyDesc chain;
  for (int i = 0; i <= 20; ++i) {
    chain.vertices.push_back({0.0, -0.05 * i, 0.0});
    chain.initial_vertices.push_back({0.05 * i * std::sin(1.0), -0.05 * i * std::cos(1.0), 0.0});
    chain.masses.push_back(0.01);
    if (i > 0) chain.segments.push_back({std::uint32_t(i - 1), std::uint32_t(i)});
  }
  chain.compliance = 1e-2;
  chain.pinned = {0};
  SceneDesc scene;
  scene.line_bodies.push_back(chain);
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = substeps, .iterations = 1, .measure_errors = false};
  std::vector<float> x;
  auto sim = test::create_or_skip(scene, backend);
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  if (!sim.ok()) return x;
  for (int f = 0; f < 60; ++f) EXPECT_TRUE(sim->step().ok());
  EXPECT_TRUE(sim->read_positions(x).ok());
  return x;
}

double rms_distance(const std::vector<float>& a, const std::vector<float>& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); i += 4)
    for (int k = 0; k < 3; ++k) sum += std::pow(double(a[i + k]) - b[i + k], 2);
  return std::sqrt(sum / double(a.size() / 4));
}

TEST_P(SmallSteps, MoreSubstepsConvergeTowardsOneAnswer) {
  const std::vector<float> x8 = swing(8, GetParam()), x32 = swing(32, GetParam()), x128 = swing(128, GetParam());
  ASSERT_EQ(x8.size(), x128.size());
  const double coarse = rms_distance(x8, x32), fine = rms_distance(x32, x128);  // the chain is 1 m long
  EXPECT_LT(fine, 0.5 * coarse) << "8 vs 32 substeps: " << coarse << " m, 32 vs 128: " << fine << " m";
  EXPECT_LT(fine, 1e-2);
  std::printf("[ small    ] %s: 8 vs 32 substeps %.2e m, 32 vs 128 substeps %.2e m\n", GetParam().c_str(), coarse,
              fine);
}

INSTANTIATE_TEST_SUITE_P(Backends, SmallSteps, ::testing::ValuesIn(test::backends()), test::backend_name);

}  // namespace
}  // namespace sinew
