// level_set_kernels.cpp — CPU reference of level_set_sample: a level set's
// value and gradient at points, read from its NanoVDB grid with
// PNanoVDB.h's C mode (level_set_sampling.h; Museth, "NanoVDB: A
// GPU-friendly and portable VDB data structure for real-time rendering and
// simulation", SIGGRAPH 2021 Talks). The interpolation and its order of
// operations: kernels/shared/level_set_params.h; the GPU twin,
// kernels/gpu/level_set_sample.gpu, does the same float operations.
#include <cstdint>

#include "cpu/cpu_kernels.h"
#include "level_set_params.h"
#include "math/vec4.h"

#if SINEW_HAS_OPENVDB
#include "cpu/level_set_sampling.h"
#endif

namespace sinew::kernels {

#if SINEW_HAS_OPENVDB

void level_set_sample(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const LevelSetSampleParams*>(params);
  auto* words = reinterpret_cast<std::uint32_t*>(bindings[0]);
  const auto* points = reinterpret_cast<const float4*>(bindings[1]);
  auto* samples = reinterpret_cast<float4*>(bindings[2]);
  for (std::uint32_t q = begin; q < end && q < p.count; ++q)
    samples[q] = sample_level_set_grid(words, 0u, p.inv_voxel, p.inv_two_voxel, points[q]);
}

#else

// Without NanoVDB nothing makes a grid, so nothing dispatches this.
void level_set_sample(const void*, std::byte* const*, std::uint32_t, std::uint32_t) {}

#endif

}  // namespace sinew::kernels
