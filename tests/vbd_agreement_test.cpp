// vbd_agreement_test.cpp — the Vertex Block Descent kernels on every GPU
// backend against the CPU reference (see agreement_support.h):
// vbd_initial_guess and vbd_solve_vertices (kernels/cpu/vbd_kernels.cpp;
// GPU twins kernels/gpu/vbd_*.gpu).
//
// vbd_solve_vertices: one dispatch of one vertex colour of a compiled tet
// grid (its FEM block's data and particles as compile_fem.cpp builds them,
// its colouring and incidences as the program builds them:
// make_vbd_topology), positions deformed (a stretch, a turn, noise that
// inverts some tets), inertia targets near them, corotational tets with no
// rotation kept yet (the exact first solve) or a kept one (the refined
// one), random E and nu, both materials, pinned vertices. The twins use the
// CPU kernel's operation order without contraction: every word is
// expected bitwise equal (expect_agree's 1e-5 relative bound, and the
// report prints how many words differ). Also: the CPU kernel gives the same
// words on 1 and 2 threads.
#include <cmath>
#include <cstdio>
#include <cstring>

#include "agreement_support.h"
#include "compiler/scene_compiler.h"
#include "fem_params.h"
#include "program/vbd_program.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "vbd_params.h"

namespace sinew::test {
namespace {

// A colour of vertices of a 4 x 3 x 3-cell grid of 1 cm, pinned at x = 0.
KernelCase solve_case(std::mt19937& rng, TetMaterial material, bool kept_rotation, std::uint32_t color_pick) {
  SceneDesc scene;
  TetBodyDesc body;
  body.mesh = *make_tet_grid({.nx = 4, .ny = 3, .nz = 3, .origin = {0, 0, 0}, .cell_size = {0.01, 0.01, 0.01}});
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] < 1e-9) body.pinned.push_back(v);
  std::uniform_real_distribution<double> log_e(4.0, 7.5), nu(0.2, 0.45), unit(-1.0, 1.0);
  EXPECT_TRUE(body.set_material(material, std::pow(10.0, log_e(rng)), nu(rng)).ok());
  scene.tet_bodies.push_back(body);
  auto compiled = compile_scene(scene);
  EXPECT_TRUE(compiled.ok()) << compiled.error().message();
  const ConstraintBlock& block = compiled->blocks.at(0);
  const VbdTopology topology = make_vbd_topology(block, compiled->positions);
  const std::uint32_t color = color_pick % std::uint32_t(topology.color_offsets.size() - 1);

  // Deformed: stretched 20% along x, turned 0.3 rad about z, 1 mm of noise
  // (some 1 cm tets invert at 3 mm: a few vertices get that).
  std::vector<float> x, y;
  const double c = std::cos(0.3), s = std::sin(0.3);
  for (std::size_t p = 0; p < compiled->positions.size(); ++p) {
    const kernels::float4 r = compiled->positions[p];
    const double noise = p % 11 == 0 ? 3e-3 : 1e-3;
    const double px = 1.2 * r.x, py = r.y;
    const double dx = c * px - s * py + noise * unit(rng), dy = s * px + c * py + noise * unit(rng),
                 dz = r.z + noise * unit(rng);
    for (float v : {float(dx), float(dy), float(dz), r.w}) x.push_back(v);
    for (float v : {float(dx + 1e-3 * unit(rng)), float(dy + 1e-3 * unit(rng)), float(dz + 1e-3 * unit(rng)), r.w})
      y.push_back(v);
  }
  std::vector<float> state(std::size_t{block.size()} * block.lambda_stride, 0.0f);
  if (kept_rotation && material == TetMaterial::corotational)
    for (std::size_t t = 0; t < block.size(); ++t) {
      float q[4] = {float(1.0 + 0.2 * unit(rng)), float(0.2 * unit(rng)), float(0.2 * unit(rng)),
                    float(0.2 + 0.2 * unit(rng))};
      const float n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      for (int k = 0; k < 4; ++k) state[t * block.lambda_stride + SINEW_FEM_ROTATION + k] = q[k] / n;
    }
  kernels::VbdSolveParams p{};
  p.first = topology.color_offsets[color];
  p.count = topology.color_offsets[color + 1] - p.first;
  p.inv_h2 = 3600.0f;
  p.model = material == TetMaterial::corotational ? SINEW_VBD_COROTATIONAL : SINEW_VBD_NEO_HOOKEAN;
  p.lambda_stride = block.lambda_stride;
  KernelCase k{Kernel::vbd_solve_vertices, p.count, {}, bytes_of(p)};
  k.bindings = {{x, false, 4},
                {y, false, 4},
                {as_words(topology.vertices)},
                {as_words(topology.offsets)},
                {as_words(topology.incidences)},
                {as_words(block.particles)},
                {block.data},
                {state}};
  return k;
}

