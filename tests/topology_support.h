// topology_support.h — what the topology tests (topology_test.cpp,
// topology_thin_test.cpp) check after every change, shared.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "runtime/simulation_internals.h"
#include "test_support.h"

namespace sinew::test {

// Steps `frames` frames; fails on an error or a non-finite position.
inline void run(Simulation& sim, int frames) {
  std::vector<float> x;
  for (int f = 0; f < frames; ++f) ASSERT_TRUE(sim.step().ok());
  ASSERT_TRUE(sim.read_positions(x).ok());
  for (float c : x) ASSERT_TRUE(std::isfinite(c));
}

// Takes `n` of `live` at random (a linear congruential generator on
// [in/out] seed, the same draws on every platform) and returns them.
inline std::vector<std::uint32_t> take_random(std::vector<std::uint32_t>& live, int n, std::uint32_t& seed) {
  std::vector<std::uint32_t> take;
  for (int i = 0; i < n && !live.empty(); ++i) {
    seed = seed * 1664525u + 1013904223u;
    const std::size_t at = (seed >> 8) % live.size();
    take.push_back(live[at]);
    live.erase(live.begin() + std::ptrdiff_t(at));
  }
  return take;
}

// Adds an 8 mm cube of 2 x 2 x 2 cells (300 kPa edge network) with its
// lowest corner at `origin` [m] to `scene`, and turns mesh collision on
// (0.5 mm, no self-collision): something to rest on a surface a change cuts.
inline void add_resting_cube(SceneDesc& scene, const Vec3d& origin) {
  TetBodyDesc cube;
  cube.mesh = *make_tet_grid({.nx = 2, .ny = 2, .nz = 2, .origin = origin, .cell_size = {4e-3, 4e-3, 4e-3}});
  cube.density = 1000.0;
  EXPECT_TRUE(cube.set_elastic(3e5, 0.3).ok());
  scene.tet_bodies.push_back(cube);
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 5e-4;
  scene.mesh_collision.self_collision = false;
}

// The lowest y [m] of tet body `body`'s vertices now.
inline double lowest_y(const Simulation& sim, const SceneDesc& scene, std::size_t body) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  double y = 1.0;
  for (std::uint32_t v = 0; v < scene.tet_bodies[body].mesh.vertices.size(); ++v)
    y = std::min(y, double(x[4 * (sim.info().tet_body_first_particle[body] + v) + 1]));
  return y;
}

// Colours valid, no constraint naming a removed vertex (of the body whose
// vertex 0 is particle `first`), and the total mass (if > 0).
inline void expect_consistent(const Simulation& sim, std::uint32_t first,
                              const std::vector<std::uint32_t>& removed_vertices, double mass) {
  auto check = SimulationInternals::check_colors(sim);
  ASSERT_TRUE(check.ok()) << check.error().message();
  EXPECT_EQ(check->conflicts, 0u);
  for (const auto& [kernel, particles] : check->in_use)
    for (std::uint32_t v : removed_vertices)
      EXPECT_EQ(std::count(particles.begin(), particles.end(), first + v), 0) << "a constraint names removed vertex " << v;
  if (mass > 0.0) {
    EXPECT_NEAR(check->total_mass, mass, 1e-6 * mass);
  }
}

// Runs `script` (cuts and frames on a backend; [out] the final positions;
// false: no such device) on the CPU and on every backend with a device:
// positions within 1e-5 m of the CPU's.
inline void expect_backends_agree(const std::function<bool(const std::string&, std::vector<float>&)>& script) {
  std::vector<float> reference;
  ASSERT_TRUE(script("cpu", reference));
  for (const std::string& backend : backends()) {
    if (backend == "cpu" || !missing_device(backend).empty()) continue;
    std::vector<float> x;
    ASSERT_TRUE(script(backend, x)) << backend;
    ASSERT_EQ(x.size(), reference.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) worst = std::max(worst, double(std::abs(x[i] - reference[i])));
    std::printf("%s: largest difference from the CPU %.3g m\n", backend.c_str(), worst);
    EXPECT_LT(worst, 1e-5) << backend;
  }
}

}  // namespace sinew::test
