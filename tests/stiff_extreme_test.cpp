// The stiff and extreme suite: each case runs 500 frames on every built
// backend and must keep every position finite, its kinetic energy under a
// stated bound and its volume within a stated band, every frame. The
// measured extremes are printed (the README's stability table quotes them).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <ostream>

#include "test_support.h"

namespace sinew {
namespace {

struct ExtremeCase {
  std::string name;
  std::function<SceneDesc()> scene;
  double max_kinetic_energy;          // [J]
  double min_volume_change, max_volume_change;  // band for FrameStats::volume_change, every frame
};

// gtest prints parameters in test names: the case's name, not its bytes.
void PrintTo(const ExtremeCase& c, std::ostream* os) { *os << c.name; }

// A 4 cm cube of soft tissue hanging from its top face.
TetBodyDesc hanging_cube(int cells = 4) {
  TetBodyDesc body;
  body.mesh = test::box_mesh(cells, cells, cells, 0.04 / cells);
  body.density = 1000.0;
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] > 0.04 - 1e-9) body.pinned.push_back(v);
  return body;
}

SceneDesc with(TetBodyDesc body, SolverSettings solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 2}) {
  SceneDesc scene;
  scene.solver = solver;
  scene.tet_bodies.push_back(std::move(body));
  return scene;
}

// Potential energy scale of the cube: m g L = 0.064 kg * 9.81 * 0.04 m = 0.025 J.
constexpr double kCubeEnergy = 0.064 * 9.81 * 0.04;

std::vector<ExtremeCase> cases() {
  std::vector<ExtremeCase> c;
  c.push_back({"RigidConstraints",
               [] {
                 TetBodyDesc b = hanging_cube();
                 b.distance_compliance = 0.0;
                 b.volume_compliance = 0.0;
                 return with(b);
               },
               kCubeEnergy, -0.01, 0.01});
  c.push_back({"YoungsModulus1e9",
               [] {
                 TetBodyDesc b = hanging_cube();
                 (void)b.set_elastic(1e9, 0.3);
                 return with(b);
               },
               kCubeEnergy, -0.01, 0.01});
  c.push_back({"NearlyIncompressible",
               [] {
                 TetBodyDesc b = hanging_cube();
                 (void)b.set_elastic(3e4, 0.499);
                 return with(b);
               },
               kCubeEnergy, -0.01, 0.01});
  for (auto [name, model] : {std::pair{"Corotational", TetMaterial::corotational}, std::pair{"StVK", TetMaterial::stvk}}) {
    c.push_back({std::string(name) + "E1e9",
                 [model] {
                   TetBodyDesc b = hanging_cube();
                   (void)b.set_material(model, 1e9, 0.3);
                   return with(b);
                 },
                 kCubeEnergy, -0.01, 0.01});
    c.push_back({std::string(name) + "Nu0499",
                 [model] {
                   TetBodyDesc b = hanging_cube();
                   (void)b.set_material(model, 3e4, 0.499);
                   return with(b);
                 },
                 kCubeEnergy, -0.01, 0.01});
  }
  c.push_back({"LargeStepOneSubstep",
               [] {
                 TetBodyDesc b = hanging_cube();
                 (void)b.set_elastic(3e4, 0.45);
                 return with(b, {.time_step = 1.0 / 30.0, .substeps = 1, .iterations = 5});
               },
               kCubeEnergy, -0.05, 0.05});
  c.push_back({"StartsHalfCompressed",
               [] {
                 TetBodyDesc b = hanging_cube();
                 (void)b.set_elastic(3e4, 0.45);
                 b.pinned.clear();  // free, so it can expand in every direction
                 for (Vec3d p : b.mesh.vertices) b.initial_vertices.push_back({p[0], 0.5 * p[1], p[2]});
                 SceneDesc s = with(b);
                 s.gravity = {0.0, 0.0, 0.0};
                 return s;
               },
               // It springs back: the stored elastic energy at 50% strain,
               // ~ E/2 * 0.5^2 * V = 0.06 J, bounds the kinetic energy.
               0.1, -0.55, 0.1});
  c.push_back({"Slivers100To1",
               [] {
                 // Cells 100 times wider than tall: tets of aspect ratio ~100.
                 TetBodyDesc b;
                 auto mesh = make_tet_grid({.nx = 4, .ny = 4, .nz = 4, .origin = {0, 0, 0},
                                            .cell_size = {0.01, 0.0001, 0.01}});
                 b.mesh = *mesh;
                 (void)b.set_elastic(3e4, 0.45);
                 for (std::uint32_t v = 0; v < b.mesh.vertices.size(); ++v)
                   if (b.mesh.vertices[v][0] < 1e-9) b.pinned.push_back(v);
                 return with(b);
               },
               // The edge network resists volume change badly on slivers: a
               // hanging sliver slab loses up to ~11% of its volume (README).
               1e-3, -0.15, 0.05});
  c.push_back({"MassRatio1e4",
               [] {
                 // A 10 kg weight on a chain of 1 g links: mass ratio 10^4.
                 LineBodyDesc chain;
                 for (int i = 0; i <= 10; ++i) {
                   chain.vertices.push_back({0.0, -0.01 * i, 0.0});
                   chain.masses.push_back(i == 10 ? 10.0 : 1e-3);
                   if (i > 0) chain.segments.push_back({std::uint32_t(i - 1), std::uint32_t(i)});
                 }
                 chain.pinned = {0};
                 chain.compliance = 1e-7;
                 // Gauss-Seidel converges slowly at this mass ratio: with 4
                 // substeps x 4 iterations the weight sinks 1.2 m (README);
                 // small steps hold it.
                 SceneDesc s;
                 s.solver = {.time_step = 1.0 / 60.0, .substeps = 60, .iterations = 1};
                 s.line_bodies.push_back(chain);
                 return s;
               },
               // Holding means the weight falls less than 5 cm: m g 0.05 m.
               10.0 * 9.81 * 0.05, 0.0, 0.0});
  c.push_back({"ThreadPulledTaut",
               [] {
                 // An inextensible thread whose ends are attached (compliance
                 // 0) to two targets 10% further apart than its length:
                 // constraints that cannot all hold.
                 LineBodyDesc thread;
                 const int n = 50;
                 for (int i = 0; i <= n; ++i) {
                   thread.vertices.push_back({0.001 * i, 0.0, 0.0});
                   thread.initial_vertices.push_back({0.0011 * i, 0.0, 0.0});
                   thread.masses.push_back(1e-5);
                   if (i > 0) thread.segments.push_back({std::uint32_t(i - 1), std::uint32_t(i)});
                 }
                 SceneDesc s;
                 s.line_bodies.push_back(thread);
                 s.targets = {{0.0, 0.0, 0.0}, {0.0011 * n, 0.0, 0.0}};
                 s.attachments = {{.vertex = {.body_kind = BodyKind::line, .body = 0, .vertex = 0}, .target = 0},
                                  {.vertex = {.body_kind = BodyKind::line, .body = 0, .vertex = std::uint32_t(n)},
                                   .target = 1}};
                 return s;
               },
               1e-3, 0.0, 0.0});
  return c;
}

