// sph_solver_test.cpp — weakly compressible SPH (issue 15, part 2;
// src/fluid/sph_solver.h) in a tank of boundary particles: a column comes
// to rest with hydrostatic pressure (the weight above within 2% of the
// bottom's pressure); the backends agree with the CPU
// after a hundred steps of a falling block; bad settings are named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "backends/backend.h"
#include "fluid/sph_solver.h"
#include "test_support.h"

namespace sinew::test {
namespace {

using P3 = std::array<double, 3>;

struct Tank {
  std::vector<P3> fluid, boundary;
};

// Fluid particles at the centres of nx * ny * nz cells of `s` from the
// origin; one layer of boundary particles s apart half a spacing outside
// its floor and four walls, the walls `wall` cells high.
Tank tank(int nx, int ny, int nz, double s, int wall) {
  Tank t;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) t.fluid.push_back({(i + 0.5) * s, (j + 0.5) * s, (k + 0.5) * s});
  for (int i = -1; i <= nx; ++i)
    for (int k = -1; k <= nz; ++k) t.boundary.push_back({(i + 0.5) * s, -0.5 * s, (k + 0.5) * s});  // floor
  for (int j = 0; j < wall; ++j)
    for (int a = -1; a <= std::max(nx, nz); ++a) {
      if (a <= nz) {
        t.boundary.push_back({-0.5 * s, (j + 0.5) * s, (a + 0.5) * s});
        t.boundary.push_back({(nx + 0.5) * s, (j + 0.5) * s, (a + 0.5) * s});
      }
      if (a >= 0 && a < nx) {
        t.boundary.push_back({(a + 0.5) * s, (j + 0.5) * s, -0.5 * s});
        t.boundary.push_back({(a + 0.5) * s, (j + 0.5) * s, (nz + 0.5) * s});
      }
    }
  return t;
}

TEST(SphSolver, AColumnAtRestHoldsItsWeight) {
  // 8 x 20 x 8 particles of 1 mm (2 cm deep) in a tank of one boundary
  // layer, c0 = 10 m/s, 7.5e-5 s steps (the CFL bound at rest: 8e-5), 0.6 s, then 20
  // samples 50 steps apart (pressure in a weakly compressible fluid is
  // noisy: layers are averaged over space and time). The fluid comes to
  // rest inside the tank, and the mean pressure of each 1 mm layer of the
  // inner 4 x 4 columns, from 4 mm above the floor (two supports from its
  // boundary layer) up to the surface's support, grows with depth and is
  // the weight of the particles above it per area within 2% of the
  // bottom's (the hydrostatic test), 1% on average.
  const double s = 1e-3;
  const Tank t = tank(8, 20, 8, s, 24);
  auto device = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(device.ok());
  SphSettings settings;
  settings.spacing = s;
  settings.time_step = 7.5e-5;  // below the CFL bound 0.4 h / (c0 + v_max), 8e-5 at rest
  auto solver = SphSolver::create(**device, settings, t.fluid, t.boundary);
  ASSERT_TRUE(solver.ok()) << solver.error().message();
  SINEW_ASSERT_OK((*solver)->step(8000));
  std::vector<SphParticle> q;
  std::vector<double> sum(32, 0.0), count(32, 0.0), above(32, 0.0);
  double speed = 0.0, highest = -1e30, lowest = 1e30;
  constexpr int kSamples = 20;
  for (int sample = 0; sample < kSamples; ++sample) {
    SINEW_ASSERT_OK((*solver)->step(50));
    SINEW_ASSERT_OK((*solver)->read(q));
    for (const auto& p : q) {
      highest = std::max(highest, double(p.position[1]));
      lowest = std::min({lowest, double(p.position[0]), double(p.position[1]), double(p.position[2])});
      speed = std::max(speed, double(std::hypot(p.velocity[0], p.velocity[1], p.velocity[2])));
      if (p.position[0] < 2 * s || p.position[0] > 6 * s || p.position[2] < 2 * s || p.position[2] > 6 * s) continue;
      const int layer = static_cast<int>(std::floor(p.position[1] / s));
      if (layer < 0 || layer >= 32) continue;
      sum[std::size_t(layer)] += p.pressure;
      count[std::size_t(layer)] += 1.0;
      for (int l = 0; l < layer; ++l) above[std::size_t(l)] += 1.0;  // its weight presses on the layers below
    }
  }
  const double g = 9.81, mass = 1000.0 * s * s * s, area = 16.0 * s * s;
  // The weight over a layer's middle: the particles above it and half its own.
  const auto weight = [&](int l) {
    return (above[std::size_t(l)] + 0.5 * count[std::size_t(l)]) / kSamples * mass * g / area;
  };
  const double bottom = weight(0);
  double worst = 0.0, bias = 0.0, previous = 1e30;
  int layers = 0, rising = 0;
  for (int l = 4; l < 32; ++l) {  // two supports (2 h) above the floor's boundary layer
    if (count[std::size_t(l)] == 0.0) continue;
    if (weight(l) < 2 * s * 1000.0 * g) break;  // the surface's support: pressure is clamped at 0 there
    const double mean = sum[std::size_t(l)] / count[std::size_t(l)];
    worst = std::max(worst, std::abs(mean - weight(l)) / bottom);
    bias += (mean - weight(l)) / bottom;
    rising += mean < previous;
    previous = mean;
    ++layers;
  }
  bias /= std::max(layers, 1);
  std::printf("[ measured ] %d layers: pressure - the weight above, %+.2f%% on average and %.2f%% at worst of the "
              "bottom's %.1f Pa; highest particle %.2f mm, fastest %.2e m/s\n",
              layers, 100.0 * bias, 100.0 * worst, bottom, 1e3 * highest, speed);
  EXPECT_GT(layers, 10);
  EXPECT_LT(worst, 0.02);
  EXPECT_LT(std::abs(bias), 0.01);
  EXPECT_EQ(rising, layers) << "pressure grows with depth";
  EXPECT_LT(speed, 0.02) << "at rest";
  EXPECT_LT(highest, 0.024) << "nothing thrown out";
  EXPECT_GT(lowest, -0.5 * s) << "nothing through the boundary";
}

// 6 x 6 x 6 particles `s` apart, 2 spacings above the tank's floor, one
// in from its walls.
std::vector<P3> falling_block(double s) {
  std::vector<P3> block;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k) block.push_back({(i + 1.5) * s, (j + 2.5) * s, (k + 1.5) * s});
  return block;
}

