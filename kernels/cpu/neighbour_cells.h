// neighbour_cells.h — the neighbour grid's cells and buckets for the CPU
// reference kernels that visit them (neighbour_kernels.cpp, sph_kernels.cpp;
// the contract: kernels/shared/neighbour_params.h; the GPU's twin:
// kernels/gpu/neighbour_math.h). Not for the AVX2 file, which keeps its own
// copies inside its target region (avx2_lanes.h says why).
#pragma once

#include <cstddef>
#include <cstdint>

namespace sinew::kernels::cells {

/// The low 10 bits of v spread to every third bit (bits 0, 3, ..., 27).
inline std::uint32_t spread10(std::uint32_t v) {
  v &= 0x3ffu;
  v = (v * 0x00010001u) & 0xFF0000FFu;
  v = (v * 0x00000101u) & 0x0F00F00Fu;
  v = (v * 0x00000011u) & 0xC30C30C3u;
  v = (v * 0x00000005u) & 0x49249249u;
  return v;
}

/// A cell's bucket: the Morton interleave of its coordinates' low bits, masked.
inline std::uint32_t bucket_of(int cx, int cy, int cz, std::uint32_t mask) {
  return ((spread10(std::uint32_t(cx)) << 2) | (spread10(std::uint32_t(cy)) << 1) | spread10(std::uint32_t(cz))) &
         mask;
}

/// Whether cell c (3 ints) is (cx, cy, cz).
inline bool same_cell(const int* c, int cx, int cy, int cz) { return c[0] == cx && c[1] == cy && c[2] == cz; }

/// n = min(counts[p.count_word], p.capacity): a kernel's item count, read
/// from its device word when it runs (any params struct with those fields).
template <class Params>
std::uint32_t count_of(const Params& p, const std::byte* counts) {
  const std::uint32_t stored = reinterpret_cast<const std::uint32_t*>(counts)[p.count_word];
  return stored < p.capacity ? stored : p.capacity;
}

/// Calls visit(t) for every sorted point t in the 27 cells around cell c
/// (3 ints), in the query's order: dz outermost, then dy, then dx, each
/// bucket's run in sorted order, a run of one other cell skipped whole and
/// a mixed run's points of other cells left out (neighbour_params.h).
/// [in] cells: the sorted points' cells (4 ints each); ranges: 3 words per bucket.
template <class Visit>
void visit_cells(const int* cells, const std::uint32_t* ranges, std::uint32_t mask, const int* c, Visit&& visit) {
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
        const std::uint32_t b = bucket_of(cx, cy, cz, mask);
        const std::uint32_t run = ranges[3 * std::size_t{b}], run_end = ranges[3 * std::size_t{b} + 1];
        const bool mixed = ranges[3 * std::size_t{b} + 2] != 0;
        if (run == run_end || (!mixed && !same_cell(cells + 4 * std::size_t{run}, cx, cy, cz))) continue;
        for (std::uint32_t t = run; t < run_end; ++t)
          if (!mixed || same_cell(cells + 4 * std::size_t{t}, cx, cy, cz)) visit(t);
      }
}

}  // namespace sinew::kernels::cells