KernelCase initial_guess_case(std::mt19937& rng) {
  kernels::VbdInitParams p{};
  p.count = 300;
  p.h2g_x = 1e-4f;
  p.h2g_y = -2.7e-3f;
  p.h2g_z = 0.0f;
  KernelCase k{Kernel::vbd_initial_guess, p.count, {}, bytes_of(p)};
  k.bindings = {{random_particles(rng, p.count), false, 4}, {std::vector<float>(4 * p.count), true, 4}};
  return k;
}

TEST_P(Agreement, VbdKernels) {
  std::mt19937 rng(std::random_device{}());
  {
    const KernelCase c = initial_guess_case(rng);
    const auto ref = run_on("cpu", c), gpu = run_on(GetParam(), c);
    expect_agree(c, ref, gpu, "vbd_initial_guess");
    report_difference(c, ref, gpu, GetParam() + " vbd_initial_guess");
  }
  for (TetMaterial material : {TetMaterial::corotational, TetMaterial::neo_hookean})
    for (bool kept : {false, true})
      for (std::uint32_t color : {0u, 3u}) {
        const KernelCase c = solve_case(rng, material, kept, color);
        const std::string what = std::string("vbd_solve_vertices ") +
                                 (material == TetMaterial::corotational ? "corotational" : "neo_hookean") +
                                 (kept ? " kept rotation" : "") + " colour " + std::to_string(color);
        const auto ref = run_on("cpu", c), gpu = run_on(GetParam(), c);
        expect_agree(c, ref, gpu, what);
        report_difference(c, ref, gpu, GetParam() + " " + what);
      }
}

// Whole frames: a stiff corotational cantilever and a Neo-Hookean block
// (pinned, gravity, velocity damping, the Chebyshev accelerator on) run 20
// frames of VBD on the CPU and on the GPU backend: every position bitwise
// equal, and the body did move.
TEST_P(Agreement, VbdFramesAreBitwiseTheCpuOnes) {
  for (TetMaterial material : {TetMaterial::corotational, TetMaterial::neo_hookean}) {
    SceneDesc scene;
    TetBodyDesc body;
    body.mesh = *make_tet_grid({.nx = 8, .ny = 2, .nz = 2, .origin = {0, 0, 0}, .cell_size = {0.01, 0.01, 0.01}});
    for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
      if (body.mesh.vertices[v][0] < 1e-9) body.pinned.push_back(v);
    body.velocity_damping = 5.0;
    ASSERT_TRUE(body.set_material(material, material == TetMaterial::corotational ? 3e7 : 1e5, 0.3).ok());
    scene.tet_bodies.push_back(body);
    scene.solver.method = SolverMethod::vbd;
    scene.solver.iterations = 12;
    scene.solver.chebyshev_rho = 0.95;
    scene.solver.chebyshev_delay = 2;
    std::vector<std::vector<float>> positions;
    for (const std::string& backend : {std::string("cpu"), GetParam()}) {
      auto sim = Simulation::create(scene, {.backend = backend, .quiet = true});
      ASSERT_TRUE(sim.ok()) << backend << ": " << sim.error().message();
      for (int f = 0; f < 20; ++f) ASSERT_TRUE(sim->step().ok()) << backend;
      positions.emplace_back();
      ASSERT_TRUE(sim->read_positions(positions.back()).ok());
    }
    const std::size_t tip = 4 * (body.mesh.vertices.size() - 1) + 1;
    EXPECT_LT(positions[0][tip], float(body.mesh.vertices.back()[1]) - 1e-7f);  // it sagged
    ASSERT_EQ(positions[0].size(), positions[1].size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < positions[0].size(); ++i) differ += positions[0][i] != positions[1][i];
    EXPECT_EQ(differ, 0u) << GetParam() << (material == TetMaterial::corotational ? " corotational" : " neo_hookean");
  }
}

// The CPU reference splits a colour over threads: the same words on 1 and 2.
TEST(CpuVbd, SolveIsTheSameOnOneAndTwoThreads) {
  std::mt19937 rng(std::random_device{}());
  for (TetMaterial material : {TetMaterial::corotational, TetMaterial::neo_hookean}) {
    const KernelCase c = solve_case(rng, material, false, 1);
    const auto one = run_on("cpu", c, true, 1), two = run_on("cpu", c, true, 2);
    ASSERT_EQ(one.size(), two.size());
    std::size_t moved = 0;
    for (std::size_t i = 0; i < c.bindings[0].data.size(); ++i) moved += one[0][i] != c.bindings[0].data[i];
    EXPECT_GT(moved, 0u);  // the case moves vertices (the test can fail)
    for (std::size_t b = 0; b < one.size(); ++b)
      EXPECT_EQ(0, std::memcmp(one[b].data(), two[b].data(), one[b].size() * 4)) << "binding " << b;
  }
}

}  // namespace
}  // namespace sinew::test
