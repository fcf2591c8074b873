// A laparoscopic instrument through a trocar (ToolDesc::trocar), driven by
// a scripted hand through the haptic loop (virtual clock, manual ticks) and
// the tool bridge: swept fast sideways, in and out, turned about the port,
// over a tissue block, against a slanted floor collider and in free space.
// Every frame the shaft line passes within 0.1 mm of the pivot and the
// shaft's point at the pivot has no sideways velocity; insertion and
// rotation about the pivot still follow the hand; without the trocar the
// same sweep carries the shaft centimetres off the port. Bad trocars are
// named errors, in code and in scene files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "haptics_test_support.h"
#include "sinew/haptics/tool_bridge.h"
#include "sinew/mesh.h"
#include "sinew/scene_file.h"
#include "sinew/simulation.h"

namespace {

using namespace sinew::test;
using sinew::ToolDesc;

constexpr double kPi = 3.14159265358979323846;
const Vec3 kPivot{0.0, 0.10, 0.0};
constexpr double kDepth = 0.03;  // [m] from the pivot down to the tool's centre at rest

Vec3 rotate(const Quat& q, const Vec3& v) {
  // v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z).
  const Vec3 u{q[1], q[2], q[3]};
  const auto cross = [](const Vec3& a, const Vec3& b) {
    return Vec3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  const Vec3 t = cross(u, v);
  const Vec3 ut = cross(u, t);
  return {v[0] + 2 * (q[0] * t[0] + ut[0]), v[1] + 2 * (q[0] * t[1] + ut[1]), v[2] + 2 * (q[0] * t[2] + ut[2])};
}
Quat about(const Vec3& axis, double angle) {
  const double s = std::sin(angle / 2);
  return {std::cos(angle / 2), axis[0] * s, axis[1] * s, axis[2] * s};
}
Quat qmul(const Quat& a, const Quat& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3], a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1], a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// The hand's script, phase by phase [s]:
//   0-0.5   at rest (the watchdog ramps the force up);
//   0.5-2.5 the handle swept sideways, 3 cm at 3 Hz (0.57 m/s), no turn;
//   2.5-4.5 in and out, 2.5 cm at 2 Hz (0.31 m/s), the tip into the block;
//   4.5-6.5 turned about the pivot: tilt 0.4 rad at 1.5 Hz about a turning
//           horizontal axis, and a roll of 0.6 rad at 1 Hz about the shaft;
//   6.5-7.5 the fastest sweep: 5 cm at 5 Hz (1.57 m/s);
//   7.5-9.0 held tilted 0.3 rad about z, rolled 0.5 rad, 4 cm deep.
constexpr double kHoldFrom = 7.5, kEnd = 9.0;
const Quat kHoldTurn = qmul(about({0, 0, 1}, 0.3), about({0, 1, 0}, 0.5));
constexpr double kHoldDepth = 0.04;

ScriptedPose hand(double t) {
  Quat turn{1, 0, 0, 0};
  double depth = kDepth;
  Vec3 sideways{0, 0, 0};
  if (t >= 0.5 && t < 2.5) {
    sideways = {0.03 * std::sin(2 * kPi * 3.0 * (t - 0.5)), 0, 0};
  } else if (t >= 2.5 && t < 4.5) {
    depth = kDepth + 0.025 * std::sin(2 * kPi * 2.0 * (t - 2.5));
  } else if (t >= 4.5 && t < 6.5) {
    const double s = t - 4.5, heading = 2 * kPi * 0.5 * s;
    const Quat tilt = about({std::cos(heading), 0, std::sin(heading)}, 0.4 * std::sin(2 * kPi * 1.5 * s));
    turn = qmul(tilt, about({0, 1, 0}, 0.6 * std::sin(2 * kPi * 1.0 * s)));
  } else if (t >= 6.5 && t < kHoldFrom) {
    sideways = {0.0, 0.0, 0.05 * std::sin(2 * kPi * 5.0 * (t - 6.5))};
  } else if (t >= kHoldFrom) {
    // Eased into the hold over 0.3 s.
    const double e = std::min(1.0, (t - kHoldFrom) / 0.3), w = 0.5 - 0.5 * std::cos(kPi * e);
    turn = qmul(about({0, 0, 1}, 0.3 * w), about({0, 1, 0}, 0.5 * w));
    depth = kDepth + (kHoldDepth - kDepth) * w;
  }
  ScriptedPose p;
  const Vec3 down = rotate(turn, {0, -depth, 0});  // from the pivot to the hand's tool centre
  for (int k = 0; k < 3; ++k) p.position[k] = kPivot[k] + down[k] + sideways[k];
  p.rotation = turn;
  return p;
}

constexpr double kFloorHeight = 0.005, kFloorTilt = 0.3;  // [m] at x = 0, [rad] about z
enum class Around { free_space, tissue_block, slanted_floor };

sinew::SceneDesc scene(Around around, bool trocar) {
  const bool block = around == Around::tissue_block;
  sinew::SceneDesc s;
  s.gravity = {0, -9.81, 0};
  s.solver = {.time_step = 0.004, .substeps = 4, .iterations = 4};
  if (block) {  // 6 x 3 x 6 cm, its top at y = 0, pinned at the bottom
    sinew::TetBodyDesc body;
    body.mesh = *sinew::make_tet_grid(
        {.nx = 6, .ny = 3, .nz = 6, .origin = {-0.03, -0.03, -0.03}, .cell_size = {0.01, 0.01, 0.01}});
    EXPECT_TRUE(body.set_material(sinew::TetMaterial::neo_hookean, 2e4, 0.4).ok());
    for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
      if (body.mesh.vertices[v][1] < -0.03 + 1e-9) body.pinned.push_back(v);
    s.tet_bodies.push_back(body);
  }
  if (around == Around::slanted_floor) {  // a plane 5 mm above y = 0, tilted 0.3 rad: it pushes the tip up and sideways
    sinew::ColliderDesc floor;
    floor.position = {0.0, kFloorHeight, 0.0};
    floor.rotation = about({0, 0, 1}, kFloorTilt);
    s.colliders.push_back(floor);
  }
  ToolDesc tool;  // a 10 cm shaft (the capsule's y), its centre 3 cm below the port, the tip 2 cm above the block
  tool.radius = 0.004;
  tool.half_height = 0.05;
  tool.mass = 0.2;
  tool.inertia = {2e-4, 2e-5, 2e-4};
  tool.gravity = false;
  tool.position = {kPivot[0], kPivot[1] - kDepth, kPivot[2]};
  if (trocar) tool.trocar = sinew::TrocarDesc{.pivot = kPivot, .axis = {0, 1, 0}};
  s.tools.push_back(tool);
  return s;
}

struct Figures {
  double max_pivot_distance = 0.0;  // [m] pivot to shaft line, every frame
  double max_pivot_distance_fastest = 0.0;  // in the 5 cm, 5 Hz sweep
  double max_sideways_speed = 0.0;  // [m/s] of the shaft's point at the pivot
  double max_tool_speed = 0.0;      // [m/s] of the tool's centre
  double max_tip_speed = 0.0;       // [m/s] of its lower end
  double max_tilt_sweep = 0.0;      // [rad] of the shaft during the first sweep
  double max_trocar_force = 0.0;    // [N]
  double max_contact_force = 0.0;   // [N] the tissue's push on the tool
  double min_floor_distance = 1.0;  // [m] from the slanted floor's plane to the tip's end point
  double depth_min = 1.0, depth_max = 0.0;  // [m] the centre below the port, in and out
  double hold_turn_error = 0.0;     // [rad] the tool's rotation against the hand's at the end
  double hold_depth_error = 0.0;    // [m]
};

Figures drive(Around around, bool trocar) {
  Figures f;
  auto sim = sinew::Simulation::create(scene(around, trocar), {.backend = "cpu", .threads = 1, .quiet = true});
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  if (!sim.ok()) return f;
  ScriptedDevice device(hand);
  VirtualRig rig(device);
  rig.publishing = false;  // the bridge publishes, after each frame
  HapticToolBridge bridge(0, rig.snapshots, rig.feedback, rig.clock);
  EXPECT_TRUE(bridge.set_damping(3.0, 2e-3).ok());
  EXPECT_TRUE(bridge.publish(*sim).ok());
  const int frames = static_cast<int>(kEnd / 0.004 + 0.5);
  for (int frame = 0; frame < frames; ++frame) {
    for (int i = 0; i < 4; ++i) rig.loop->tick(), rig.clock.advance(kMs);
    EXPECT_TRUE(bridge.apply_feedback(*sim).ok());
    EXPECT_TRUE(sim->step().ok());
    EXPECT_TRUE(bridge.publish(*sim).ok());
    const auto s = sim->tool_state(0);
    const double t = rig.clock.now_ns() * 1e-9;
    const Vec3 c = s->position, u = rotate(s->rotation, {0, 1, 0});
    const Vec3 to_pivot{kPivot[0] - c[0], kPivot[1] - c[1], kPivot[2] - c[2]};
    const double along = dot(u, to_pivot);
    Vec3 across{};
    for (int k = 0; k < 3; ++k) across[k] = to_pivot[k] - u[k] * along;
    const double distance = std::sqrt(dot(across, across));
    f.max_pivot_distance = std::max(f.max_pivot_distance, distance);
    if (t >= 6.5 && t < kHoldFrom) f.max_pivot_distance_fastest = std::max(f.max_pivot_distance_fastest, distance);
    // The shaft's point at the pivot: v + w x r, r = u (u . (p - c)).
    const Vec3& v = s->velocity;
    const Vec3& w = s->angular_velocity;
    const Vec3 r{u[0] * along, u[1] * along, u[2] * along};
    Vec3 vp{v[0] + w[1] * r[2] - w[2] * r[1], v[1] + w[2] * r[0] - w[0] * r[2], v[2] + w[0] * r[1] - w[1] * r[0]};
    const double slide = dot(vp, u);
    for (int k = 0; k < 3; ++k) vp[k] -= slide * u[k];
    f.max_sideways_speed = std::max(f.max_sideways_speed, std::sqrt(dot(vp, vp)));
    f.max_tool_speed = std::max(f.max_tool_speed, std::sqrt(dot(v, v)));
    const Vec3 tip_r{-0.05 * u[0], -0.05 * u[1], -0.05 * u[2]};
    const Vec3 vt{v[0] + w[1] * tip_r[2] - w[2] * tip_r[1], v[1] + w[2] * tip_r[0] - w[0] * tip_r[2],
                  v[2] + w[0] * tip_r[1] - w[1] * tip_r[0]};
    f.max_tip_speed = std::max(f.max_tip_speed, std::sqrt(dot(vt, vt)));
    if (t >= 0.5 && t < 2.5) f.max_tilt_sweep = std::max(f.max_tilt_sweep, std::acos(std::clamp(u[1], -1.0, 1.0)));
    if (t >= 2.5 && t < 4.5) {
      f.depth_min = std::min(f.depth_min, along);
      f.depth_max = std::max(f.depth_max, along);
    }
    f.max_trocar_force = std::max(f.max_trocar_force, std::sqrt(dot(s->trocar_force, s->trocar_force)));
    const double n0 = -std::sin(kFloorTilt), n1 = std::cos(kFloorTilt);  // the floor's normal
    const Vec3 tip{c[0] - 0.05 * u[0], c[1] - 0.05 * u[1], c[2] - 0.05 * u[2]};
    f.min_floor_distance = std::min(f.min_floor_distance, n0 * tip[0] + n1 * (tip[1] - kFloorHeight));
    f.max_contact_force = std::max(f.max_contact_force, std::sqrt(dot(s->contact_force, s->contact_force)));
    if (frame == frames - 1) {
      const Quat& q = s->rotation;
      const Quat rel = qmul(q, {kHoldTurn[0], -kHoldTurn[1], -kHoldTurn[2], -kHoldTurn[3]});
      f.hold_turn_error = 2 * std::acos(std::min(1.0, std::abs(rel[0])));
      f.hold_depth_error = std::abs(along - kHoldDepth);
    }
  }
  return f;
}

void report(const char* where, const Figures& f) {
  std::printf("%s: pivot to shaft line max %.3g m (fastest sweep %.3g m); sideways speed at the pivot max %.3g m/s; "
              "tool centre up to %.3g m/s, tip up to %.3g m/s; tilt in the sweep %.3g rad; port force up to %.3g N; "
              "tissue's push up to %.3g N; tip to the slanted floor's plane min %.4g m; insertion %.4g..%.4g m; "
              "hold: rotation error %.3g rad, depth error %.3g m\n",
              where, f.max_pivot_distance, f.max_pivot_distance_fastest, f.max_sideways_speed, f.max_tool_speed,
              f.max_tip_speed, f.max_tilt_sweep, f.max_trocar_force, f.max_contact_force, f.min_floor_distance,
              f.depth_min, f.depth_max, f.hold_turn_error, f.hold_depth_error);
}

void expect_held_and_following(const Figures& f, bool free_hold = true) {
  EXPECT_LE(f.max_pivot_distance, 1e-4) << "the shaft within 0.1 mm of the pivot every frame";
  EXPECT_LE(f.max_sideways_speed, 1e-9) << "no sideways velocity at the port [m/s]";
  EXPECT_GT(f.max_tip_speed, 0.5) << "fast motion was exercised [m/s]";
  EXPECT_GT(f.max_tilt_sweep, 0.15) << "a sideways push on the handle turned the shaft about the port [rad]";
  EXPECT_GT(f.max_trocar_force, 0.1) << "the port pushed [N]";
  EXPECT_GT(f.depth_max - f.depth_min, 0.025) << "insertion followed the hand in and out (5 cm range)";
  EXPECT_LT(f.hold_turn_error, 0.03) << "tilt and roll about the port followed the hand [rad]";
  if (free_hold) {
    EXPECT_LT(f.hold_depth_error, 2e-3) << "insertion depth followed the hand [m]";
  }
}

TEST(Trocar, HoldsTheShaftThroughThePivotInFreeSpace) {
  const Figures f = drive(Around::free_space, true);
  report("trocar, free space", f);
  expect_held_and_following(f);
}

TEST(Trocar, HoldsTheShaftThroughThePivotOverATissueBlock) {
  const Figures f = drive(Around::tissue_block, true);
  report("trocar, over a tissue block", f);
  expect_held_and_following(f);
  EXPECT_GT(f.max_contact_force, 0.5) << "the tip pressed into the tissue [N]";
}

// A collider pushing the tip up and sideways moves the tool after its
// motion is integrated; the port is held again after it.
TEST(Trocar, HoldsTheShaftThroughThePivotAgainstASlantedFloor) {
  const Figures f = drive(Around::slanted_floor, true);
  report("trocar, against a slanted floor", f);
  expect_held_and_following(f, false);  // the floor holds the tip short of the hand's last depth
  // The tip's end point (a sphere of 4 mm radius) rested on the floor, not in it.
  EXPECT_GT(f.min_floor_distance, 0.004 - 1e-4);
  EXPECT_LT(f.min_floor_distance, 0.004 + 1e-4);
}

// The same hand without a trocar carries the shaft far off the pivot: the
// test above can fail.
TEST(Trocar, WithoutOneTheSameSweepLeavesThePivot) {
  const Figures f = drive(Around::free_space, false);
  report("no trocar, free space", f);
  EXPECT_GT(f.max_pivot_distance, 0.01);
}

std::string create_error(const sinew::SceneDesc& s) {
  auto sim = sinew::Simulation::create(s, {.backend = "cpu", .threads = 1, .quiet = true});
  return sim ? std::string("(no error)") : sim.error().message();
}

TEST(Trocar, BadTrocarsAreNamed) {
  const double nan = std::nan("");
  sinew::SceneDesc s = scene(Around::free_space, true);
  s.tools[0].trocar->pivot = {0.0, nan, 0.0};
  EXPECT_NE(create_error(s).find("tools[0].trocar.pivot[1] must be finite"), std::string::npos) << create_error(s);
  s = scene(Around::free_space, true);
  s.tools[0].trocar->axis = {0.0, 0.0, 0.0};
  EXPECT_NE(create_error(s).find("tools[0].trocar.axis must be non-zero"), std::string::npos) << create_error(s);
  s.tools[0].trocar->axis = {std::numeric_limits<double>::infinity(), 1.0, 0.0};
  EXPECT_NE(create_error(s).find("tools[0].trocar.axis[0] must be finite"), std::string::npos) << create_error(s);
  s = scene(Around::free_space, true);
  s.tools[0].trocar->pivot = {0.01, 0.10, 0.0};  // 1 cm off the shaft line
  EXPECT_NE(create_error(s).find("tools[0].trocar: the tool's initial shaft line"), std::string::npos)
      << create_error(s);
  // A non-unit axis is normalised; an initial pose within the tolerance is projected.
  s = scene(Around::free_space, true);
  s.tools[0].trocar->axis = {0.0, 3.0, 0.0};
  s.tools[0].trocar->pivot = {5e-6, 0.10, 0.0};
  auto sim = sinew::Simulation::create(s, {.backend = "cpu", .threads = 1, .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  EXPECT_DOUBLE_EQ(sim->tool_state(0)->position[0], 5e-6);
}

TEST(Trocar, SceneFilesReadIt) {
  const std::string tool = R"({"tools": [{"position": [0, 0.07, 0], "gravity": false, )";
  auto file = sinew::parse_scene_json(tool + R"("trocar": {"pivot": [0, 0.1, 0], "axis": [0, 2, 0]}}]})", ".");
  ASSERT_TRUE(file.ok()) << file.error().message();
  ASSERT_TRUE(file->scene.tools[0].trocar.has_value());
  EXPECT_EQ(file->scene.tools[0].trocar->pivot, (std::array<double, 3>{0, 0.1, 0}));
  EXPECT_EQ(file->scene.tools[0].trocar->axis, (std::array<double, 3>{0, 2, 0}));
  auto missing = sinew::parse_scene_json(tool + R"("trocar": {"axis": [0, 1, 0]}}]})", ".");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message().find("/tools/0/trocar/pivot: is required"), std::string::npos)
      << missing.error().message();
  auto unknown = sinew::parse_scene_json(tool + R"("trocar": {"pivot": [0, 0.1, 0], "axes": [0, 1, 0]}}]})", ".");
  ASSERT_FALSE(unknown.ok());
  auto off = sinew::parse_scene_json(tool + R"("trocar": {"pivot": [0.02, 0.1, 0]}}]})", ".");
  ASSERT_FALSE(off.ok());
  EXPECT_NE(off.error().message().find("/tools/0/trocar: the tool's initial shaft line"), std::string::npos)
      << off.error().message();
}

TEST(Trocar, ItsPushIsPartOfASavedState) {
  // A sideways push on the handle: the port pushes back, and a state saved
  // then restores that reported push (into the same and a new Simulation).
  const sinew::SceneDesc s = scene(Around::free_space, true);
  auto sim = sinew::Simulation::create(s, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const auto push = [&](double fx) {
    ASSERT_TRUE(sim->apply_tool_force(0, {fx, 0.0, 0.0}, {0.0, 0.0, 0.0}).ok());
    ASSERT_TRUE(sim->step().ok());
  };
  push(0.5);
  const Vec3 saved_push = sim->tool_state(0)->trocar_force;
  ASSERT_GT(std::abs(saved_push[0]), 0.0);
  sinew::SavedState state;
  ASSERT_TRUE(sim->save_state(state).ok());
  push(-2.0);
  push(-2.0);
  ASSERT_NE(sim->tool_state(0)->trocar_force, saved_push);
  ASSERT_TRUE(sim->restore_state(state).ok());
  EXPECT_EQ(sim->tool_state(0)->trocar_force, saved_push);
  auto fresh = sinew::Simulation::create(s, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(fresh.ok());
  ASSERT_TRUE(fresh->restore_state(state).ok());
  EXPECT_EQ(fresh->tool_state(0)->trocar_force, saved_push);
}

}  // namespace