class Extreme : public ::testing::TestWithParam<std::tuple<std::string, ExtremeCase>> {};

TEST_P(Extreme, StaysFiniteBoundedAndKeepsItsVolume) {
  const auto& [backend, c] = GetParam();
  if (const std::string why = test::missing_device(backend); !why.empty()) GTEST_SKIP() << why;
  auto sim = test::create_or_skip(c.scene(), backend);
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  double max_ke = 0.0, min_dv = 0.0, max_dv = 0.0;
  std::vector<float> x;
  for (int f = 0; f < 500; ++f) {
    SINEW_ASSERT_OK(sim->step());
    const FrameStats& s = sim->last_frame();
    ASSERT_TRUE(std::isfinite(s.kinetic_energy) && std::isfinite(s.volume_change)) << "frame " << f;
    max_ke = std::max(max_ke, s.kinetic_energy);
    min_dv = std::min(min_dv, s.volume_change);
    max_dv = std::max(max_dv, s.volume_change);
    if (f % 50 == 49) {
      SINEW_ASSERT_OK(sim->read_positions(x));
      for (float v : x) ASSERT_TRUE(std::isfinite(v)) << "frame " << f;
    }
  }
  std::printf("[ extreme  ] %-22s max kinetic energy %.3e J, volume change [%+.4f%%, %+.4f%%], final residual %.2e\n",
              c.name.c_str(), max_ke, 100 * min_dv, 100 * max_dv, sim->last_frame().residual_rms);
  EXPECT_LE(max_ke, c.max_kinetic_energy);
  EXPECT_GE(min_dv, c.min_volume_change);
  EXPECT_LE(max_dv, c.max_volume_change);
}

INSTANTIATE_TEST_SUITE_P(Cases, Extreme, ::testing::Combine(::testing::ValuesIn(test::backends()), ::testing::ValuesIn(cases())),
                         [](const auto& param_info) {
                           return std::get<0>(param_info.param) + "_" + std::get<1>(param_info.param).name;
                         });

}  // namespace
}  // namespace sinew
