// fluid_coupling_kernels.cpp — CPU reference of the kernels that couple a
// fluid with the tissue of its scene on one device (kernels/shared/
// fluid_coupling_params.h): the order of operations of SurfaceSamples::
// positions_on and spread_to_vertices (src/fluid/boundary_sampling.cpp),
// so the device path gives the host path's very floats.
#include <cstdint>

#include "cpu/cpu_kernels.h"
#include "fluid_coupling_params.h"

namespace sinew::kernels {

using u32 = std::uint32_t;

void fluid_boundary_follow(const void* params, std::byte* const* bindings, u32 begin, u32 end) {
  const auto& p = *static_cast<const FluidCouplingParams*>(params);
  const auto* particles = reinterpret_cast<const u32*>(bindings[0]);
  const auto* weights = reinterpret_cast<const float*>(bindings[1]);
  const auto* position = reinterpret_cast<const float*>(bindings[2]);
  const auto* velocity = reinterpret_cast<const float*>(bindings[3]);
  auto* boundary_position = reinterpret_cast<float*>(bindings[4]);
  auto* boundary_velocity = reinterpret_cast<float*>(bindings[5]);
  auto* impulse = reinterpret_cast<float*>(bindings[6]);
  for (u32 b = begin; b < end && b < p.boundary; ++b) {
    for (int a = 0; a < 4; ++a) impulse[4 * std::size_t{b} + a] = 0.0f;
    if (b < p.first) continue;
    const std::size_t s = b - p.first;
    const u32* q = particles + 4 * s;
    const float* w = weights + 4 * s;
    float* x = boundary_position + 4 * std::size_t{b};
    float* v = boundary_velocity + 4 * std::size_t{b};
    for (int a = 0; a < 3; ++a) {
      float xa = 0.0f, va = 0.0f;
      for (int k = 0; k < 3; ++k) {
        xa += w[k] * position[4 * std::size_t{q[k]} + a];
        va += w[k] * velocity[4 * std::size_t{q[k]} + a];
      }
      x[a] = xa;
      v[a] = va;
    }
    x[3] = v[3] = 0.0f;
  }
}

void fluid_forces_on_tissue(const void* params, std::byte* const* bindings, u32 begin, u32 end) {
  const auto& p = *static_cast<const FluidCouplingParams*>(params);
  const auto* vertex_particle = reinterpret_cast<const u32*>(bindings[0]);
  const auto* offsets = reinterpret_cast<const u32*>(bindings[1]);
  const auto* entry_sample = reinterpret_cast<const u32*>(bindings[2]);
  const auto* entry_weight = reinterpret_cast<const float*>(bindings[3]);
  const auto* impulse = reinterpret_cast<const float*>(bindings[4]);
  auto* force = reinterpret_cast<float*>(bindings[5]);
  for (u32 i = begin; i < end && i < p.vertices; ++i) {
    float f[3] = {0.0f, 0.0f, 0.0f};
    for (u32 e = offsets[i]; e < offsets[i + 1]; ++e) {
      const float* j = impulse + 4 * (std::size_t{p.first} + entry_sample[e]);
      for (int a = 0; a < 3; ++a) f[a] += entry_weight[e] * (j[a] * p.inv_frame);
    }
    float* out = force + 4 * std::size_t{vertex_particle[i]};
    for (int a = 0; a < 3; ++a) out[a] = p.add != 0u ? out[a] + f[a] : f[a];
  }
}

}  // namespace sinew::kernels
