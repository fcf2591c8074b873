// device_colored_contact_test.cpp — the mesh contacts coloured on the device
// in the solver (ContactSchedule::device_colored: Jones and Plassmann's
// colouring at the frame's start, capped, with an overflow set solved one
// contact after another). On the dropped blocks and the folded membrane of
// mesh_contact_test.cpp: the same physics as the host-coloured schedule
// (nothing passes through, the blocks rest on each other), the backends
// bitwise equal, and the positions within a stated distance of the
// host-coloured run's (not bitwise: the colours, so the order of the
// Gauss-Seidel sweep, differ). Bad settings are named errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mesh_contact_support.h"
#include "sinew/scene_file.h"
#include "test_support.h"

namespace sinew::test {
namespace {

class DeviceColoredContacts : public BackendTest {};

// The largest distance between the same particle in two runs [m].
double largest_distance(const std::vector<float>& a, const std::vector<float>& b) {
  double worst = 0.0;
  for (std::size_t p = 0; p + 3 < std::min(a.size(), b.size()); p += 4)
    worst = std::max(worst, std::hypot(double(a[p]) - b[p], double(a[p + 1]) - b[p + 1], double(a[p + 2]) - b[p + 2]));
  return worst;
}

// Floats that differ between two runs (0: bitwise equal).
std::size_t differing(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return std::max(a.size(), b.size());
  std::size_t n = 0;
  for (std::size_t k = 0; k < a.size(); ++k) n += a[k] != b[k] || std::signbit(a[k]) != std::signbit(b[k]);
  return n;
}

// A run of the dropped blocks: the positions after `frames`, how deep
// either block lies in the other [m], the upper block's lowest vertex [m]
// and the last frame's statistics.
struct BlocksRun {
  std::vector<float> x;
  double depth = 0.0, lowest_upper = 0.0;
  FrameStats last;
  std::uint32_t most_overflow = 0;
};

BlocksRun run_blocks(const SceneDesc& scene, const std::string& backend, int frames) {
  BlocksRun out;
  auto sim = create_or_skip(scene, backend);
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  if (!sim.ok()) return out;
  for (int f = 0; f < frames; ++f) {
    const Status s = sim->step();
    EXPECT_TRUE(s.ok()) << s.error().message();
    if (!s.ok()) return out;
    out.most_overflow = std::max(out.most_overflow, sim->last_frame().mesh_contact_overflow);
  }
  EXPECT_TRUE(sim->read_positions(out.x).ok());
  const PlacedBody lower{&scene.tet_bodies[0].mesh, sim->info().tet_body_first_particle[0]};
  const PlacedBody upper{&scene.tet_bodies[1].mesh, sim->info().tet_body_first_particle[1]};
  out.depth = std::max(penetration(out.x, upper, lower), penetration(out.x, lower, upper));
  out.lowest_upper = 1e9;
  for (std::uint32_t v = 0; v < scene.tet_bodies[1].mesh.vertices.size(); ++v)
    out.lowest_upper = std::min(out.lowest_upper, at(out.x, upper.first + v)[1]);
  out.last = sim->last_frame();
  return out;
}

// How far the device-coloured blocks may end from the host-coloured ones:
// both rest on the lower block within the thickness, their Gauss-Seidel
// orders differ, so the resting shapes differ by a fraction of it.
constexpr double kScheduleTolerance = 0.5e-3;  // [m], half the blocks' thickness

// The dropped blocks (a 3 cm block onto a 4 cm one on the floor), 120
// frames: they rest on each other within the thickness as with the host's
// colours, within kScheduleTolerance of that run's positions, and the
// other backends are bitwise the CPU's.
TEST_P(DeviceColoredContacts, DroppedBlocksRestOnEachOtherAsWithHostColours) {
  constexpr int frames = 120;
  const SceneDesc scene = dropped_blocks_scene(ContactSchedule::device_colored);
  const BlocksRun got = run_blocks(scene, GetParam(), frames);
  ASSERT_FALSE(got.x.empty());
  const BlocksRun host = run_blocks(dropped_blocks_scene(ContactSchedule::colored), GetParam(), frames);
  ASSERT_FALSE(host.x.empty());
  const double apart = largest_distance(got.x, host.x);
  std::printf("[%s] device colours: depth %.3g mm, upper block's lowest %.4f m, KE %.3g J, %u contacts in %u colours "
              "(+%u overflow, most %u); host colours: depth %.3g mm, %u colours; largest distance %.3g mm\n",
              GetParam().c_str(), got.depth * 1e3, got.lowest_upper, got.last.kinetic_energy, got.last.mesh_contacts,
              got.last.mesh_contact_colors, got.last.mesh_contact_overflow, got.most_overflow, host.depth * 1e3,
              host.last.mesh_contact_colors, apart * 1e3);
  EXPECT_LT(got.depth, scene.mesh_collision.thickness);
  EXPECT_GT(got.lowest_upper, 0.0395);  // on the lower block (top at 4 cm)
  EXPECT_LT(got.last.kinetic_energy, 1e-5);
  EXPECT_GT(got.last.mesh_contacts, 0u);
  EXPECT_GT(got.last.mesh_contact_colors, 0u);
  EXPECT_LE(got.last.mesh_contact_colors, scene.mesh_collision.device_colors);
  EXPECT_LT(got.last.contact_violation, scene.mesh_collision.thickness);
  EXPECT_LT(apart, kScheduleTolerance);
  if (GetParam() != "cpu") {
    const BlocksRun cpu = run_blocks(scene, "cpu", frames);
    EXPECT_EQ(differing(got.x, cpu.x), 0u) << "positions differ from the cpu backend's";
    EXPECT_EQ(got.last.mesh_contact_colors, cpu.last.mesh_contact_colors);
    EXPECT_EQ(got.last.mesh_contact_overflow, cpu.last.mesh_contact_overflow);
  }
}

// A cap of 2 colours: most contacts go to the overflow set (counted in
// FrameStats), which is solved one contact after another after the
// colours, and the blocks still rest on each other within the thickness.
TEST_P(DeviceColoredContacts, TheOverflowSetIsCountedAndSolved) {
  SceneDesc scene = dropped_blocks_scene(ContactSchedule::device_colored);
  scene.mesh_collision.device_colors = 2;
  const BlocksRun got = run_blocks(scene, GetParam(), 90);
  ASSERT_FALSE(got.x.empty());
  std::printf("[%s] cap 2: depth %.3g mm, %u contacts, %u colours, %u in the overflow set\n", GetParam().c_str(),
              got.depth * 1e3, got.last.mesh_contacts, got.last.mesh_contact_colors, got.last.mesh_contact_overflow);
  EXPECT_GT(got.last.mesh_contact_overflow, 0u);
  EXPECT_LE(got.last.mesh_contact_overflow, got.last.mesh_contacts);
  EXPECT_LE(got.last.mesh_contact_colors, 2u);
  EXPECT_LT(got.depth, scene.mesh_collision.thickness);
  EXPECT_GT(got.lowest_upper, 0.0395);
}

// The residual-driven mode: the stepper's programs carry the colouring in
// the frame's first one (with the first substep's predict), and the blocks
// rest on each other as in the fixed mode.
TEST_P(DeviceColoredContacts, DroppedBlocksRestOnEachOtherInTheResidualMode) {
  SceneDesc scene = dropped_blocks_scene(ContactSchedule::device_colored);
  scene.solver.residual_tolerance = 1e-4;
  scene.solver.max_iterations = 12;
  scene.solver.check_interval = 2;
  const BlocksRun got = run_blocks(scene, GetParam(), 60);
  ASSERT_FALSE(got.x.empty());
  std::printf("[%s] residual mode, device colours: depth %.3g mm, lowest %.4f m, %u contacts in %u colours\n",
              GetParam().c_str(), got.depth * 1e3, got.lowest_upper, got.last.mesh_contacts,
              got.last.mesh_contact_colors);
  EXPECT_LT(got.depth, scene.mesh_collision.thickness);
  EXPECT_GT(got.lowest_upper, 0.0395);
  EXPECT_LT(got.last.kinetic_energy, 1e-5);
  EXPECT_GT(got.last.mesh_contact_colors, 0u);
}

// The membrane folded onto itself (mesh_contact_test.cpp): its upper layer
// never passes through the lower one and ends resting on it, and the other
// backends are bitwise the CPU's.
std::vector<float> fold(const std::string& backend, int& worst, std::uint32_t& most_contacts, double& lowest) {
  constexpr int nz = FoldedStrip::nz;
  const SceneDesc scene = FoldedStrip::scene(ContactSchedule::device_colored);
  std::vector<float> x;
  auto sim = create_or_skip(scene, backend);
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  if (!sim.ok()) return x;
  const std::uint32_t first = sim->info().tri_body_first_particle[0];
  worst = 0;
  most_contacts = 0;
  constexpr int total = 2 * FoldedStrip::fold_frames;
  for (int f = 0; f < total; ++f) {
    for (int k = 0; k <= nz; ++k) EXPECT_TRUE(sim->set_target(k, FoldedStrip::target(f, k)).ok());
    const Status s = sim->step();
    EXPECT_TRUE(s.ok()) << s.error().message();
    if (!s.ok()) return {};
    most_contacts = std::max(most_contacts, sim->last_frame().mesh_contacts);
    if (f % 6 == 5 || f + 1 == total) {
      EXPECT_TRUE(sim->read_positions(x).ok());
      worst = std::max(worst, self_intersections(x, scene.tri_bodies[0].mesh, first));
    }
  }
  lowest = 1e9;  // the upper layer (x from 6 to 9 cm unfolded)
  for (int i = 12; i <= 18; ++i)
    for (int k = 0; k <= nz; ++k)
      lowest = std::min(lowest, at(x, first + static_cast<std::uint32_t>(i * (nz + 1) + k))[1]);
  return x;
}

TEST_P(DeviceColoredContacts, MembraneFoldedOntoItselfNeverPassesThroughItself) {
  const double thickness = FoldedStrip::scene(ContactSchedule::device_colored).mesh_collision.thickness;
  int worst = 0;
  std::uint32_t most_contacts = 0;
  double lowest = 0.0;
  const std::vector<float> x = fold(GetParam(), worst, most_contacts, lowest);
  ASSERT_FALSE(x.empty());
  std::printf("[%s] device colours: intersecting triangle pairs %d, most contacts %u, upper layer's lowest %.2f mm\n",
              GetParam().c_str(), worst, most_contacts, lowest * 1e3);
  EXPECT_EQ(worst, 0);
  EXPECT_GT(most_contacts, 0u);
  EXPECT_GT(lowest, 0.5 * thickness);
  EXPECT_LT(lowest, 3.0 * thickness);
  if (GetParam() != "cpu") {
    int cpu_worst = 0;
    std::uint32_t cpu_contacts = 0;
    double cpu_lowest = 0.0;
    const std::vector<float> cpu = fold("cpu", cpu_worst, cpu_contacts, cpu_lowest);
    EXPECT_EQ(differing(x, cpu), 0u) << "positions differ from the cpu backend's";
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, DeviceColoredContacts, ::testing::ValuesIn(backends()), backend_name);

// Out-of-range caps and rounds, and continuous collision (whose contacts
// are coloured on the host) with the device's colours: errors naming the
// setting, from the scene check.
TEST(DeviceColoredContactSettings, BadSettingsAreNamed) {
  const auto error_of = [](const SceneDesc& scene) {
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    return sim.ok() ? std::string("(no error)") : sim.error().message();
  };
  struct Case {
    std::uint32_t colors, rounds;
    const char* named;
  };
  for (const Case& k : {Case{0, 128, "mesh_collision.device_colors"}, Case{129, 128, "mesh_collision.device_colors"},
                        Case{32, 0, "mesh_collision.device_rounds"}, Case{32, 255, "mesh_collision.device_rounds"}}) {
    SceneDesc scene = dropped_blocks_scene(ContactSchedule::device_colored);
    scene.mesh_collision.device_colors = k.colors;
    scene.mesh_collision.device_rounds = k.rounds;
    const std::string message = error_of(scene);
    EXPECT_NE(message.find(k.named), std::string::npos) << message;
  }
  SceneDesc scene = dropped_blocks_scene(ContactSchedule::device_colored);
  scene.mesh_collision.continuous = true;
  const std::string message = error_of(scene);
  EXPECT_NE(message.find("mesh_collision.continuous"), std::string::npos) << message;
  EXPECT_NE(message.find("device_colored"), std::string::npos) << message;
}

// The scene file's "schedule": "device_colored" with its cap and rounds,
// and an out-of-range cap named with its JSON path.
TEST(DeviceColoredContactSettings, SceneFilesReadTheSchedule) {
  const auto scene_with = [](const std::string& collision) {
    return R"({"solver": {"time_step": 0.01, "substeps": 4, "iterations": 2},
      "tet_bodies": [{"mesh": {"grid": {"cells": [2, 2, 2], "size": [0.02, 0.02, 0.02]}},
        "elastic": {"youngs_modulus": 20000.0, "poisson_ratio": 0.4}}],
      "mesh_collision": {"enabled": true, )" + collision + "}}";
  };
  auto file = parse_scene_json(scene_with(R"("schedule": "device_colored", "device_colors": 12, "device_rounds": 40)"), ".");
  ASSERT_TRUE(file.ok()) << file.error().message();
  EXPECT_EQ(file->scene.mesh_collision.schedule, ContactSchedule::device_colored);
  EXPECT_EQ(file->scene.mesh_collision.device_colors, 12u);
  EXPECT_EQ(file->scene.mesh_collision.device_rounds, 40u);
  auto bad = parse_scene_json(scene_with(R"("schedule": "device_colored", "device_colors": 200)"), ".");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("device_colors"), std::string::npos) << bad.error().message();
}

}  // namespace
}  // namespace sinew::test
