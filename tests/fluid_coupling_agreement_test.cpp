// fluid_coupling_agreement_test.cpp — the kernels that couple a fluid with
// its scene's tissue on the device (kernels/shared/fluid_coupling_params.h)
// against their CPU reference, on random samples and particle lists, with
// and without the host's forces to add to.
#include <random>

#include "agreement_support.h"
#include "fluid_coupling_params.h"

namespace sinew::test {
namespace {

TEST_P(Agreement, FluidCouplingKernels) {
  std::mt19937 rng(std::random_device{}());
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), w01(0.0f, 1.0f);
  const std::uint32_t particles = 500 + rng() % 50, fixed = 37, samples = 900 + rng() % 50;
  const std::uint32_t boundary = fixed + samples;
  // Samples on random triangles of the particles, weights summing to 1.
  std::vector<std::uint32_t> sample_particles(4 * samples);
  std::vector<float> sample_weights(4 * samples);
  for (std::uint32_t s = 0; s < samples; ++s) {
    const float a = w01(rng), b = w01(rng) * (1.0f - a);
    const float w[4] = {a, b, 1.0f - a - b, 0.0f};
    for (int k = 0; k < 4; ++k) {
      sample_particles[4 * s + k] = k < 3 ? std::uint32_t(rng() % particles) : 0u;
      sample_weights[4 * s + k] = w[k];
    }
  }
  std::vector<float> position(4 * particles), velocity(4 * particles), impulse(4 * boundary);
  for (float& c : position) c = u(rng);
  for (float& c : velocity) c = u(rng);
  for (float& c : impulse) c = 1e-6f * u(rng);
  kernels::FluidCouplingParams params{};
  params.boundary = boundary;
  params.first = fixed;
  params.inv_frame = 500.0f;
  KernelCase follow{Kernel::fluid_boundary_follow, boundary,
                    {{as_words(sample_particles), false, 4}, {sample_weights, false, 4}, {position, false, 4},
                     {velocity, false, 4}, {std::vector<float>(4 * boundary), true, 4},
                     {std::vector<float>(4 * boundary), true, 4}, {impulse, false, 4}},
                    bytes_of(params)};
  // The fixed boundary's positions are not the kernel's: compare what it writes.
  auto ref = run_on("cpu", follow), gpu = run_on(GetParam(), follow);
  expect_agree(follow, ref, gpu, "fluid_boundary_follow");

  // Every particle a list of (sample, weight) entries, a third with none.
  std::vector<std::uint32_t> vertex_particle, offsets{0}, entry_sample;
  std::vector<float> entry_weight;
  for (std::uint32_t p = 0; p < particles; ++p) {
    if (rng() % 3 == 0) continue;
    vertex_particle.push_back(p);
    for (std::uint32_t e = 0, n = 1 + rng() % 6; e < n; ++e) {
      entry_sample.push_back(rng() % samples);
      entry_weight.push_back(w01(rng));
    }
    offsets.push_back(static_cast<std::uint32_t>(entry_sample.size()));
  }
  params.vertices = static_cast<std::uint32_t>(vertex_particle.size());
  std::vector<float> host_force(4 * particles);
  for (float& c : host_force) c = 1e-3f * u(rng);
  for (std::uint32_t add : {0u, 1u}) {
    params.add = add;
    KernelCase forces{Kernel::fluid_forces_on_tissue, params.vertices,
                      {{as_words(vertex_particle), false, 1}, {as_words(offsets), false, 1},
                       {as_words(entry_sample), false, 1}, {entry_weight, false, 1}, {impulse, false, 4},
                       {host_force, false, 4}},
                      bytes_of(params)};
    expect_agree(forces, run_on("cpu", forces), run_on(GetParam(), forces),
                 add ? "fluid_forces_on_tissue (added)" : "fluid_forces_on_tissue");
  }
}

}  // namespace
}  // namespace sinew::test