class SphAgreement : public BackendTest {};

TEST_P(SphAgreement, ABlockFallingInATankMatchesTheCpu) {
  // A 6 x 6 x 6 block 2 mm above the floor of a tank of 8 x 8 cells falls
  // for 400 steps of 5e-5 s (it lands and spreads): every particle within
  // 1e-4 m (a tenth of the spacing) of the CPU's; the square roots and
  // divisions of the GPUs may round differently, so not bitwise.
  if (GetParam() == "cpu") GTEST_SKIP() << "the reference itself";
  const double s = 1e-3;
  Tank t = tank(8, 8, 8, s, 12);
  const std::vector<P3> block = falling_block(s);
  std::vector<std::vector<SphParticle>> out;
  for (const std::string& backend : {std::string("cpu"), GetParam()}) {
    auto device = create_device({.backend = backend, .quiet = true});
    ASSERT_TRUE(device.ok()) << device.error().message();
    auto solver = SphSolver::create(**device, {.spacing = s}, block, t.boundary);
    ASSERT_TRUE(solver.ok()) << solver.error().message();
    SINEW_ASSERT_OK((*solver)->step(400));
    SINEW_ASSERT_OK((*solver)->read(out.emplace_back()));
  }
  double worst = 0.0, fell = 0.0;
  for (std::size_t i = 0; i < block.size(); ++i) {
    fell = std::max(fell, block[i][1] - double(out[0][i].position[1]));
    for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(double(out[1][i].position[k] - out[0][i].position[k])));
  }
  std::printf("[ measured ] %s: the block fell up to %.3f mm; every particle within %.2e m of the CPU's\n",
              GetParam().c_str(), 1e3 * fell, worst);
  EXPECT_GT(fell, 1.5 * s) << "it fell";
  EXPECT_LT(worst, 1e-4);
}

INSTANTIATE_TEST_SUITE_P(Backends, SphAgreement, ::testing::ValuesIn(backends()), backend_name);

