// scene_fluid_test.cpp — a fluid as a stage of its scene (SceneDesc::fluid,
// sinew/scene_fluid.h), on the Simulation's device: a cup of tissue holds
// the fluid and carries its weight, sloshing conserves the momentum of
// both (with and without the host's own forces on top), the device path
// gives the host coupling's very floats on the CPU and agrees on every GPU
// backend, a frame reads back only the fluid's counts, and bad fluid scenes
// are named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "sinew/fluid_coupling.h"
#include "sinew/log.h"
#include "sinew/simulation.h"
#include "fluid_cup.h"
#include "test_support.h"

namespace sinew::test {
namespace {

constexpr double kS = kCupCell;


TEST(SceneFluid, ACupHoldsTheFluidAndCarriesItsWeight) {
  // 5 x 3 x 5 particles poured into a cup pinned at its base, 0.3 s: none
  // leaves the cavity, and once settled the fluid's push on the tissue over
  // a frame is its weight (within 5%).
  auto sim = Simulation::create(cup_scene(true, {0, -9.81, 0}, fluid_block(5, 3, 5, {1.5 * kS, 1.5 * kS, 1.5 * kS})),
                                {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  std::array<double, 3> pushed{};
  for (int frame = 0; frame < 300; ++frame) {
    SINEW_ASSERT_OK(sim->step());
    if (frame < 250) continue;
    auto impulses = sim->fluid().last_impulses();
    ASSERT_TRUE(impulses.ok()) << impulses.error().message();
    for (int a = 0; a < 3; ++a) pushed[a] += impulses->tissue[a] / (50 * 1e-3);
  }
  std::vector<FluidParticle> q;
  SINEW_ASSERT_OK(sim->fluid().read(q));
  ASSERT_EQ(q.size(), 75u);
  int outside = 0;
  for (const auto& p : q)
    outside += p.position[0] < 0.5 * kS || p.position[0] > 7.5 * kS || p.position[2] < 0.5 * kS ||
               p.position[2] > 7.5 * kS || p.position[1] < 0.5 * kS;
  const auto info = sim->fluid().info();
  ASSERT_TRUE(info.ok());
  const double weight = info->particle_mass * double(q.size()) * 9.81;
  std::printf("[ measured ] %u boundary particles on the cup; the fluid pushes it %.4e N down (its weight %.4e N), "
              "%d particles outside the cavity\n",
              info->coupled_boundary, -pushed[1], weight, outside);
  EXPECT_EQ(outside, 0);
  EXPECT_NEAR(-pushed[1], weight, 0.05 * weight);
  EXPECT_LT(std::abs(pushed[0]) + std::abs(pushed[2]), 0.05 * weight);
}

// Fluid + cup momentum along x after `frames` frames of a free cup in no
// gravity, the fluid starting at 0.2 m/s; the host adds `host_force` [N]
// along x spread evenly over the cup's particles each frame.
struct Momenta {
  double fluid = 0.0, cup = 0.0, start = 0.0;
};
Momenta slosh(int frames, double host_force) {
  auto sim = Simulation::create(cup_scene(false, {0, 0, 0}, fluid_block(3, 3, 5, {1.5 * kS, 1.5 * kS, 1.5 * kS}), {0.2, 0, 0}),
                                {.backend = "cpu", .quiet = true});
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  if (!sim.ok()) return {};
  const std::size_t n = sim->info().particles;
  std::vector<float> forces(3 * n, 0.0f);
  for (std::size_t i = 0; i < n; ++i) forces[3 * i] = float(host_force / double(n));
  Momenta out;
  const double m = sim->fluid().info()->particle_mass;
  out.start = m * 45 * 0.2;
  for (int frame = 0; frame < frames; ++frame) {
    if (host_force != 0.0) {
      EXPECT_TRUE(sim->set_particle_forces(forces).ok());
    }
    EXPECT_TRUE(sim->step().ok());
  }
  std::vector<FluidParticle> q;
  EXPECT_TRUE(sim->fluid().read(q).ok());
  for (const auto& p : q) out.fluid += m * p.velocity[0];
  std::vector<float> x, v;
  EXPECT_TRUE(sim->read_positions(x).ok());
  EXPECT_TRUE(sim->read_velocities(v).ok());
  for (std::size_t i = 0; i < x.size() / 4; ++i) out.cup += v[4 * i] / x[4 * i + 3];  // m v, w the inverse mass
  return out;
}

TEST(SceneFluid, SloshingInAFreeCupConservesMomentum) {
  // The fluid hits the cup's wall and pushes it along: fluid + cup hold the
  // initial momentum within 0.5% after 50 frames (float rounding of the
  // sums and the tissue's solve).
  const Momenta p = slosh(50, 0.0);
  std::printf("[ measured ] momentum along x: fluid %.4e + cup %.4e = %.4e N s against %.4e at the start\n", p.fluid,
              p.cup, p.fluid + p.cup, p.start);
  EXPECT_GT(p.cup, 0.2 * p.start) << "the fluid pushed the cup";
  EXPECT_NEAR(p.fluid + p.cup, p.start, 0.005 * p.start);
}

TEST(SceneFluid, TheHostsForcesAddToTheFluids) {
  // The host pushes the cup along x with 1e-4 N in all while the fluid
  // sloshes: after 50 frames of 1 ms the pair gained 5e-6 N s (within 1%
  // of the start's momentum, 9e-6 N s: rounding as above).
  const double force = 1e-4, frames = 50;
  const Momenta p = slosh(int(frames), force);
  const double expected = p.start + force * frames * 1e-3;
  std::printf("[ measured ] momentum along x: %.4e N s, expected %.4e\n", p.fluid + p.cup, expected);
  EXPECT_NEAR(p.fluid + p.cup, expected, 0.01 * p.start);
}

// The tissue's positions and the fluid's particles after `frames` frames
// of the pinned cup on `backend`, through the scene's fluid stage.
struct Snapshot {
  std::vector<float> tissue;
  std::vector<FluidParticle> fluid;
};
Snapshot run_stage(const std::string& backend, int frames) {
  auto sim = Simulation::create(cup_scene(true, {0, -9.81, 0}, fluid_block(5, 3, 5, {1.5 * kS, 1.5 * kS, 1.5 * kS})),
                                {.backend = backend, .quiet = true});
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  Snapshot out;
  if (!sim.ok()) return out;
  for (int f = 0; f < frames; ++f) EXPECT_TRUE(sim->step().ok());
  EXPECT_TRUE(sim->read_positions(out.tissue).ok());
  EXPECT_TRUE(sim->fluid().read(out.fluid).ok());
  return out;
}

TEST(SceneFluid, GivesTheHostCouplingsVeryFloatsOnTheCpu) {
  // The same cup through FluidCoupling (the host reads the tissue back,
  // moves the boundary, reads the impulses and sets the forces) and through
  // the stage (all on the device): every float equal after 40 frames.
  constexpr int kFrames = 40;
  const Snapshot stage = run_stage("cpu", kFrames);
  SceneDesc scene = cup_scene(true, {0, -9.81, 0}, fluid_block(5, 3, 5, {1.5 * kS, 1.5 * kS, 1.5 * kS}));
  FluidDesc fluid = scene.fluid->fluid;
  fluid.device = {.backend = "cpu", .quiet = true};
  scene.fluid.reset();
  scene.external_forces = true;
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const CoupledSurface surface{extract_boundary_surface(scene.tet_bodies[0].mesh), 0};
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
  auto coupled = FluidCoupling::create(*sim, fluid, std::span(&surface, 1));
  ASSERT_TRUE(coupled.ok()) << coupled.error().message();
  for (int f = 0; f < kFrames; ++f) SINEW_ASSERT_OK(coupled->step());
  std::vector<FluidParticle> q;
  SINEW_ASSERT_OK(coupled->fluid().read(q));
#pragma GCC diagnostic pop
  std::vector<float> x;
  SINEW_ASSERT_OK(sim->read_positions(x));
  ASSERT_EQ(x.size(), stage.tissue.size());
  EXPECT_EQ(std::memcmp(x.data(), stage.tissue.data(), 4 * x.size()), 0) << "tissue positions differ";
  ASSERT_EQ(q.size(), stage.fluid.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < q.size(); ++i)
    differ += q[i].id != stage.fluid[i].id || std::memcmp(&q[i].position, &stage.fluid[i].position, 12) != 0 ||
              std::memcmp(&q[i].velocity, &stage.fluid[i].velocity, 12) != 0;
  EXPECT_EQ(differ, 0u) << "fluid particles differ";
}

TEST(SceneFluid, AgreesOnEveryBackend) {
  // 20 frames on each GPU backend against the CPU's: tissue and fluid
  // within 1 um (a thousandth of the spacing: rounding, not physics).
  constexpr int kFrames = 20;
  const Snapshot ref = run_stage("cpu", kFrames);
  int ran = 0;
  for (const std::string& backend : backends()) {
    if (backend == "cpu" || !missing_device(backend).empty()) continue;
    ++ran;
    const Snapshot got = run_stage(backend, kFrames);
    ASSERT_EQ(got.tissue.size(), ref.tissue.size()) << backend;
    ASSERT_EQ(got.fluid.size(), ref.fluid.size()) << backend;
    double worst = 0.0;
    for (std::size_t i = 0; i < ref.tissue.size(); i += 4)
      for (int a = 0; a < 3; ++a) worst = std::max(worst, double(std::abs(got.tissue[i + a] - ref.tissue[i + a])));
    for (std::size_t i = 0; i < ref.fluid.size(); ++i)
      for (int a = 0; a < 3; ++a)
        worst = std::max(worst, double(std::abs(got.fluid[i].position[a] - ref.fluid[i].position[a])));
    std::printf("[ measured ] %s: largest difference from the CPU after %d frames %.3e m\n", backend.c_str(), kFrames,
                worst);
    EXPECT_LT(worst, 1e-6) << backend;
  }
  if (ran == 0) GTEST_SKIP() << "no GPU backend with a device here";
}

TEST(SceneFluid, AFrameReadsBackOnlyTheFluidsCounts) {
  auto sim = Simulation::create(cup_scene(true, {0, -9.81, 0}, fluid_block(2, 2, 2, {3 * kS, 2 * kS, 3 * kS})),
                                {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  SINEW_ASSERT_OK(sim->step());
  SINEW_ASSERT_OK(sim->step());
  const FrameStats& stats = sim->last_frame();
  EXPECT_EQ(stats.position_reads, 0u);
  // The statistics' few words and the fluid's 28 bytes, never the positions.
  EXPECT_LT(stats.read_back_bytes, 16u * sim->info().particles);
  const auto fluid = std::find_if(stats.stages.begin(), stats.stages.end(), [](const StageProfile& p) { return p.name == "fluid"; });
  ASSERT_NE(fluid, stats.stages.end()) << "the fluid is a stage of the frame";
  EXPECT_EQ(fluid - stats.stages.begin(), 1) << "right after the forces";
  EXPECT_EQ(sim->fluid().stats()->steps, 40u);  // 2 frames of 20 steps of 50 us
}

TEST(SceneFluid, AnEmitterPastTheCapacityEndsAWholeFrameAndIsNamed) {
  // A source pouring into the cup with room for 2 particles more: the frame
  // that outgrows it completes (the tissue steps, the frame counts) and
  // step() says capacity_exceeded, naming the particles.
  SceneDesc scene = cup_scene(true, {0, -9.81, 0}, fluid_block(2, 2, 2, {3 * kS, 2 * kS, 3 * kS}));
  scene.fluid->fluid.capacity = 10;
  scene.fluid->fluid.emitters.push_back(
      {.centre = {4 * kS, 4 * kS, 4 * kS}, .direction = {0, -1, 0}, .radius = 1.5 * kS, .flow_rate = 2e-6});
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  // The warning comes first: 90% of the capacity (sinew/warnings.h), once.
  std::vector<std::pair<std::uint64_t, std::string>> warnings;
  set_log_callback([&](LogLevel level, std::string_view text) {
    if (level == LogLevel::warning) warnings.emplace_back(sim->last_frame().frame, std::string(text));
  });
  Status s;
  int frames = 0;
  while (s.ok() && frames < 50) {
    s = sim->step();
    ++frames;
  }
  set_log_callback({});
  EXPECT_EQ(sim->last_frame().counter("fluid", "particles_capacity"), 10.0);
  ASSERT_EQ(warnings.size(), 1u) << "one warning when the particles reached 9 of 10";
  EXPECT_NE(warnings[0].second.find("fluid: particles reached"), std::string::npos) << warnings[0].second;
  EXPECT_NE(warnings[0].second.find("of its capacity 10"), std::string::npos) << warnings[0].second;
  ASSERT_FALSE(s.ok()) << "the source outgrew the capacity within 50 frames";
  EXPECT_EQ(s.error().code(), ErrorCode::capacity_exceeded) << s.error().message();
  EXPECT_NE(s.error().message().find("sph particles"), std::string::npos) << s.error().message();
  EXPECT_EQ(sim->last_frame().frame, std::uint64_t(frames)) << "the frame that overflowed completed";
  EXPECT_EQ(sim->fluid().stats()->particles, 10u);
  EXPECT_EQ(sim->last_frame().counter("fluid", "particles"), 10.0);
}

TEST(SceneFluid, BadFluidScenesAreNamed) {
  const auto fails_with = [](const SceneDesc& scene, const char* words) {
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    ASSERT_FALSE(sim.ok()) << words;
    EXPECT_NE(sim.error().message().find(words), std::string::npos) << sim.error().message();
  };
  const SceneDesc good = cup_scene(true, {0, -9.81, 0}, fluid_block(2, 2, 2, {3 * kS, 2 * kS, 3 * kS}));
  SceneDesc bad = good;
  bad.fluid->fluid.settings.time_step = 3e-5;  // 1 ms is 33.3 of them
  fails_with(bad, "not a whole number of fluid steps");
  bad = good;
  bad.fluid->surfaces[0].body = 3;
  fails_with(bad, "fluid.surfaces[0].body 3");
  bad = good;
  bad.fluid->surfaces[0].triangles = {{0, 1, 100000}};
  fails_with(bad, "fluid.surfaces[0].triangles[0] names vertex 100000");
  bad = good;
  bad.fluid->surfaces[0].body_kind = BodyKind::line;
  fails_with(bad, "fluid.surfaces[0].body_kind");
  bad = good;
  bad.fluid->fluid.particles[0][1] = std::nan("");
  fails_with(bad, "must be finite");

  SceneDesc dry = good;
  dry.fluid.reset();
  auto sim = Simulation::create(dry, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  std::vector<FluidParticle> q;
  const Status s = sim->fluid().read(q);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message().find("SceneDesc::fluid"), std::string::npos) << s.error().message();
  EXPECT_FALSE(sim->fluid().stats().ok());
}

}  // namespace
}  // namespace sinew::test
