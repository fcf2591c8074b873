// haptics_scripted_hands_test.cpp — scripted hands on a virtual clock
// (sinew/haptics/scripted_hands.h): two probes on keyframed paths pressed
// into the tissue block through their haptic loops, ticked between the
// frames; the same run twice is the same bit for bit; ticks at each hand's
// own rate; bad hands named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "haptics_block_scene.h"
#include "sinew/haptics/scripted_hands.h"
#include "sinew/simulation.h"

namespace sinew::test {
namespace {

using haptics::KeyframePath;
using haptics::PathInterpolation;
using haptics::ScriptedHandDesc;
using haptics::ScriptedHands;

constexpr double kRadius = 0.004;
const std::array<double, 4> kHorizontal{M_SQRT1_2, 0.0, 0.0, M_SQRT1_2};  // a capsule's y axis along x

// A probe lying along x at y, its lowest point 2 mm above the block's top.
ToolDesc probe(double y) {
  ToolDesc t;
  t.radius = kRadius;
  t.half_height = 0.008;
  t.mass = 0.3;
  t.inertia = {1e-4, 1e-4, 1e-4};
  t.position = {0.0, y, kBlockTop + kRadius + 0.002};
  t.rotation = kHorizontal;
  t.gravity = false;
  return t;
}

// The hand over the probe: down 5 mm (3 mm into the block) over 0.1-0.4 s, then held.
ScriptedHandDesc hand(std::uint32_t tool, double y, double rate_hz) {
  const std::array<double, 3> up{0.0, y, kBlockTop + kRadius + 0.002}, down{0.0, y, kBlockTop + kRadius - 0.003};
  auto path = KeyframePath::create({{.time = 0.1, .position = up, .rotation = kHorizontal},
                                    {.time = 0.4, .position = down, .rotation = kHorizontal}},
                                   PathInterpolation::smooth);
  EXPECT_TRUE(path.ok());
  ScriptedHandDesc d;
  d.tool = tool;
  d.path = *path;
  d.loop.rate_hz = rate_hz;
  d.loop.coupling.damping = 3.0;
  d.tool_damping = 20.0;
  return d;
}

struct PressRun {
  std::vector<float> positions;
  std::array<std::array<double, 3>, 2> tool_position{}, contact_force{};
  std::array<std::uint64_t, 2> ticks{};
  std::array<haptics::Vec3, 2> device_force{};
};

PressRun press(int frames) {
  SceneDesc scene = block_press_scene();
  scene.tools = {probe(-0.01), probe(0.01)};
  auto sim = Simulation::create(scene, {.backend = "cpu", .threads = 1, .quiet = true});
  EXPECT_TRUE(sim.ok());
  // Hand 1 at 500 Hz: its ticks interleave with hand 0's at 1 kHz.
  auto hands = ScriptedHands::create({hand(0, -0.01, 1000.0), hand(1, 0.01, 500.0)}, *sim, scene.solver.time_step);
  EXPECT_TRUE(hands.ok()) << hands.error().message();
  PressRun r;
  for (int f = 1; f <= frames; ++f) {
    EXPECT_TRUE((*hands)->before_step(*sim).ok());
    EXPECT_TRUE(sim->step().ok());
    EXPECT_TRUE((*hands)->after_step(*sim).ok());
  }
  EXPECT_TRUE(sim->read_positions(r.positions).ok());
  for (int i = 0; i < 2; ++i) {
    auto st = sim->tools().state(*sim->tools().tool(i));
    r.tool_position[i] = st->position;
    r.contact_force[i] = st->contact_force;
    r.ticks[i] = (*hands)->loop(i).counters().ticks;
    r.device_force[i] = (*hands)->device(i).last_force();
  }
  return r;
}

TEST(ScriptedHands, PressTwoProbesThroughTheirLoops) {
  const int frames = 36;  // 0.6 s at 60 Hz
  const PressRun r = press(frames);
  // Each loop ticked at its own rate over the whole run: 600 and 300 ticks.
  EXPECT_EQ(r.ticks[0], 600u);
  EXPECT_EQ(r.ticks[1], 300u);
  for (int i = 0; i < 2; ++i) {
    // The probe followed its hand down into the block (the coupling stretches a little)...
    EXPECT_LT(r.tool_position[i][2], kBlockTop + kRadius - 0.001) << "hand " << i;
    // ...the tissue pushes it up, and the device feels that push (the coupling pulls the hand up).
    EXPECT_GT(r.contact_force[i][2], 0.05) << "hand " << i;
    EXPECT_GT(r.device_force[i][2], 0.05) << "hand " << i;
  }
}

TEST(ScriptedHands, TheSameRunTwiceIsTheSameBitForBit) {
  const PressRun a = press(20), b = press(20);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_EQ(0, std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(float)));
  EXPECT_EQ(a.device_force, b.device_force);
  EXPECT_EQ(a.tool_position, b.tool_position);
}

TEST(ScriptedHands, BadHandsAreNamed) {
  SceneDesc scene = block_press_scene();
  scene.tools = {probe(0.0)};
  auto sim = Simulation::create(scene, {.backend = "cpu", .threads = 1, .quiet = true});
  ASSERT_TRUE(sim.ok());
  const auto message = [&](std::vector<ScriptedHandDesc> hands, double frame = 1.0 / 60.0) {
    auto h = ScriptedHands::create(std::move(hands), *sim, frame);
    EXPECT_FALSE(h.ok());
    return h.ok() ? std::string() : h.error().message();
  };
  EXPECT_NE(message({hand(3, 0.0, 1000.0)}).find("hands[0].tool"), std::string::npos);
  EXPECT_NE(message({hand(0, 0.0, 1000.0), hand(0, 0.0, 1000.0)}).find("hands[1].tool: tool 0 is driven by hands[0]"),
            std::string::npos);
  EXPECT_NE(message({hand(0, 0.0, 0.0)}).find("rate_hz"), std::string::npos);
  ScriptedHandDesc bad = hand(0, 0.0, 1000.0);
  bad.tool_damping = -1.0;
  EXPECT_NE(message({bad}).find("hands[0].tool_damping"), std::string::npos);
  EXPECT_NE(message({hand(0, 0.0, 1000.0)}, 0.0).find("frame_seconds"), std::string::npos);
}

}  // namespace
}  // namespace sinew::test