TEST(SphSolver, TheAvx2KernelsAreBitwiseTheReference) {
  // The CPU backend's AVX2 density and step (sph_kernels_avx2.cpp) against
  // the scalar reference (cpu_simd = false): a block falling into the tank
  // and splashing for 400 steps, every position, velocity and density
  // bit for bit. Skipped where the CPU has no AVX2 (both runs would be scalar).
  const double s = 1e-3;
  Tank t = tank(8, 8, 8, s, 12);
  const std::vector<P3> block = falling_block(s);
  std::vector<std::vector<SphParticle>> out;
  std::vector<std::vector<std::array<float, 3>>> impulses;
  std::vector<std::string> names;
  for (bool simd : {false, true}) {
    auto device = create_device({.backend = "cpu", .cpu_simd = simd, .quiet = true});
    ASSERT_TRUE(device.ok()) << device.error().message();
    names.push_back((*device)->device_name());
    FluidDesc desc;
    desc.settings.spacing = s;
    desc.particles = block;
    desc.boundary = t.boundary;
    desc.boundary_forces = true;  // and sph_boundary_force_avx2
    auto solver = SphSolver::create(**device, desc);
    ASSERT_TRUE(solver.ok()) << solver.error().message();
    SINEW_ASSERT_OK((*solver)->step(400));
    SINEW_ASSERT_OK((*solver)->read(out.emplace_back()));
    SINEW_ASSERT_OK((*solver)->read_boundary_impulses(impulses.emplace_back()));
  }
  if (names[0] == names[1]) GTEST_SKIP() << "no AVX2 here: " << names[1];
  ASSERT_EQ(out[0].size(), out[1].size());
  int differ = 0;
  for (std::size_t i = 0; i < out[0].size(); ++i)
    differ += std::memcmp(&out[0][i], &out[1][i], sizeof(SphParticle)) != 0;
  EXPECT_EQ(differ, 0) << "particles whose bits differ";
  ASSERT_EQ(impulses[0].size(), t.boundary.size());
  float pushed = 0.0f;
  for (const auto& j : impulses[0]) pushed += std::abs(j[1]);
  EXPECT_GT(pushed, 0.0f) << "the floor took an impulse";
  EXPECT_EQ(std::memcmp(impulses[0].data(), impulses[1].data(), 12 * impulses[0].size()), 0) << "boundary impulses";
}

TEST(SphSolver, AStepAtTheSoundsBoundFailsOnceTheParticlesMove) {
  // dt = 0.4 h / c0 passes at rest; once the block falls, dt > 0.4 h / (c0
  // + v_max): step() says so, with the particle's speed, never clamps.
  const double s = 1e-3;
  const Tank t = tank(4, 4, 4, s, 8);
  std::vector<P3> block;
  for (const P3& p : t.fluid) block.push_back({p[0], p[1] + 2 * s, p[2]});
  auto device = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(device.ok());
  auto solver = SphSolver::create(**device, {.spacing = s, .time_step = 8e-5}, block, t.boundary);
  ASSERT_TRUE(solver.ok()) << solver.error().message();
  const Status moved = (*solver)->step(20);
  ASSERT_FALSE(moved.ok());
  EXPECT_NE(moved.error().message().find("beyond the CFL bound 0.4 h / (c0 + v_max)"), std::string::npos)
      << moved.error().message();
  EXPECT_GT((*solver)->last_max_speed(), 0.0);
  EXPECT_NEAR((*solver)->mach(), (*solver)->last_max_speed() / 10.0, 1e-12);
}

TEST(SphSolver, BadSettingsAreNamed) {
  auto device = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(device.ok());
  const Tank t = tank(2, 2, 2, 1e-3, 2);
  const auto message = [&](const SphSettings& s) {
    auto made = SphSolver::create(**device, s, t.fluid, t.boundary);
    return made.ok() ? std::string() : made.error().message();
  };
  SphSettings s;
  s.time_step = 1e-3;
  EXPECT_NE(message(s).find("beyond the CFL bound 0.4 h / c0 = 8e-05 s"), std::string::npos) << message(s);
  s = {};
  s.spacing = 0.0;
  EXPECT_NE(message(s).find("spacing must be finite and > 0"), std::string::npos);
  s = {};
  s.viscosity = -1.0;
  EXPECT_NE(message(s).find("viscosity must be finite and >= 0"), std::string::npos);
  s = {};
  s.boundary_viscosity = NAN;
  EXPECT_NE(message(s).find("boundary_viscosity must be finite and >= 0"), std::string::npos);
  s = {};
  s.support = 0.5;
  EXPECT_NE(message(s).find("support must be finite and >= 1 spacing"), std::string::npos);
  s = {};
  s.gravity = {0.0, NAN, 0.0};
  EXPECT_NE(message(s).find("gravity must be finite"), std::string::npos);
  Tank nan = t;
  nan.fluid[1][2] = NAN;
  auto bad = SphSolver::create(**device, {}, nan.fluid, nan.boundary);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("fluid particle 1 has coordinate nan"), std::string::npos)
      << bad.error().message();
  EXPECT_NE(SphSolver::create(**device, {}, {}, t.boundary).error().message().find("no fluid"), std::string::npos);
}

}  // namespace
}  // namespace sinew::test
