// Two hands on one scene: two haptic loops, each with its own device (one
// scripted, one replaying a recorded trajectory), channels and tool bridge,
// pressing two probes into one tissue block; ticked on a virtual clock, and
// on their own threads beside the physics thread.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "haptics_block_scene.h"
#include "haptics_test_support.h"
#include "sinew/haptics/local_contact_builder.h"
#include "sinew/haptics/replay_device.h"
#include "sinew/haptics/tool_bridge.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace sinew::test {
namespace {

constexpr double kTop = kBlockTop, kRadius = 0.004, kStart = 0.002, kSpeed = 0.02, kDepth = 0.003;
const Quat kHorizontal{M_SQRT1_2, 0.0, 0.0, M_SQRT1_2};  // a capsule's y axis along x
constexpr std::array<double, 2> kProbeY{-0.01, 0.01};    // [m] where each hand presses

// The device's height below the block's top [m] at t [s] (<= 0: above).
double depth(double t) { return std::min(kSpeed * std::max(t - 0.05, 0.0), kStart + kDepth) - kStart; }

Vec3 hand_position(int hand, double t) { return {0.0, kProbeY[hand], kTop + kRadius - depth(t)}; }

SceneDesc two_probe_scene() {
  SceneDesc scene = block_press_scene();
  for (int hand = 0; hand < 2; ++hand) {
    ToolDesc probe;
    probe.radius = kRadius;
    probe.half_height = 0.008;
    probe.mass = 0.3;
    probe.inertia = {1e-4, 1e-4, 1e-4};
    probe.position = hand_position(hand, 0.0);
    probe.rotation = kHorizontal;
    probe.gravity = false;
    scene.tools.push_back(probe);
  }
  return scene;
}

// Hand 1's trajectory, recorded every millisecond from the same press.
std::vector<TrajectorySample> recorded_press() {
  std::vector<TrajectorySample> out;
  for (int k = 0; k <= 1000; ++k) {
    const double t = 1e-3 * k;
    out.push_back({.time = t, .position = hand_position(1, t), .rotation = kHorizontal});
  }
  return out;
}

// Both hands, their loops, channels and bridges.
struct TwoHands {
  std::array<SnapshotChannel, 2> snapshots;
  std::array<FeedbackChannel, 2> feedback;
  std::unique_ptr<ScriptedDevice> scripted;
  std::unique_ptr<ReplayDevice> replay;
  std::array<std::unique_ptr<HapticLoop>, 2> loops;
  std::array<std::unique_ptr<HapticToolBridge>, 2> bridges;

