// fluid_coupling_test.cpp — fluid in a tissue cup (sinew/fluid_coupling.h;
// issue 15, part 3): the cup holds the fluid (a cavity), the fluid's
// weight reaches the tissue, fluid sloshing in a free cup conserves the
// total momentum of both, and bad couplings are named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "sinew/fluid_coupling.h"
#include "fluid_cup.h"
#include "test_support.h"

// FluidCoupling is deprecated (SceneDesc::fluid, scene_fluid_test.cpp); its
// tests stay for the release that keeps it.
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"

namespace sinew::test {
namespace {

constexpr double kS = kCupCell;


struct Scene {
  SceneDesc scene;
  TriMesh surface;
};

Scene cup_scene(bool pinned, std::array<double, 3> gravity) {
  Scene s;
  TetBodyDesc body = fluid_cup_body(pinned);
  s.surface = extract_boundary_surface(body.mesh);
  s.scene.tet_bodies.push_back(std::move(body));
  s.scene.gravity = gravity;
  s.scene.external_forces = true;
  s.scene.solver.time_step = 1e-3;
  s.scene.solver.substeps = 4;
  s.scene.solver.iterations = 10;
  return s;
}

TEST(FluidCoupling, ACupHoldsTheFluidAndCarriesItsWeight) {
  // 5 x 3 x 5 particles poured into a cup pinned at its base, 0.3 s: none
  // leaves the cavity, and once settled the fluid's push on the tissue over
  // a frame is its weight (within 5%), the fixed-boundary share 0.
  Scene s = cup_scene(true, {0, -9.81, 0});
  auto sim = Simulation::create(s.scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  FluidDesc fluid;
  fluid.settings.spacing = kS;
  fluid.particles = fluid_block(5, 3, 5, {1.5 * kS, 1.5 * kS, 1.5 * kS});  // a spacing from the walls
  fluid.device = {.backend = "cpu", .quiet = true};
  const CoupledSurface surface{s.surface, sim->info().tet_body_first_particle[0]};
  auto coupled = FluidCoupling::create(*sim, fluid, std::span(&surface, 1));
  ASSERT_TRUE(coupled.ok()) << coupled.error().message();
  std::array<double, 3> pushed{};
  for (int frame = 0; frame < 300; ++frame) {
    SINEW_ASSERT_OK(coupled->step());
    if (frame >= 250)
      for (int a = 0; a < 3; ++a) pushed[a] += coupled->last_impulse()[a] / (50 * 1e-3);
  }
  std::vector<FluidParticle> q;
  SINEW_ASSERT_OK(coupled->fluid().read(q));
  ASSERT_EQ(q.size(), fluid.particles.size());
  int outside = 0;
  for (const auto& p : q)
    outside += p.position[0] < 0.5 * kS || p.position[0] > 7.5 * kS || p.position[2] < 0.5 * kS ||
               p.position[2] > 7.5 * kS || p.position[1] < 0.5 * kS;
  const double weight = coupled->fluid().particle_mass() * double(q.size()) * 9.81;
  std::printf("[ measured ] %zu boundary particles on the cup; the fluid pushes it %.4e N down (its weight %.4e N), "
              "%d particles outside the cavity\n",
              std::size_t(coupled->coupled_count()), -pushed[1], weight, outside);
  EXPECT_EQ(outside, 0);
  EXPECT_NEAR(-pushed[1], weight, 0.05 * weight);
  EXPECT_LT(std::abs(pushed[0]) + std::abs(pushed[2]), 0.05 * weight);
}

TEST(FluidCoupling, SloshingInAFreeCupConservesMomentum) {
  // No gravity, nothing pinned: the fluid starts at 0.2 m/s along x inside
  // the cup at rest, hits the wall and pushes the cup along. After 50
  // frames the cup carries a good share of the momentum, and fluid + cup
  // hold the initial momentum within 0.5% (float rounding of the sums and
  // of the tissue's solve).
  Scene s = cup_scene(false, {0, 0, 0});
  auto sim = Simulation::create(s.scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  FluidDesc fluid;
  fluid.settings.spacing = kS;
  fluid.settings.gravity = {0, 0, 0};
  fluid.particles = fluid_block(3, 3, 5, {1.5 * kS, 1.5 * kS, 1.5 * kS});
  fluid.velocities.assign(fluid.particles.size(), {0.2, 0.0, 0.0});
  fluid.device = {.backend = "cpu", .quiet = true};
  const CoupledSurface surface{s.surface, sim->info().tet_body_first_particle[0]};
  auto coupled = FluidCoupling::create(*sim, fluid, std::span(&surface, 1));
  ASSERT_TRUE(coupled.ok()) << coupled.error().message();
  const double m = coupled->fluid().particle_mass();
  const double p0 = m * double(fluid.particles.size()) * 0.2;
  for (int frame = 0; frame < 50; ++frame) SINEW_ASSERT_OK(coupled->step());
  std::vector<FluidParticle> q;
  SINEW_ASSERT_OK(coupled->fluid().read(q));
  std::array<double, 3> fluid_p{}, cup_p{};
  for (const auto& p : q)
    for (int a = 0; a < 3; ++a) fluid_p[a] += m * p.velocity[a];
  std::vector<float> x, v;
  SINEW_ASSERT_OK(sim->read_positions(x));
  SINEW_ASSERT_OK(sim->read_velocities(v));
  for (std::size_t i = 0; i < x.size() / 4; ++i)
    for (int a = 0; a < 3; ++a) cup_p[a] += v[4 * i + a] / x[4 * i + 3];  // m v, w the inverse mass
  std::printf("[ measured ] momentum along x: fluid %.4e + cup %.4e = %.4e N s against %.4e at the start (%.3f%%)\n",
              fluid_p[0], cup_p[0], fluid_p[0] + cup_p[0], p0, 100.0 * (fluid_p[0] + cup_p[0] - p0) / p0);
  EXPECT_GT(cup_p[0], 0.2 * p0) << "the fluid pushed the cup";
  EXPECT_NEAR(fluid_p[0] + cup_p[0], p0, 0.005 * p0);
  EXPECT_LT(std::abs(fluid_p[1] + cup_p[1]) + std::abs(fluid_p[2] + cup_p[2]), 0.005 * p0);
}

TEST(FluidCoupling, BadCouplingsAreNamed) {
  Scene s = cup_scene(true, {0, -9.81, 0});
  auto sim = Simulation::create(s.scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  FluidDesc fluid;
  fluid.settings.spacing = kS;
  fluid.settings.time_step = 3e-5;  // 1 ms is 33.3 of them
  fluid.particles = fluid_block(2, 2, 2, {3 * kS, 2 * kS, 3 * kS});
  fluid.device = {.backend = "cpu", .quiet = true};
  const CoupledSurface surface{s.surface, sim->info().tet_body_first_particle[0]};
  auto bad = FluidCoupling::create(*sim, fluid, std::span(&surface, 1));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("not a whole number of fluid steps"), std::string::npos) << bad.error().message();
  fluid.settings.time_step = 5e-5;
  CoupledSurface far = surface;
  far.first_particle = 100000;
  bad = FluidCoupling::create(*sim, fluid, std::span(&far, 1));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("beyond the simulation's"), std::string::npos) << bad.error().message();
  EXPECT_FALSE(FluidCoupling::create(*sim, fluid, {}).ok());
}

}  // namespace
}  // namespace sinew::test
