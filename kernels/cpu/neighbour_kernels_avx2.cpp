// neighbour_kernels_avx2.cpp — the neighbour query of neighbour_kernels.cpp
// (kernels/shared/neighbour_params.h) for up to eight points of one cell at
// a time with AVX2, for the CPU backend's speed. The same cells in the same
// order, the same float operations ((ex ex + ey ey) + ez ez, no fused
// multiply-add), so it finds the same neighbours in the same order as the
// scalar reference (tests/neighbour_search_test.cpp compares the lists
// word for word). An earlier version put eight candidates of one point in
// the lanes: transposing them from float4s cost more than the tests.
//
// Only the functions in the target("avx2") region use AVX2; the CPU backend
// calls this only where cpu_has_avx2().
#include <immintrin.h>

#include <cstdint>

#include "cpu/avx2_cells.h"
#include "cpu/avx2_lanes.h"
#include "cpu/neighbour_kernels.h"
#include "neighbour_params.h"

namespace sinew::kernels {

#pragma GCC push_options
#pragma GCC target("avx2")

namespace {

using u32 = std::uint32_t;

}  // namespace

void nbr_query_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const NeighbourParams*>(params);
  const u32 stored = reinterpret_cast<const u32*>(bindings[0])[p.count_word];
  const u32 n = stored < p.capacity ? stored : p.capacity;
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  const auto* order = reinterpret_cast<const u32*>(bindings[4]);
  auto* lists = reinterpret_cast<u32*>(bindings[5]);
  auto* neighbours = reinterpret_cast<u32*>(bindings[6]);
  const __m256 radius2 = _mm256_set1_ps(p.radius2);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const u32 last = end < n ? end : n;
  avx2::CellRuns runs;
  // Up to eight points of one cell in the lanes: they share the 27 cells'
  // candidates, each read once and broadcast to every lane, and each lane
  // takes the candidates within the radius in candidate order, as the
  // scalar reference does for one point.
  for (u32 s = begin; s < last;) {
    const u32 k = avx2::same_cell_run(cells, s, last);
    u32 index[8];
    for (u32 j = 0; j < 8; ++j) index[j] = s + (j < k ? j : 0);
    const avx2::Lanes x = avx2::load_particles(points, index);
    const __m256i self = _mm256_add_epi32(_mm256_set1_epi32(int(s)), lane);
    const u32 lanes = (1u << k) - 1u;
    runs.look_up(cells + 4 * std::size_t{s}, cells, ranges, p.table_mask);
    u32 found[8] = {0, 0, 0, 0, 0, 0, 0, 0}, first[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    if (p.mode == 1)
      for (u32 j = 0; j < k; ++j) first[j] = lists[order[s + j]];
    __m256i counted = _mm256_setzero_si256();
    for (const avx2::CellRuns::Run& r : runs.runs)
      for (u32 t = r.begin; t < r.end; ++t) {
        if (r.mixed) {
          const int* ct = cells + 4 * std::size_t{t};
          if (!(ct[0] == r.cx && ct[1] == r.cy && ct[2] == r.cz)) continue;
        }
        const float* y = points + 4 * std::size_t{t};
        const __m256 ex = _mm256_sub_ps(_mm256_set1_ps(y[0]), x.x), ey = _mm256_sub_ps(_mm256_set1_ps(y[1]), x.y),
                     ez = _mm256_sub_ps(_mm256_set1_ps(y[2]), x.z);
        const __m256 d2 =
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey)), _mm256_mul_ps(ez, ez));
        const __m256i hit = _mm256_andnot_si256(_mm256_cmpeq_epi32(self, _mm256_set1_epi32(int(t))),
                                                _mm256_castps_si256(_mm256_cmp_ps(d2, radius2, _CMP_LT_OQ)));
        if (p.mode == 0) {
          counted = _mm256_sub_epi32(counted, hit);  // -1 per hit
          continue;
        }
        u32 mask = u32(_mm256_movemask_ps(_mm256_castsi256_ps(hit))) & lanes;
        while (mask != 0) {  // the lanes it hits, in lane order
          const u32 j = u32(__builtin_ctz(mask));
          mask &= mask - 1u;
          if (first[j] + found[j] < p.out_capacity) neighbours[first[j] + found[j]] = order[t];
          ++found[j];
        }
      }
    if (p.mode == 0) {
      alignas(32) u32 count[8];
      _mm256_store_si256(reinterpret_cast<__m256i*>(count), counted);
      for (u32 j = 0; j < k; ++j) lists[order[s + j]] = count[j];
    }
    s += k;
  }
}

#pragma GCC pop_options

}  // namespace sinew::kernels