  TwoHands(const SceneDesc& scene, Simulation& sim, Clock& clock, bool threads) {
    scripted = std::make_unique<ScriptedDevice>([](double t) {
      ScriptedPose p;
      p.position = hand_position(0, t);
      p.rotation = kHorizontal;
      return p;
    });
    auto r = ReplayDevice::create(recorded_press());
    EXPECT_TRUE(r.ok());
    replay = std::make_unique<ReplayDevice>(std::move(*r));
    for (int hand = 0; hand < 2; ++hand) {
      HapticLoopSettings hs;
      hs.realtime = false;
      hs.coupling.damping = 3.0;
      hs.local_contacts = hand == 1;  // the second hand feels the tissue through the local model
      HapticDevice& device = hand == 0 ? static_cast<HapticDevice&>(*scripted) : *replay;
      auto loop = HapticLoop::create(hs, device, snapshots[hand], feedback[hand], clock);
      EXPECT_TRUE(loop.ok());
      loops[hand] = std::move(*loop);
      bridges[hand] = std::make_unique<HapticToolBridge>(hand, snapshots[hand], feedback[hand], clock);
      EXPECT_TRUE(bridges[hand]->set_damping(20.0, 2e-3).ok());
      if (hand == 1) {
        auto b = haptics::LocalContactBuilder::create(scene, sim.info(), 1);
        EXPECT_TRUE(b.ok());
        EXPECT_TRUE(bridges[hand]->set_local_contacts(std::move(*b)).ok());
      }
      EXPECT_TRUE(bridges[hand]->publish(sim).ok());
    }
    if (threads) {
      const std::int64_t now = clock.now_ns();
      scripted->set_origin(now);
      replay->set_origin(now);
      for (auto& l : loops) EXPECT_TRUE(l->start().ok());
    } else {
      EXPECT_TRUE(scripted->start(0).ok());
      EXPECT_TRUE(replay->start(0).ok());
    }
  }
  void frame(Simulation& sim) {
    for (auto& b : bridges) EXPECT_TRUE(b->apply_feedback(sim).ok());
    EXPECT_TRUE(sim.step().ok());
    for (auto& b : bridges) EXPECT_TRUE(b->publish(sim).ok());
  }
};

double contact_force_z(Simulation& sim, std::size_t tool) {
  return sim.tools().state(*sim.tools().tool(tool))->contact_force[2];
}

TEST(TwoHands, BothHandsPressAndFeelTheTissueOnAVirtualClock) {
  const SceneDesc scene = two_probe_scene();
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok());
  VirtualClock clock{0};
  TwoHands hands(scene, *sim, clock, false);
  for (int f = 1; f <= 36; ++f) {  // 0.6 s
    const std::int64_t end = std::llround(f * 1e9 / 60.0);
    for (std::int64_t t = (clock.now_ns() / kMs + 1) * kMs; t <= end; t += kMs) {
      clock.set(t);
      for (auto& l : hands.loops) (void)l->tick();
    }
    clock.set(end);
    hands.frame(*sim);
  }
  // Each tool is pressed into the block by its own hand, and each hand is
  // pushed back by its own tool.
  for (std::size_t hand = 0; hand < 2; ++hand) {
    const auto c = hands.loops[hand]->counters();
    EXPECT_EQ(c.ticks, 600u);
    EXPECT_EQ(c.device_failures, 0u);
    EXPECT_GT(contact_force_z(*sim, hand), 0.05) << "hand " << hand;
    std::vector<TickRecord> ticks;
    ASSERT_TRUE(hands.loops[hand]->copy_telemetry(ticks).ok());
    EXPECT_NEAR(ticks.back().device_position[1], kProbeY[hand], 1e-12);
    EXPECT_GT(ticks.back().force[2], 0.05) << "hand " << hand;
  }
  EXPECT_GT(hands.scripted->last_force()[2], 0.05);
  EXPECT_GT(hands.replay->last_force()[2], 0.05);
  // The probes press symmetric spots: their forces agree within 10%.
  EXPECT_NEAR(contact_force_z(*sim, 0), contact_force_z(*sim, 1), 0.1 * contact_force_z(*sim, 0));
}

TEST(TwoHands, TwoLoopThreadsBesideThePhysicsThread) {
  // Each loop on its own thread at 1 kHz of wall time while this thread
  // steps the physics as fast as it can: both hands are served and press.
  const SceneDesc scene = two_probe_scene();
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok());
  MonotonicClock clock;
  TwoHands hands(scene, *sim, clock, true);
  const auto start = std::chrono::steady_clock::now();
  int frames = 0;
  while (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(700)) {
    hands.frame(*sim);
    ++frames;
  }
  for (auto& l : hands.loops) l->stop();
  for (std::size_t hand = 0; hand < 2; ++hand) {
    const auto c = hands.loops[hand]->counters();
    EXPECT_GT(c.ticks, 20u) << "hand " << hand;  // ~700 at 1 kHz; a loaded machine delays some
    EXPECT_EQ(c.device_failures, 0u);
    EXPECT_GT(c.snapshots_received, 1u);
  }
  // Each tool followed its hand down (how far depends on how many frames
  // the machine ran), driven by its own loop's feedback (a frame shorter
  // than a tick finds no new tick and applies nothing: counted, not asserted).
  for (std::size_t hand = 0; hand < 2; ++hand) {
    EXPECT_LT(sim->tools().state(*sim->tools().tool(hand))->position[2], scene.tools[hand].position[2]);
    EXPECT_LT(hands.bridges[hand]->frames_without_feedback(), std::uint64_t(frames));
  }
  std::printf("two loop threads: %llu and %llu ticks over %d frames\n",
              static_cast<unsigned long long>(hands.loops[0]->counters().ticks),
              static_cast<unsigned long long>(hands.loops[1]->counters().ticks), frames);
}

}  // namespace
}  // namespace sinew::test
