// level_set_tool_test.cpp — rigid tools shaped by a level set (issue 14,
// part 3; ToolShape::level_set): a burr's penalty against a plane, an
// analytic box and a level-set bone is Archimedes' (the stiffness times the
// volume inside the face) at rest; pressed into tissue it rests where a
// capsule tool of its shape rests (every backend); a membrane's faces hold
// it between the vertices; two tools feel equal and opposite forces; driven
// through the haptic loop's virtual coupling into a level-set bone, the
// force rendered to the device is the bone's push; bad tools are named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "haptics_test_support.h"
#include "mesh_contact_support.h"
#include "sinew/haptics/tool_bridge.h"
#include "sinew/level_set.h"
#include "sinew/simulation.h"
#include "test_support.h"

namespace sinew::test {
namespace {

#if SINEW_HAS_OPENVDB

using V3 = std::array<double, 3>;
constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

// A solid sphere of `radius` about the origin, every voxel inside stored.
LevelSet solid_sphere(double radius, double voxel) {
  auto s = LevelSet::sphere({0, 0, 0}, radius, {.voxel_size = voxel, .exterior_band = 3 * voxel, .interior_band = kInf});
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message());
  return *s;
}

// A burr: a sphere of radius R, mass m, its penalty damped near critically.
ToolDesc burr(double radius, double mass, double stiffness, double damping, const V3& at) {
  ToolDesc t;
  t.shape = ToolShape::level_set;
  t.level_set = solid_sphere(radius, radius / 12);
  t.penalty_stiffness = stiffness;
  t.penalty_damping = damping;
  t.mass = mass;
  const double i = 0.4 * mass * radius * radius;
  t.inertia = {i, i, i};
  t.position = at;
  return t;
}

// Archimedes: a pressure k d over a closed shell pressed delta into a flat
// face pushes with k times the volume inside, a sphere's cap pi delta^2 (R - delta / 3).
double cap_force(double k, double radius, double delta) { return k * kPi * delta * delta * (radius - delta / 3); }
// ... and the depth at which that is f (bisection: the force grows with depth).
double cap_depth(double k, double radius, double f) {
  double lo = 0, hi = radius;
  for (int i = 0; i < 100; ++i) (cap_force(k, radius, 0.5 * (lo + hi)) < f ? lo : hi) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

// A solid level-set block of bone, 2 cm wide, its top face at y = 0 (voxel 0.25 mm).
ColliderDesc bone_block() {
  ColliderDesc bone;
  bone.shape = ColliderShape::level_set;
  auto grid = LevelSet::box({-0.01, -0.01, -0.01}, {0.01, 0.0, 0.01},
                            {.voxel_size = 2.5e-4, .exterior_band = 1e-3, .interior_band = kInf});
  EXPECT_TRUE(grid.ok()) << (grid.ok() ? "" : grid.error().message());
  if (grid.ok()) bone.level_set = *grid;
  return bone;
}

struct Rest {
  double force = 0, depth = 0, y = 0, spread = 0;  // means over the last frames; spread: max - min of y
};

// Steps `frames`, pushing tool 0 with `push` each frame; averages the last quarter.
Rest settle(Simulation& sim, int frames, const V3& push = {0, 0, 0}) {
  Rest r;
  double lo = 1e30, hi = -1e30;
  const int from = frames - frames / 4;
  for (int f = 1; f <= frames; ++f) {
    EXPECT_TRUE(sim.apply_tool_force(0, push, {0, 0, 0}).ok());
    EXPECT_TRUE(sim.step().ok());
    auto s = sim.tool_state(0);
    EXPECT_TRUE(s.ok());
    if (f <= from) continue;
    const double n = frames - from;
    r.force += s->penalty_force[1] / n;
    r.depth += s->penalty_depth / n;
    r.y += s->position[1] / n;
    lo = std::min(lo, s->position[1]);
    hi = std::max(hi, s->position[1]);
  }
  r.spread = hi - lo;
  return r;
}

// A 3 mm burr of 10 g at 1 kHz: k = 5e8 N/m^3 holds its weight 0.28 mm
// deep (contact stiffness 2 k pi R delta = 700 N/m, sqrt(k / m) dt = 0.26).
constexpr double kR = 0.003, kMass = 0.01, kK = 5e8;
// Damping near critical: c times the cap's area 2 pi R delta ~ 2 sqrt(k_contact m).
constexpr double kC = 1.2e6;

SceneDesc burr_over(const ColliderDesc& ground) {
  SceneDesc scene;
  scene.solver = {.time_step = 1e-3, .substeps = 1, .iterations = 1};
  scene.colliders.push_back(ground);
  scene.tools.push_back(burr(kR, kMass, kK, kC, {0.0, kR + 2e-4, 0.0}));
  return scene;
}

TEST(LevelSetTool, ABurrRestsOnPlaneBoxAndLevelSetBoneWhereArchimedesSays) {
  // Each face's top at y = 0: a plane, an analytic box and a level-set box
  // (voxel 0.25 mm). At rest the penalty carries the weight (1%), and the
  // burr's centre is R - delta above the face, delta from k V(delta) = m g,
  // within a tenth of the burr's voxel (the point shell is discrete).
  ColliderDesc plane;
  ColliderDesc box;
  box.shape = ColliderShape::box;
  box.half_extents = {0.01, 0.005, 0.01};
  box.position = {0, -0.005, 0};
  const ColliderDesc bone = bone_block();
  const double weight = kMass * 9.81, delta = cap_depth(kK, kR, weight);
  for (const ColliderDesc& ground : {plane, box, bone}) {
    auto sim = Simulation::create(burr_over(ground), {.backend = "cpu", .quiet = true});
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    const Rest r = settle(*sim, 1000);
    std::printf("[ measured ] %s: penalty %.5f N for a weight of %.5f N; centre %.4f mm above the face, "
                "Archimedes %.4f mm; deepest point %.4f mm; rocks %.2g mm\n",
                ground.shape == ColliderShape::plane ? "plane" : ground.shape == ColliderShape::box ? "box" : "level set",
                r.force, weight, 1e3 * r.y, 1e3 * (kR - delta), 1e3 * r.depth, 1e3 * r.spread);
    EXPECT_NEAR(r.force, weight, 0.01 * weight);
    EXPECT_NEAR(r.y, kR - delta, kR / 120);
    EXPECT_LT(r.spread, 1e-5) << "at rest";
  }
}

TEST(LevelSetTool, TwoToolsFeelEqualAndOppositePenalties) {
  // A burr pushed into a capsule tool (gravity off, nothing else): the
  // capsule feels minus the burr's force, and their moments about a common
  // point cancel (the penalty is a set of equal and opposite point forces).
  SceneDesc scene;
  scene.gravity = {0, 0, 0};
  scene.solver = {.time_step = 1e-3, .substeps = 1, .iterations = 1};
  ToolDesc rod;
  rod.radius = 0.004;
  rod.half_height = 0.02;
  rod.mass = 0.05;
  rod.gravity = false;
  rod.position = {0, -0.004, 0.003};
  rod.rotation = {std::sqrt(0.5), 0, 0, std::sqrt(0.5)};  // its axis along x
  scene.tools.push_back(burr(kR, kMass, kK, kC, {0.002, kR + 1e-4, 0}));
  scene.tools[0].gravity = false;
  scene.tools.push_back(rod);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  int touching = 0, turned = 0;
  V3 start_a = scene.tools[0].position, start_b = scene.tools[1].position;  // where each frame starts
  for (int f = 0; f < 50; ++f) {
    SINEW_ASSERT_OK(sim->apply_tool_force(0, {0, -0.5, 0}, {0, 0, 0}));
    SINEW_ASSERT_OK(sim->step());
    auto a = sim->tool_state(0), b = sim->tool_state(1);
    ASSERT_TRUE(a.ok() && b.ok());
    if (a->penalty_points > 0) {
      ++touching;
      EXPECT_GE(a->penalty_force[1], 0.0) << "the rod pushes the burr up (or nothing, moving apart)";
      // The penalty belongs to the frame's start: the moments about the
      // origin use the centres there, x x F + the torque about the centre.
      const V3 fa = a->penalty_force, fb = b->penalty_force, ta = a->penalty_torque, tb = b->penalty_torque;
      const V3 ma{start_a[1] * fa[2] - start_a[2] * fa[1] + ta[0], start_a[2] * fa[0] - start_a[0] * fa[2] + ta[1],
                  start_a[0] * fa[1] - start_a[1] * fa[0] + ta[2]};
      const V3 mb{start_b[1] * fb[2] - start_b[2] * fb[1] + tb[0], start_b[2] * fb[0] - start_b[0] * fb[2] + tb[1],
                  start_b[0] * fb[1] - start_b[1] * fb[0] + tb[2]};
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(fa[k], -fb[k], 1e-12 + 1e-12 * std::abs(fa[k]));
        EXPECT_NEAR(ma[k], -mb[k], 1e-14 + 1e-12 * std::abs(ma[k]));
      }
      if (fa[1] > 0.01) {
        // Pressed 2 mm along x from the rod's centre: turned about z by about 2 mm x the force.
        EXPECT_NEAR(tb[2], -0.002 * fa[1], 0.2 * 0.002 * fa[1]) << "off the rod's centre: the rod is turned";
        ++turned;
      }
    }
    start_a = a->position;
    start_b = b->position;
  }
  EXPECT_GT(touching, 10);
  EXPECT_GT(turned, 5);
}

TEST(LevelSetTool, ABurrDrivenThroughTheHapticCouplingRendersTheBonesPush) {
  // A 2 mm burr of 20 g on the virtual coupling (K = 500 N/m, physics and
  // haptics at 1 kHz on a virtual clock); the device goes 2 mm below a
  // level-set bone's face and stays. At rest the device feels what the bone
  // pushes the burr with (1%), that is K (2 mm - delta) with k V(delta)
  // equal to it (Archimedes, 3%), steadily (its last 100 ticks within 1%).
  const double radius = 0.002, k = 2.66e9;
  SceneDesc scene;
  scene.gravity = {0, 0, 0};
  scene.solver = {.time_step = 1e-3, .substeps = 1, .iterations = 1};
  const ColliderDesc bone = bone_block();
  scene.colliders.push_back(bone);
  const double start = radius + 1e-3;
  scene.tools.push_back(burr(radius, 0.02, k, 2e6, {0, start, 0}));
  scene.tools[0].gravity = false;
  // The burr's handpiece, about 10 cm long: a ball's own inertia (3e-8 kg
  // m^2) is too small for the coupling's rotational damping at 1 kHz
  // (B_r dt / I = 15 > 2 spins it up; tool_bridge.h).
  scene.tools[0].inertia = {2e-5, 2e-6, 2e-5};
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();

  const double target = radius - 0.002;  // the device's point 2 mm below the face
  ScriptedDevice device([&](double t) {
    ScriptedPose p;
    const double s = std::min(1.0, t / 0.3);
    p.position = {0, start + (target - start) * (0.5 - 0.5 * std::cos(kPi * s)), 0};
    return p;
  });
  SINEW_ASSERT_OK(device.start(0));
  VirtualClock clock{0};
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  HapticLoopSettings settings;
  settings.realtime = false;
  auto loop = HapticLoop::create(settings, device, snapshots, feedback, clock);
  ASSERT_TRUE(loop.ok()) << loop.error().message();
  HapticToolBridge bridge(0, snapshots, feedback, clock);
  SINEW_ASSERT_OK(bridge.set_damping(2.0, 1e-4));
  SINEW_ASSERT_OK(bridge.publish(*sim));
  double felt = 0, pushed = 0, lo = 1e30, hi = -1e30;
  constexpr int kTicks = 1500;
  for (int tick = 1; tick <= kTicks; ++tick) {
    SINEW_ASSERT_OK(bridge.apply_feedback(*sim));
    SINEW_ASSERT_OK(sim->step());
    SINEW_ASSERT_OK(bridge.publish(*sim));
    const TickRecord r = (*loop)->tick();
    clock.advance(kMs);
    if (tick <= kTicks - 100) continue;
    auto s = sim->tool_state(0);
    ASSERT_TRUE(s.ok());
    felt += r.force[1] / 100;
    pushed += s->penalty_force[1] / 100;
    lo = std::min(lo, r.force[1]);
    hi = std::max(hi, r.force[1]);
  }
  // Equilibrium: K (2 mm - delta) = k V(delta).
  double a = 0, b = 0.002;
  for (int i = 0; i < 100; ++i) {
    const double m = 0.5 * (a + b);
    (cap_force(k, radius, m) < settings.coupling.stiffness * (0.002 - m) ? a : b) = m;
  }
  const double expected = cap_force(k, radius, a);
  std::printf("[ measured ] device feels %.4f N, the bone pushes the burr %.4f N, Archimedes %.4f N; "
              "last 100 ticks %.4f..%.4f N\n",
              felt, pushed, expected, lo, hi);
  EXPECT_NEAR(felt, pushed, 0.01 * pushed);
  EXPECT_NEAR(felt, expected, 0.03 * expected);
  EXPECT_LT(hi - lo, 0.01 * felt);
}

TEST(LevelSetTool, BadLevelSetToolsAreNamed) {
  SceneDesc scene = burr_over(ColliderDesc{});
  auto fails_with = [&](const SceneDesc& s, const std::string& what) {
    auto sim = Simulation::create(s, {.backend = "cpu", .quiet = true});
    ASSERT_FALSE(sim.ok()) << what;
    EXPECT_NE(sim.error().message().find(what), std::string::npos) << sim.error().message();
  };
  SceneDesc s = scene;
  s.tools[0].level_set.reset();
  fails_with(s, "tools[0].level_set is missing");
  s = scene;
  s.tools[0].penalty_stiffness = 0;
  fails_with(s, "tools[0].penalty_stiffness");
  s = scene;
  s.tools[0].penalty_stiffness = std::nan("");
  fails_with(s, "tools[0].penalty_stiffness");
  s = scene;
  s.tools[0].penalty_damping = -1;
  fails_with(s, "tools[0].penalty_damping");
  s = scene;
  s.tools[0].shape = ToolShape::capsule;
  fails_with(s, "tools[0].level_set is set but the shape is not ToolShape::level_set");
}

// A burr that cuts (ToolDesc::cuts) drills down into a level-set block
// pushed with 2 N: after each frame the block loses what its cutter swept
// over the frame, exactly what Tools::cut from the frame's start pose to
// its end pose removes (a scene without cuts, cut by hand the same way,
// runs bitwise alike), and the removed volume is the swept capsule's below
// the block's top face.
TEST(LevelSetTool, ACuttingBurrDrillsWhatItSweeps) {
  constexpr double kCutter = kR - 1e-4;  // removes what the burr presses deeper than 0.1 mm
  const auto scene = [](bool cuts) {
    SceneDesc s = burr_over(bone_block());
    s.gravity = {0.0, 0.0, 0.0};
    if (cuts) s.tools[0].cuts = ToolCutDesc{.collider = 0, .cutter = {.radius = kCutter}};
    return s;
  };
  auto with = Simulation::create(scene(true), {.backend = "cpu", .quiet = true});
  auto by_hand = Simulation::create(scene(false), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(with.ok()) << with.error().message();
  ASSERT_TRUE(by_hand.ok()) << by_hand.error().message();
  const ToolId tool = *with->tools().tool(0), tool_b = *by_hand->tools().tool(0);
  const ColliderId bone = *by_hand->tools().collider(0);
  Pose from{.position = {0.0, kR + 2e-4, 0.0}};
  double removed = 0.0, removed_by_hand = 0.0;
  for (int f = 0; f < 300; ++f) {
    ASSERT_TRUE(with->tools().apply_force(tool, {0.0, -2.0, 0.0}, {0.0, 0.0, 0.0}).ok());
    ASSERT_TRUE(by_hand->tools().apply_force(tool_b, {0.0, -2.0, 0.0}, {0.0, 0.0, 0.0}).ok());
    ASSERT_TRUE(with->step().ok());
    ASSERT_TRUE(by_hand->step().ok());
    const ToolState a = *with->tools().state(tool), b = *by_hand->tools().state(tool_b);
    ASSERT_EQ(a.position, b.position) << "frame " << f;
    const Pose to{.position = b.position, .rotation = b.rotation};
    auto cut = by_hand->tools().cut(bone, {.radius = kCutter}, from, to);
    ASSERT_TRUE(cut.ok()) << cut.error().message();
    from = to;
    EXPECT_EQ(a.cut_volume, cut->removed_volume) << "frame " << f;
    EXPECT_EQ(b.cut_volume, 0.0);  // no cuts of its own
    removed += a.cut_volume;
    removed_by_hand += cut->removed_volume;
  }
  EXPECT_GT(with->last_frame().stage_ms("tool cuts"), 0.0);
  // It drilled: the centre well below the top face (at y = 0).
  const double c1 = with->tools().state(tool)->position[1];
  ASSERT_LT(c1, -5e-4);
  // The cutter's sweep below y = 0: a cylinder from its centre's end
  // height up to the face, and the hemisphere below it.
  const double swept = kPi * kCutter * kCutter * (-c1) + 2.0 / 3.0 * kPi * kCutter * kCutter * kCutter;
  // The grid measures it to about half a voxel over the cut's surface
  // (0.25 mm voxels on a 2.9 mm cutter: a few per cent; measured +6%).
  EXPECT_NEAR(removed / swept, 1.0, 0.1) << removed << " m^3 removed, " << swept << " swept";
  EXPECT_EQ(removed, removed_by_hand);
}

TEST(LevelSetTool, BadCutsAreNamed) {
  SceneDesc scene = burr_over(bone_block());
  scene.colliders.push_back(ColliderDesc{});  // a plane
  const auto fails_with = [](const SceneDesc& s, const std::string& what) {
    auto sim = Simulation::create(s, {.backend = "cpu", .quiet = true});
    ASSERT_FALSE(sim.ok()) << what;
    EXPECT_NE(sim.error().message().find(what), std::string::npos) << sim.error().message();
  };
  SceneDesc s = scene;
  s.tools[0].cuts = ToolCutDesc{.collider = 2, .cutter = {}};
  fails_with(s, "tools[0].cuts.collider: collider 2 does not exist (the scene has 2)");
  s.tools[0].cuts = ToolCutDesc{.collider = 1, .cutter = {}};
  fails_with(s, "tools[0].cuts.collider: collider 1 is not a level set");
  s.tools[0].cuts = ToolCutDesc{.collider = 0, .cutter = {.radius = 0.0}};
  fails_with(s, "tools[0].cuts.cutter.radius");
  s.tools[0].cuts = ToolCutDesc{.collider = 0, .cutter = {.kind = CutterShape::Kind::capsule, .half_height = -1.0}};
  fails_with(s, "tools[0].cuts.cutter.half_height");
  s.tools[0].cuts = ToolCutDesc{.collider = 0, .cutter = {.kind = CutterShape::Kind::box, .half_extents = {1e-3, std::nan(""), 1e-3}}};
  fails_with(s, "tools[0].cuts.cutter.half_extents[1]");
}

// ------------------------------------------------------------------ tissue

class LevelSetToolTissue : public BackendTest {};

// A pad of 12 x 4 x 12 cells of 5 mm, pinned at its bottom, and a 1 cm
// ball tool 1 mm over it, pushed down with 2 N (gravity off).
SceneDesc ball_on_pad(const ToolDesc& ball) {
  SceneDesc scene;
  scene.gravity = {0, 0, 0};
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 20, .iterations = 2};
  TetBodyDesc pad;
  pad.mesh = box_mesh(12, 4, 12, 0.005);
  for (auto& v : pad.mesh.vertices) v = {v[0] - 0.03, v[1], v[2] - 0.03};
  // The tissue this test was tuned on: compliances set by hand to
  // c_d = 1/E, c_v = 3 (1 - 2 nu) / E at 300 kPa (an effective E of ~75
  // kPa, docs/materials.md). On set_elastic(3e5, 0.3), 4x stiffer, the
  // pressed tool went through the pad (as in contact_test's pushed tool):
  // an open problem of tools on stiffer tissue, not what this checks.
  pad.distance_compliance = 1.0 / 3e5;
  pad.volume_compliance = 3.0 * (1.0 - 2.0 * 0.3) / 3e5;
  for (std::uint32_t v = 0; v < pad.mesh.vertices.size(); ++v)
    if (pad.mesh.vertices[v][1] < 1e-9) pad.pinned.push_back(v);
  scene.tet_bodies.push_back(pad);
  scene.tools.push_back(ball);
  return scene;
}

TEST_P(LevelSetToolTissue, ABallLevelSetPressesTissueLikeACapsuleOfItsShape) {
  // The same 1 cm ball as a capsule (half_height 0) and as a level set
  // (voxel 0.5 mm): pushed with 2 N they rest at heights within a voxel of
  // each other, each carried by the tissue's contact force (2%; means over
  // the last 50 of 150 frames).
  const double radius = 0.01;
  ToolDesc capsule;
  capsule.radius = radius;
  capsule.half_height = 0.0;
  capsule.mass = 0.1;
  const double i = 0.4 * capsule.mass * radius * radius;
  capsule.inertia = {i, i, i};
  capsule.gravity = false;
  capsule.position = {0, 0.02 + radius + 1e-3, 0};
  ToolDesc level_set = capsule;
  level_set.shape = ToolShape::level_set;
  level_set.level_set = solid_sphere(radius, 5e-4);
  level_set.penalty_stiffness = 1e9;  // meets nothing but tissue here
  double y[2] = {0, 0}, force[2] = {0, 0};
  int which = 0;
  for (const ToolDesc& tool : {capsule, level_set}) {
    auto made = create_or_skip(ball_on_pad(tool), GetParam());
    ASSERT_TRUE(made.ok()) << made.error().message();
    for (int f = 1; f <= 150; ++f) {
      SINEW_ASSERT_OK(made->apply_tool_force(0, {0, -2.0, 0}, {0, 0, 0}));
      SINEW_ASSERT_OK(made->step());
      if (f <= 100) continue;
      auto s = made->tool_state(0);
      ASSERT_TRUE(s.ok());
      y[which] += s->position[1] / 50;
      force[which] += s->contact_force[1] / 50;
    }
    ++which;
  }
  std::printf("[ measured ] %s: capsule rests at %.4f mm carried by %.4f N; level set at %.4f mm by %.4f N\n",
              GetParam().c_str(), 1e3 * y[0], force[0], 1e3 * y[1], force[1]);
  EXPECT_NEAR(y[1], y[0], 5e-4);
  EXPECT_LT(y[1], 0.02 + radius) << "pressed into the pad";
  EXPECT_NEAR(force[0], 2.0, 0.04);
  EXPECT_NEAR(force[1], 2.0, 0.04);
}

TEST_P(LevelSetToolTissue, AMembranesFacesHoldABallBetweenItsVertices) {
  // mesh_contact_test's coupled tool on a coarse membrane (2 cm cells,
  // ThinProbe), the tool a 4 mm ball (level set) over a cell's middle, 1.4
  // cm from the nearest vertex: the faces hold it well above the coupling's
  // target, their reaction balancing the spring (10%, last 60 of 150
  // frames); without the faces (tool_faces off) it passes to the target.
  const double mass = 0.02, radius = 0.004;
  SceneDesc scene = ThinProbe::tool_scene(mass);
  ToolDesc& tool = scene.tools[0];
  tool.shape = ToolShape::level_set;
  tool.level_set = solid_sphere(radius, radius / 12);
  tool.penalty_stiffness = 1e9;  // meets nothing but tissue here
  tool.rotation = {1, 0, 0, 0};
  tool.position[1] = 1e-4 + radius + scene.mesh_collision.thickness;
  const double i = 0.4 * mass * radius * radius;
  tool.inertia = {i, i, i};
  for (const bool faces : {true, false}) {
    scene.mesh_collision.tool_faces = faces;
    auto sim = create_or_skip(scene, GetParam());
    SINEW_ASSERT_OK(sim);
    constexpr int kFrames = 150, kAveraged = 60;
    double force = 0, spring = 0;
    for (int f = 0; f < kFrames; ++f) {
      std::array<double, 3> pull{};
      SINEW_ASSERT_OK(ThinProbe::couple(*sim, mass, pull));
      SINEW_ASSERT_OK(sim->step());
      auto state = sim->tool_state(0);
      SINEW_ASSERT_OK(state);
      if (f >= kFrames - kAveraged) {
        force += state->contact_force[1] / kAveraged;
        spring += pull[1] / kAveraged;
      }
    }
    auto state = sim->tool_state(0);
    SINEW_ASSERT_OK(state);
    std::printf("[ measured ] %s, tool faces %s: ball at %.2f mm (target %.2f), contact force %.4f N against a "
                "spring of %.4f N\n",
                GetParam().c_str(), faces ? "on" : "off", 1e3 * state->position[1], 1e3 * ThinProbe::kTarget[1],
                force, spring);
    if (faces) {
      EXPECT_GT(state->position[1], ThinProbe::kTarget[1] + 0.003) << "through the membrane";
      EXPECT_LT(spring, -0.05) << "the spring presses the ball down";
      EXPECT_NEAR(force, -spring, 0.1 * std::abs(spring));
    } else {
      EXPECT_NEAR(state->position[1], ThinProbe::kTarget[1], 5e-4) << "without the faces nothing holds the ball";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, LevelSetToolTissue, ::testing::ValuesIn(test::backends()), test::backend_name);

#endif  // SINEW_HAS_OPENVDB

}  // namespace
}  // namespace sinew::test
