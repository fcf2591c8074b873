// Every GPU backend against the CPU reference backend:
//  - kernel by kernel: random inputs (fresh each run), outputs poisoned
//    with NaN before the run, one dispatch on each device, results within
//    1e-5 relative (float32 rounding of a few operations; the GPU kernels,
//    kernels/gpu/NAME.gpu compiled to OpenCL C and SPIR-V, use the CPU
//    kernels' operation order, so most results are bitwise equal and the
//    tolerance only covers sqrt/division rounding differences a device may
//    have);
//  - scene by scene: after 100 frames positions agree within 1e-4 of the
//    bounding-box diagonal.
// A backend that is built but has no device here is skipped.
#include "agreement_support.h"

namespace sinew::test {
namespace {

TEST_P(Agreement, PredictAndUpdateVelocityKernels) {
  std::mt19937 rng(std::random_device{}());
  const std::uint32_t n = 1000 + rng() % 100;
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> v(4 * n);
  for (float& c : v) c = u(rng);
  KernelCase predict{Kernel::xpbd_predict, n, {{random_particles(rng, n), false, 4}, {std::vector<float>(4 * n), true, 4}, {v, false, 4}}, {}};
  predict.params = bytes_of(kernels::PredictParams{1.0f / 240.0f, 0.1f, -9.81f, 0.3f, n, 0, 0, 0});
  expect_agree(predict, run_on("cpu", predict), run_on(GetParam(), predict), "predict");

  KernelCase update{Kernel::xpbd_update_velocity, n,
                    {{random_particles(rng, n), false, 4}, {random_particles(rng, n), false, 4}, {std::vector<float>(4 * n), true, 4}}, {}};
  update.params = bytes_of(kernels::UpdateVelocityParams{240.0f, n, 1.0f / 240.0f, 0});
  expect_agree(update, run_on("cpu", update), run_on(GetParam(), update), "update_velocity");
}

TEST_P(Agreement, SolveKernels) {
  std::mt19937 rng(std::random_device{}());
  for (auto [kernel, arity] : {std::pair{Kernel::xpbd_solve_distance, 2u}, std::pair{Kernel::xpbd_solve_volume, 4u}}) {
    for (bool reset : {false, true}) {
      for (bool measure : {false, true}) {
        for (float damping : {0.0f, 6.0f}) {  // gamma = tau / h, e.g. tau = 10 ms at 1.7 ms substeps
          if (reset && measure) continue;
          const KernelCase c = solve_case(rng, kernel, arity, 500 + rng() % 50, reset, measure, damping);
          expect_agree(c, run_on("cpu", c), run_on(GetParam(), c),
                       std::string(kernel_name(kernel)) + (reset ? " reset" : "") + (measure ? " measure" : "") +
                           (damping != 0.0f ? " damped" : ""));
        }
      }
    }
  }
}

TEST_P(Agreement, CubeAfter100Frames) {
  TetBodyDesc body;
  body.mesh = test::box_mesh(8, 8, 8, 1.0 / 8);
  ASSERT_TRUE(body.set_elastic(1e5, 0.4).ok());
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] > 1.0 - 1e-9) body.pinned.push_back(v);
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 2, .iterations = 4};
  scene.tet_bodies.push_back(body);
  std::vector<float> x[2];
  int k = 0;
  for (const std::string& backend : {std::string("cpu"), GetParam()}) {
    auto sim = test::create_or_skip(scene, backend);
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    for (int f = 0; f < 100; ++f) ASSERT_TRUE(sim->step().ok());
    ASSERT_TRUE(sim->read_positions(x[k++]).ok());
  }
  const double diagonal = std::sqrt(3.0);
  double worst = 0.0;
  for (std::size_t i = 0; i < x[0].size(); i += 4)
    worst = std::max(worst, std::hypot(double(x[0][i]) - x[1][i], double(x[0][i + 1]) - x[1][i + 1], double(x[0][i + 2]) - x[1][i + 2]));
  EXPECT_LT(worst, 1e-4 * diagonal) << "largest position difference " << worst << " m";
  std::printf("[ agree    ] cube 100 frames, %s vs cpu: largest difference %.3e m (%.2e of the diagonal)\n",
              GetParam().c_str(), worst, worst / diagonal);
}

}  // namespace

// The one instantiation of the Agreement suite (its TEST_Ps live in several files).
INSTANTIATE_TEST_SUITE_P(GpuBackends, Agreement, ::testing::ValuesIn(gpu_backends()), backend_name);

}  // namespace sinew::test
