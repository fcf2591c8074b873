// warnings_test.cpp — sinew/warnings.h: a Neo-Hookean body past its stable
// Courant number is warned when created (and one within it is not); frames
// over their budget are warned at once and then as counts; bad settings are
// named. (The capacity warning: scene_fluid_test.cpp, on a fluid that fills.)
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "robustness_scenes.h"
#include "runtime/frame_warnings.h"
#include "sinew/log.h"
#include "sinew/warnings.h"

namespace sinew::test {
namespace {

class Warnings : public ::testing::Test {
 protected:
  void SetUp() override {
    set_log_callback([this](LogLevel level, std::string_view text) {
      if (level == LogLevel::warning) warnings.emplace_back(text);
    });
  }
  void TearDown() override { set_log_callback({}); }
  [[nodiscard]] int count(std::string_view words) const {
    int n = 0;
    for (const std::string& w : warnings) n += w.find(words) != std::string::npos;
    return n;
  }
  std::vector<std::string> warnings;
};

TEST_F(Warnings, ANeoHookeanBodyPastItsCourantLimitIsWarnedWhenCreated) {
  SceneDesc scene = robustness_block();  // Courant number 0.22 at 8 substeps
  {
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    SINEW_ASSERT_OK(sim);
    EXPECT_EQ(count("Courant"), 0) << "within its stable range";
  }
  scene.solver.substeps = 1;  // Courant number ~1.8
  {
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    ASSERT_TRUE(sim.ok()) << "a warning, not an error: the scene runs as asked";
  }
  ASSERT_EQ(count("Courant"), 1);
  const std::string& w = warnings.back();
  EXPECT_NE(w.find("tet body 0"), std::string::npos) << w;
  EXPECT_NE(w.find("substeps per frame bring it to 0.2"), std::string::npos) << w;
  // The advice holds: that many substeps bring the number to 0.2 or below.
  const std::size_t at = w.find(" substeps per frame");
  const std::size_t from = w.rfind(' ', at - 1) + 1;
  const int advised = std::stoi(w.substr(from, at - from));
  scene.solver.substeps = advised;
  EXPECT_LE(shear_courant_number(scene, 0), 0.2 + 1e-12);
  // A corotational body of the same stiffness has no such limit: no warning.
  scene.solver.substeps = 1;
  ASSERT_TRUE(scene.tet_bodies[0].set_material(TetMaterial::corotational, 3e3, 0.4).ok());
  warnings.clear();
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  EXPECT_EQ(count("Courant"), 0);
}

TEST_F(Warnings, OverrunsAreWarnedOnceThenCountedAndNeverWithoutABudget) {
  auto sim = Simulation::create(robustness_block(), {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  EXPECT_EQ(sim->warning_settings().frame_budget_ms, 0.0) << "off by default";
  run(*sim, 1, 3);
  EXPECT_EQ(count("overran"), 0) << "no budget, no overrun";
  // A budget no frame can keep: the first overrun at once, then one line per repeat_seconds.
  SINEW_ASSERT_OK(sim->set_warning_settings({.frame_budget_ms = 1e-6, .repeat_seconds = 3600.0}));
  run(*sim, 4, 8);
  ASSERT_EQ(count("overran"), 1) << "once, then quiet within repeat_seconds";
  EXPECT_NE(warnings.back().find("1 of the last 1 frames overran their budget of 1e-06 ms"), std::string::npos)
      << warnings.back();
  SINEW_ASSERT_OK(sim->set_warning_settings({.frame_budget_ms = 1e-6, .repeat_seconds = 1e-9}));
  run(*sim, 9, 10);
  ASSERT_EQ(count("overran"), 3) << "with a tiny repeat interval, every frame";
  EXPECT_NE(warnings.back().find("frame 10)"), std::string::npos) << warnings.back();
  // A budget every frame keeps: nothing.
  SINEW_ASSERT_OK(sim->set_warning_settings({.frame_budget_ms = 1e9}));
  run(*sim, 11, 12);
  EXPECT_EQ(count("overran"), 3);
}

TEST_F(Warnings, BadSettingsAreNamedAndChangeNothing) {
  auto sim = Simulation::create(robustness_block(), {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const auto fails = [&](const WarningSettings& s, const char* field) {
    const Status st = sim->set_warning_settings(s);
    ASSERT_FALSE(st.ok()) << field;
    EXPECT_EQ(st.error().code(), ErrorCode::bad_parameter);
    EXPECT_NE(st.error().message().find(field), std::string::npos) << st.error().message();
  };
  fails({.frame_budget_ms = -1.0}, "frame_budget_ms");
  fails({.frame_budget_ms = std::nan("")}, "frame_budget_ms");
  fails({.repeat_seconds = 0.0}, "repeat_seconds");
  fails({.capacity_fraction = 0.0}, "capacity_fraction");
  fails({.capacity_fraction = 1.5}, "capacity_fraction");
  EXPECT_EQ(sim->warning_settings().capacity_fraction, 0.9) << "the defaults stay";
}

}  // namespace
}  // namespace sinew::test
