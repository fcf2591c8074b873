// vbd_test — Vertex Block Descent (SolverSettings::method = vbd; Chen et al.,
// "Vertex Block Descent", ACM TOG 43(4), SIGGRAPH 2024) against the static
// solution of linear elasticity on the same mesh (tests/linear_elastic_oracle.h):
// a slender stiff beam sagging under its own weight and a block compressed by
// its own weight; a stiff body released from a stretch neither gains energy
// nor produces NaN; pinned vertices stay where they were; and every scene
// feature vbd does not support is a named error from Simulation::create.
// (The GPU backends' agreement with this CPU reference: vbd_agreement_test.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "linear_elastic_oracle.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace sinew {
namespace {

constexpr double kDensity = 1000.0;  // [kg/m^3]

// A box of nx x ny x nz cells of edge `cell` [m] from the origin, pinned
// where its coordinate `axis` is 0.
struct Box {
  TetMesh mesh;
  std::vector<std::uint32_t> pinned;
};

Box box(int nx, int ny, int nz, double cell, int axis) {
  Box b;
  b.mesh = *make_tet_grid({.nx = nx, .ny = ny, .nz = nz, .origin = {0, 0, 0}, .cell_size = {cell, cell, cell}});
  for (std::uint32_t v = 0; v < b.mesh.vertices.size(); ++v)
    if (b.mesh.vertices[v][std::size_t(axis)] < 1e-9) b.pinned.push_back(v);
  return b;
}

SceneDesc vbd_scene(const Box& b, TetMaterial material, double young, double poisson, int iterations,
                    double damping) {
  SceneDesc scene;
  TetBodyDesc body;
  body.mesh = b.mesh;
  body.density = kDensity;
  body.pinned = b.pinned;
  body.velocity_damping = damping;
  EXPECT_TRUE(body.set_material(material, young, poisson).ok());
  scene.tet_bodies.push_back(std::move(body));
  scene.solver.method = SolverMethod::vbd;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 1;
  scene.solver.iterations = iterations;
  return scene;
}

// Runs `frames` frames; returns the displacements [m] per vertex (empty on
// failure, with a test failure).
std::vector<Vec3d> run(const SceneDesc& scene, int frames, std::vector<FrameStats>* stats = nullptr) {
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  EXPECT_TRUE(sim.ok()) << (sim ? "" : sim.error().message());
  if (!sim) return {};
  for (int f = 0; f < frames; ++f) {
    const Status s = sim->step();
    EXPECT_TRUE(s.ok()) << (s ? "" : s.error().message());
    if (!s) return {};
    if (stats) stats->push_back(sim->last_frame());
  }
  std::vector<float> x;
  EXPECT_TRUE(sim->read_positions(x).ok());
  const TetMesh& mesh = scene.tet_bodies[0].mesh;
  std::vector<Vec3d> u(mesh.vertices.size());
  for (std::size_t v = 0; v < u.size(); ++v)
    for (std::size_t k = 0; k < 3; ++k) u[v][k] = double(x[4 * v + k]) - mesh.vertices[v][k];
  return u;
}

// The oracle's mean displacement [m] along y of the vertices whose rest
// coordinate `along` is `at` [m], under `gravity_y` [m/s^2] with b's pins.
double oracle_y(const Box& b, double young, double gravity_y, int along, double at) {
  test::StaticLoads loads;
  loads.density = kDensity;
  loads.gravity = {0.0, gravity_y, 0.0};
  loads.pinned = b.pinned;
  std::string error;
  const std::vector<Vec3d> u = test::solve_linear_elastic(b.mesh, young, 0.3, loads, &error);
  EXPECT_FALSE(u.empty()) << error;
  return u.empty() ? 0.0 : test::mean_displacement(b.mesh, u, 1, along, at);
}

bool all_finite(const std::vector<Vec3d>& u) {
  for (const Vec3d& d : u)
    for (double c : d)
      if (!std::isfinite(c)) return false;
  return !u.empty();
}

// The beam: E = 30 MPa, nu = 0.3, 16 x 2 x 2 cells of 1 cm (two
// elements through its 2 cm thickness, 16 cm long), pinned at x = 0, sagging
// under gravity; the tip is the mean vertical displacement of its x = L face.
TEST(Vbd, StiffBeamSagsAsLinearElasticityWithinFivePercent) {
  const Box b = box(16, 2, 2, 0.01, 0);
  const double tip_oracle = oracle_y(b, 3e7, -9.81, 0, 0.16);
  ASSERT_LT(tip_oracle, 0.0);

  // Few sweeps make a stiff body lag, not soften: undamped, its tip swings
  // slowly about the static state. Velocity damping and the Chebyshev
  // accelerator settle it; neither changes the static state.
  SceneDesc scene = vbd_scene(b, TetMaterial::corotational, 3e7, 0.3, 40, 5.0);
  scene.solver.chebyshev_rho = 0.95;
  scene.solver.chebyshev_delay = 2;
  const std::vector<Vec3d> u = run(scene, 150);
  ASSERT_TRUE(all_finite(u));
  const double tip = test::mean_displacement(b.mesh, u, 1, 0, 0.16);
  std::printf("[ vbd ] beam tip %.4f mm, oracle %.4f mm, ratio %.4f\n", -tip * 1e3, -tip_oracle * 1e3,
              tip / tip_oracle);
  EXPECT_NEAR(tip / tip_oracle, 1.0, 0.05);
}

// A 4 x 4 x 4-cell block (1 cm cells) on its pinned base, compressed by its
// own weight under 100 m/s^2 (strains ~4e-3 at E = 1 MPa); stable
// Neo-Hookean and corotational, top face against the oracle.
TEST(Vbd, BlockInCompressionWithinFivePercent) {
  const Box b = box(4, 4, 4, 0.01, 1);
  const double top_oracle = oracle_y(b, 1e6, -100.0, 1, 0.04);
  ASSERT_LT(top_oracle, 0.0);
  for (TetMaterial material : {TetMaterial::corotational, TetMaterial::neo_hookean}) {
    SceneDesc scene = vbd_scene(b, material, 1e6, 0.3, 20, 0.0);
    scene.gravity = {0.0, -100.0, 0.0};
    const std::vector<Vec3d> u = run(scene, 60);
    ASSERT_TRUE(all_finite(u));
    const double top = test::mean_displacement(b.mesh, u, 1, 1, 0.04);
    std::printf("[ vbd ] block top %.4f mm, oracle %.4f mm, ratio %.4f (%s)\n", -top * 1e3, -top_oracle * 1e3,
                top / top_oracle, material == TetMaterial::corotational ? "corotational" : "neo_hookean");
    EXPECT_NEAR(top / top_oracle, 1.0, 0.05);
  }
}

// Released from a uniform 5% stretch with no pins and no gravity at E =
// 100 GPa (a million times soft tissue), the body may not gain energy: its
// kinetic energy never exceeds the elastic energy it was released with, it
// ends at rest, at its rest volume, with no NaN and no inverted tet.
TEST(Vbd, HugeStiffnessReleasedFromStretchStaysFiniteAndLosesEnergy) {
  Box b = box(4, 4, 4, 0.01, 0);
  b.pinned.clear();
  const double young = 1e11, nu = 0.3, stretch = 0.05;
  for (TetMaterial material : {TetMaterial::corotational, TetMaterial::neo_hookean}) {
    SceneDesc scene = vbd_scene(b, material, young, nu, 10, 0.0);
    scene.gravity = {0.0, 0.0, 0.0};
    for (const Vec3d& v : b.mesh.vertices)
      scene.tet_bodies[0].initial_vertices.push_back({v[0] * (1 + stretch), v[1] * (1 + stretch), v[2] * (1 + stretch)});
    // Elastic energy of the stretch (small-strain): V (mu |eps|^2 + lambda / 2 (tr eps)^2), eps = stretch I.
    const double mu = young / (2 * (1 + nu)), lambda = young * nu / ((1 + nu) * (1 - 2 * nu));
    const double volume = 0.04 * 0.04 * 0.04;
    const double stored = volume * (3 * mu + 4.5 * lambda) * stretch * stretch;
    std::vector<FrameStats> stats;
    const std::vector<Vec3d> u = run(scene, 120, &stats);
    ASSERT_TRUE(all_finite(u));
    double most = 0.0;
    for (const FrameStats& s : stats) {
      EXPECT_TRUE(std::isfinite(s.kinetic_energy));
      most = std::max(most, s.kinetic_energy);
      EXPECT_EQ(s.inverted_tets, 0u);
    }
    std::printf("[ vbd ] stored %.4g J, largest kinetic energy %.4g J, last %.4g J, volume change %.2e\n", stored,
                most, stats.back().kinetic_energy, stats.back().volume_change);
    EXPECT_LE(most, stored);
    EXPECT_LT(stats.back().kinetic_energy, 1e-6 * stored);
    EXPECT_LT(std::abs(stats.back().volume_change), 1e-3);
  }
}

// Pinned vertices are never written: bitwise where they started.
TEST(Vbd, PinnedVerticesStayBitwise) {
  const Box b = box(8, 2, 2, 0.01, 0);
  SceneDesc scene = vbd_scene(b, TetMaterial::corotational, 1e5, 0.3, 5, 0.0);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  std::vector<float> start, x;
  ASSERT_TRUE(sim->read_positions(start).ok());
  for (int f = 0; f < 30; ++f) ASSERT_TRUE(sim->step().ok());
  ASSERT_TRUE(sim->read_positions(x).ok());
  for (std::uint32_t v : b.pinned)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(x[4 * v + k], start[4 * v + k]) << "vertex " << v;
  // ... and the rest of the body did move (the test can fail).
  EXPECT_LT(x[4 * (b.mesh.vertices.size() - 1) + 1], start[4 * (b.mesh.vertices.size() - 1) + 1] - 1e-4f);
}

// Everything vbd does not solve is refused by name, never run by xPBD instead.
TEST(Vbd, UnsupportedCombinationsAreNamedErrors) {
  const Box b = box(2, 2, 2, 0.01, 0);
  const SceneDesc base = vbd_scene(b, TetMaterial::corotational, 1e5, 0.3, 5, 0.0);
  ASSERT_TRUE(Simulation::create(base, {.backend = "cpu", .quiet = true}).ok());
  struct Case {
    const char* what;  // a word the message must contain
    SceneDesc scene;
  };
  std::vector<Case> cases;
  const auto add = [&](const char* what, auto edit) {
    SceneDesc s = base;
    edit(s);
    cases.push_back({what, std::move(s)});
  };
  add("stvk", [](SceneDesc& s) { ASSERT_TRUE(s.tet_bodies[0].set_material(TetMaterial::stvk, 1e5, 0.3).ok()); });
  add("tet_bodies[0]", [](SceneDesc& s) {  // the edge network, not an FEM material
    TetBodyDesc& body = s.tet_bodies[0];
    body.material = TetMaterial::none;
    body.distance_constraints = body.volume_constraints = true;
    ASSERT_TRUE(body.set_elastic(1e5, 0.3).ok());
  });
  add("tri_bodies", [](SceneDesc& s) {
    TriBodyDesc tri;
    tri.mesh.vertices = {{0, 1, 0}, {0.01, 1, 0}, {0, 1, 0.01}};
    tri.mesh.triangles = {{0, 1, 2}};
    s.tri_bodies.push_back(tri);
  });
  add("line_bodies", [](SceneDesc& s) {
    LineBodyDesc line;
    line.vertices = {{0, 1, 0}, {0.01, 1, 0}};
    line.masses = {1e-3, 1e-3};
    line.segments = {{0, 1}};
    s.line_bodies.push_back(line);
  });
  add("colliders", [](SceneDesc& s) { s.colliders.push_back(ColliderDesc{}); });
  add("attachments", [](SceneDesc& s) {
    s.targets.push_back({0.02, 0.02, 0.02});
    AttachmentDesc a;
    a.vertex.vertex = static_cast<std::uint32_t>(s.tet_bodies[0].mesh.vertices.size() - 1);
    s.attachments.push_back(a);
  });
  add("tools", [](SceneDesc& s) { s.tools.push_back(ToolDesc{}); });
  add("needles", [](SceneDesc& s) {
    NeedleDesc needle;
    needle.curve = {{0.0, 0.1, 0.0}, {0.01, 0.1, 0.0}};
    s.needles.push_back(needle);
  });
  add("graspers", [](SceneDesc& s) { s.graspers.push_back(GrasperDesc{}); });
  add("mesh_collision", [](SceneDesc& s) { s.mesh_collision.enabled = true; });
  add("topology_changes", [](SceneDesc& s) { s.topology_changes = true; });
  add("external_forces", [](SceneDesc& s) { s.external_forces = true; });
  add("residual", [](SceneDesc& s) { s.solver.residual_tolerance = 1e-4; });
  for (const Case& c : cases) {
    auto sim = Simulation::create(c.scene, {.backend = "cpu", .quiet = true});
    ASSERT_FALSE(sim.ok()) << c.what;
    const std::string message = sim.error().message();
    EXPECT_NE(message.find("vbd"), std::string::npos) << c.what << ": " << message;
    EXPECT_NE(message.find(c.what), std::string::npos) << c.what << ": " << message;
  }
}

}  // namespace
}  // namespace sinew
