// neighbour_kernels_avx2.cpp — the neighbour query of neighbour_kernels.cpp
// (kernels/shared/neighbour_params.h) eight candidates at a time with AVX2,
// for the CPU backend's speed. The same cells in the same order, the same
// float operations ((ex ex + ey ey) + ez ez, no fused multiply-add), so it
// finds the same neighbours in the same order as the scalar reference
// (tests/neighbour_search_test.cpp compares the lists word for word).
//
// Only the functions in the target("avx2") region use AVX2; the CPU backend
// calls this only where cpu_has_avx2().
#include <immintrin.h>

#include <cstdint>

#include "cpu/avx2_lanes.h"
#include "cpu/neighbour_kernels.h"
#include "neighbour_params.h"

namespace sinew::kernels {

#pragma GCC push_options
#pragma GCC target("avx2")

namespace {

using u32 = std::uint32_t;

u32 spread10_avx2(u32 v) {
  v &= 0x3ffu;
  v = (v * 0x00010001u) & 0xFF0000FFu;
  v = (v * 0x00000101u) & 0x0F00F00Fu;
  v = (v * 0x00000011u) & 0xC30C30C3u;
  v = (v * 0x00000005u) & 0x49249249u;
  return v;
}

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
  // The 27 cells' runs of the last point's cell: the points of a cell are
  // next to each other in sorted order, so the next point usually shares
  // them (about eight a cell in a fluid), and the bucket lookups, scattered
  // in memory, are done once a cell instead of once a point. A run that
  // cannot hold the cell (empty, or one other cell's) is kept empty.
  struct Visit {
    u32 run, run_end;
    bool mixed;
  };
  Visit visits[27];
  int cached[3] = {0, 0, 0};
  bool have_cached = false;
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    const int* c = cells + 4 * std::size_t{s};
    const u32 i = order[s];
    const __m256 px = _mm256_set1_ps(x[0]), py = _mm256_set1_ps(x[1]), pz = _mm256_set1_ps(x[2]);
    const __m256i self = _mm256_set1_epi32(int(s));
    u32 found = 0;
    const u32 first = p.mode == 0 ? 0u : lists[i];
    // Fill: hits gather in a batch written out when it may overflow and at the end.
    constexpr u32 kBatch = 64;
    u32 batch[kBatch + 8];
    u32 held = 0;
    const auto flush = [&] {
      for (u32 k = 0; k < held; ++k)
        if (first + found + k < p.out_capacity) neighbours[first + found + k] = batch[k];
      found += held;
      held = 0;
    };
    if (!have_cached || c[0] != cached[0] || c[1] != cached[1] || c[2] != cached[2]) {
      int v = 0;
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx, ++v) {
            const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
            const u32 b = ((spread10_avx2(u32(cx)) << 2) | (spread10_avx2(u32(cy)) << 1) | spread10_avx2(u32(cz))) &
                          p.table_mask;
            Visit& w = visits[v];
            w = {ranges[3 * std::size_t{b}], ranges[3 * std::size_t{b} + 1], ranges[3 * std::size_t{b} + 2] != 0};
            // A run of one cell: all of it or none of it is the visited cell's.
            const int* rc = cells + 4 * std::size_t{w.run};
            if (w.run < w.run_end && !w.mixed && !(rc[0] == cx && rc[1] == cy && rc[2] == cz)) w.run_end = w.run;
          }
      for (int k = 0; k < 3; ++k) cached[k] = c[k];
      have_cached = true;
    }
    int v = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx, ++v) {
          const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
          const u32 run = visits[v].run, run_end = visits[v].run_end;
          const bool mixed = visits[v].mixed;
          if (run == run_end) continue;
          u32 t = run;
          const __m256i ccx = _mm256_set1_epi32(cx), ccy = _mm256_set1_epi32(cy), ccz = _mm256_set1_epi32(cz);
          // Whole groups of eight; a run's last few too, as a group masked
          // to the run, where eight points are there to be read (runs are
          // short: about eight points a cell in a fluid at rest).
          for (; t < run_end && t + 8 <= p.capacity; t += 8) {
            const u32 index[8] = {t, t + 1, t + 2, t + 3, t + 4, t + 5, t + 6, t + 7};
            const avx2::Lanes y = avx2::load_particles(points, index);
            const __m256 ex = _mm256_sub_ps(y.x, px), ey = _mm256_sub_ps(y.y, py), ez = _mm256_sub_ps(y.z, pz);
            const __m256 d2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey)),
                                            _mm256_mul_ps(ez, ez));
            __m256i hit = _mm256_castps_si256(_mm256_cmp_ps(d2, radius2, _CMP_LT_OQ));
            if (mixed) {  // buckets shared by far cells: each point's own cell
              const avx2::Lanes ct = avx2::load_particles(reinterpret_cast<const float*>(cells), index);
              hit = _mm256_and_si256(hit, _mm256_cmpeq_epi32(_mm256_castps_si256(ct.x), ccx));
              hit = _mm256_and_si256(hit, _mm256_cmpeq_epi32(_mm256_castps_si256(ct.y), ccy));
              hit = _mm256_and_si256(hit, _mm256_cmpeq_epi32(_mm256_castps_si256(ct.z), ccz));
            }
            hit = _mm256_andnot_si256(_mm256_cmpeq_epi32(_mm256_add_epi32(_mm256_set1_epi32(int(t)), lane), self), hit);
            const u32 left = run_end - t;
            const u32 mask = u32(_mm256_movemask_ps(_mm256_castsi256_ps(hit))) & (left >= 8 ? 0xffu : (1u << left) - 1u);
            if (p.mode == 1) {
              for (u32 j = 0; j < 8; ++j) {  // in candidate order, branch-free
                batch[held] = order[t + j];  // t + j < capacity: a point, maybe of the next run
                held += (mask >> j) & 1u;
              }
              if (held >= kBatch) flush();
            } else {
              found += u32(__builtin_popcount(mask));
            }
          }
          for (; t < run_end; ++t) {  // at the buffer's end, one by one as the scalar kernel
            const int* cc = cells + 4 * std::size_t{t};
            const float* yy = points + 4 * std::size_t{t};
            const float ex = yy[0] - x[0], ey = yy[1] - x[1], ez = yy[2] - x[2];
            const float d2 = ex * ex + ey * ey + ez * ez;
            const u32 hit = u32(d2 < p.radius2) & u32(t != s) &
                            u32(!mixed || (cc[0] == cx && cc[1] == cy && cc[2] == cz));
            if (p.mode == 1) {
              batch[held] = order[t];
              held += hit;
              if (held >= kBatch) flush();
            } else {
              found += hit;
            }
          }
        }
    if (p.mode == 1) flush();
    if (p.mode == 0) lists[i] = found;
  }
}

#pragma GCC pop_options

}  // namespace sinew::kernels
