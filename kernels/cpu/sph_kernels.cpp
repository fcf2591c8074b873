// sph_kernels.cpp — CPU reference of the fluid's kernels
// (kernels/shared/sph_params.h; Müller, Charypar and Gross, SCA 2003, for
// the poly6 density). They visit the neighbour grid's cells in the order of
// nbr_query (neighbour_kernels.cpp) and round every float operation in the
// GPU twins' order (kernels/gpu/sph_*.gpu).
#include <cstdint>

#include "cpu/cpu_kernels.h"
#include "cpu/neighbour_cells.h"
#include "sph_params.h"

namespace sinew::kernels {
namespace {

using u32 = std::uint32_t;
using cells::bucket_of;
using cells::same_cell;

}  // namespace

void sph_density(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphParams*>(params);
  const u32 stored = reinterpret_cast<const u32*>(bindings[0])[p.count_word];
  const u32 n = stored < p.capacity ? stored : p.capacity;
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  auto* density = reinterpret_cast<float*>(bindings[4]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    const int* c = cells + 4 * std::size_t{s};
    float sum = 0.0f;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
          const u32 b = bucket_of(cx, cy, cz, p.table_mask);
          const u32 run = ranges[3 * std::size_t{b}], run_end = ranges[3 * std::size_t{b} + 1];
          const bool mixed = ranges[3 * std::size_t{b} + 2] != 0;
          if (run == run_end || (!mixed && !same_cell(cells + 4 * std::size_t{run}, cx, cy, cz))) continue;
          for (u32 t = run; t < run_end; ++t) {
            if (mixed && !same_cell(cells + 4 * std::size_t{t}, cx, cy, cz)) continue;
            const float* y = points + 4 * std::size_t{t};
            const float ex = y[0] - x[0], ey = y[1] - x[1], ez = y[2] - x[2];
            const float d2 = ex * ex + ey * ey + ez * ez;
            if (!(d2 < p.h2)) continue;
            const float q = p.h2 - d2;
            const float w = q * q * q;
            sum = sum + y[3] * w;
          }
        }
    density[s] = p.poly6 * sum;
  }
}

}  // namespace sinew::kernels
