// body_attachment_agreement_test.cpp — xpbd_solve_body_attachment on every
// GPU backend against the CPU reference (see agreement_support.h): random
// pairs of barycentric points (1 to 4 particles a side, unused slots
// repeating the side's first particle with weight 0), some particles or
// whole sides immovable, compliances 0 and not, break forces never, above
// and below the force the solve reaches, some already broken, first and
// later iterations, the measuring pass. The broken flags must agree
// bitwise: a break the CPU sees and a GPU misses would change the scene.
// And a block torn from another as some of its attachments break, 60
// frames on each backend against the CPU.
#include "agreement_support.h"

#include <cstdio>

#include "contact_params.h"
#include "sinew/scene.h"
#include "sinew/simulation.h"

namespace sinew::test {
namespace {

using kernels::SolveParams;

TEST_P(Agreement, BodyAttachmentKernel) {
  const unsigned seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), alpha(0.0f, 1e-4f), lam(-1e-2f, 1e-2f),
      force(1.0f, 4000.0f);
  const std::uint32_t first = 3, count = 300 + rng() % 50, total = first + count + 5;
  for (bool reset : {false, true}) {
    for (bool measure : {false, true}) {
      std::vector<float> x = random_particles(rng, 8 * total);
      std::vector<std::uint32_t> idx = one_colour(rng, total, 8);
      std::vector<float> data, lambda;
      std::uint32_t breakable = 0;
      for (std::uint32_t i = 0; i < total; ++i) {
        float w[8] = {};
        for (int side = 0; side < 2; ++side) {
          const std::uint32_t used = 1 + rng() % 4;
          float sum = 0.0f;
          for (std::uint32_t k = 0; k < used; ++k) sum += (w[4 * side + k] = unit(rng) + 0.01f);
          for (std::uint32_t k = 0; k < used; ++k) w[4 * side + k] /= sum;
          for (std::uint32_t k = used; k < 4; ++k) idx[8 * i + 4 * side + k] = idx[8 * i + 4 * side];
        }
        if (i % 13 == 5)  // a wholly immovable side
          for (int k = 0; k < 4; ++k) x[4 * idx[8 * i + k] + 3] = 0.0f;
        if (i % 29 == 7)  // both sides immovable
          for (int k = 0; k < 8; ++k) x[4 * idx[8 * i + k] + 3] = 0.0f;
        if (i % 17 == 3) {  // the two points on each other: single vertices at one place
          w[0] = w[4] = 1.0f;
          for (int k = 1; k < 4; ++k) w[k] = w[4 + k] = 0.0f, idx[8 * i + k] = idx[8 * i], idx[8 * i + 4 + k] = idx[8 * i + 4];
          for (int k = 0; k < 3; ++k) x[4 * idx[8 * i + 4] + k] = x[4 * idx[8 * i] + k];
        }
        // Break force: 0 (never) for a quarter, else random around the
        // forces |lambda| / h^2 the solve reaches (up to thousands here).
        const float brk = i % 4 == 0 ? 0.0f : force(rng);
        const float broken = i % 23 == 11 ? 1.0f : 0.0f;
        breakable += brk > 0.0f && broken == 0.0f;
        data.insert(data.end(), w, w + 8);
        const float rest = i % 2 == 1 ? 0.01f * unit(rng) : 0.0f;  // [m]: half with a rest length
        data.insert(data.end(), {i % 3 == 0 ? 0.0f : alpha(rng), brk, broken, rest});
        lambda.push_back(lam(rng));
      }
      KernelCase c{Kernel::xpbd_solve_body_attachment, count, {}, {}};
      c.bindings.push_back({x, false, 4});
      c.bindings.push_back({as_words(idx), false});
      c.bindings.push_back({data, false, 4});
      c.bindings.push_back({lambda, reset && !measure});
      c.bindings.push_back({std::vector<float>(total, 0.0f), measure});
      c.params = bytes_of(SolveParams{first, count, 3600.0f, reset ? 1u : 0u, 1.0f / 60.0f, 1.0f,
                                      measure ? 1u : 0u, 0});
      const std::string what = std::string("body attachment") + (reset ? " reset" : "") + (measure ? " measure" : "");
      const auto ref = run_on("cpu", c);
      const auto gpu = run_on(GetParam(), c);
      expect_agree(c, ref, gpu, what);
      report_difference(c, ref, gpu, GetParam() + " " + what);
      std::uint32_t broke = 0, flags_differ = 0;
      for (std::uint32_t i = first; i < first + count; ++i) {
        broke += ref[2][12 * i + 10] != data[12 * i + 10];
        flags_differ += ref[2][12 * i + 10] != gpu[2][12 * i + 10];
      }
      EXPECT_EQ(flags_differ, 0u) << what << ": broken flags differ";
      if (!measure) EXPECT_GT(broke, 0u) << what << ": no attachment broke; the case does not test breaking";
      if (!measure) EXPECT_LT(broke, breakable) << what << ": every breakable attachment broke";
      if (measure) EXPECT_EQ(broke, 0u) << what << ": the measuring pass broke an attachment";
      std::printf("[ agree    ] %s on %s: %u of %u breakable attachments broke, flags equal\n", what.c_str(),
                  GetParam().c_str(), broke, breakable);
    }
  }
}

// A 4 x 2 x 4 cm block hung face to face (25 vertex-to-vertex attachments)
// from a pinned one, the attachments' break forces spread from 0.5 to 2
// times the load each carries at rest: the weakest break first, the rest
// then carry more and follow, and the block falls away; 60 frames on each
// backend against the CPU (a break one device missed would show).
TEST_P(Agreement, BodyAttachmentSceneAfter60Frames) {
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 8, .iterations = 4};
  const auto block = [](double y0) {
    TetBodyDesc b;
    b.mesh = box_mesh(4, 2, 4, 0.01);
    for (Vec3d& v : b.mesh.vertices) v[1] += y0;
    EXPECT_TRUE(b.set_elastic(5e3, 0.3).ok());
    return b;
  };
  TetBodyDesc a = block(0.02), b = block(0.0);
  for (std::uint32_t v = 0; v < a.mesh.vertices.size(); ++v)
    if (a.mesh.vertices[v][1] > 0.04 - 1e-9) a.pinned.push_back(v);
  const double load = 1000.0 * 0.04 * 0.02 * 0.04 * 9.81 / 25.0;  // [N] per attachment
  for (std::uint32_t v = 0; v < b.mesh.vertices.size(); ++v) {
    if (b.mesh.vertices[v][1] < 0.02 - 1e-9) continue;
    std::uint32_t u = 0;  // A's vertex at the same place
    for (std::uint32_t w = 0; w < a.mesh.vertices.size(); ++w)
      if (std::abs(a.mesh.vertices[w][0] - b.mesh.vertices[v][0]) < 1e-9 &&
          std::abs(a.mesh.vertices[w][1] - b.mesh.vertices[v][1]) < 1e-9 &&
          std::abs(a.mesh.vertices[w][2] - b.mesh.vertices[v][2]) < 1e-9)
        u = w;
    BodyAttachmentDesc link;
    link.a = {BodyKind::tet, 0, {u}, {1.0}};
    link.b = {BodyKind::tet, 1, {v}, {1.0}};
    link.compliance = 1e-4;
    link.break_force = load * (0.5 + 1.5 * double(scene.body_attachments.size() % 5) / 4.0);
    scene.body_attachments.push_back(link);
  }
  scene.tet_bodies = {a, b};
  auto cpu = create_or_skip(scene, "cpu");
  auto gpu = create_or_skip(scene, GetParam());
  ASSERT_TRUE(cpu.ok()) << cpu.error().message();
  ASSERT_TRUE(gpu.ok()) << gpu.error().message();
  for (int f = 0; f < 60; ++f) ASSERT_TRUE(cpu->step().ok() && gpu->step().ok());
  std::vector<float> x, y;
  ASSERT_TRUE(cpu->read_positions(x).ok() && gpu->read_positions(y).ok());
  double worst = 0.0, lowest = 1.0;
  for (std::size_t i = 0; i < x.size(); i += 4) {
    worst = std::max(worst, std::hypot(double(x[i]) - y[i], double(x[i + 1]) - y[i + 1], double(x[i + 2]) - y[i + 2]));
    lowest = std::min(lowest, double(x[i + 1]));
  }
  EXPECT_LT(lowest, -0.02) << "some attachments broke and the block tore away";
  EXPECT_LT(worst, 1e-4 * 0.06) << "largest position difference " << worst << " m";
  std::printf("[ agree    ] hung block 60 frames, %s vs cpu: largest difference %.3e m; lowest vertex %.3g m\n",
              GetParam().c_str(), worst, lowest);
}

}  // namespace
}  // namespace sinew::test
