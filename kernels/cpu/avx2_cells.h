// avx2_cells.h — the neighbour grid's 27 cells around a cell, for the AVX2
// kernels that visit them (neighbour_kernels_avx2.cpp, sph_kernels_avx2.cpp):
// the same buckets and runs, in the same order, as the scalar reference's
// visit_cells (neighbour_cells.h, kernels/shared/neighbour_params.h).
//
// Include only from files compiled for CPUs checked with cpu_has_avx2(), as
// avx2_lanes.h: its inline functions are built for AVX2 (the target pragma
// below) and must not be shared with scalar files.
#pragma once

#include <cstdint>

#pragma GCC push_options
#pragma GCC target("avx2")

namespace sinew::kernels::avx2 {

/// The low 10 bits of v spread to every third bit (neighbour_math.h).
inline std::uint32_t spread10(std::uint32_t v) {
  v &= 0x3ffu;
  v = (v * 0x00010001u) & 0xFF0000FFu;
  v = (v * 0x00000101u) & 0x0F00F00Fu;
  v = (v * 0x00000011u) & 0xC30C30C3u;
  v = (v * 0x00000005u) & 0x49249249u;
  return v;
}

/// A cell's bucket (neighbour_math.h): the Morton interleave of its coordinates' low bits, masked.
inline std::uint32_t bucket_of(int cx, int cy, int cz, std::uint32_t mask) {
  return ((spread10(std::uint32_t(cx)) << 2) | (spread10(std::uint32_t(cy)) << 1) | spread10(std::uint32_t(cz))) & mask;
}

/// The 27 cells' runs around one cell (dz outermost, as the reference visits
/// them), looked up once per cell: the particles of a cell are next to each
/// other in sorted order, so the next particles usually share them. A run
/// that cannot hold the cell (empty, or one other cell's) is kept empty; a
/// run of a bucket shared by far cells (mixed) holds other cells' particles
/// too, which the caller skips by their cell.
struct CellRuns {
  struct Run {
    std::uint32_t begin, end;
    bool mixed;
    int cx, cy, cz;
  };
  Run runs[27];
  int at[3] = {0, 0, 0};
  bool valid = false;

  void look_up(const int* c, const int* cells, const std::uint32_t* ranges, std::uint32_t mask) {
    if (valid && c[0] == at[0] && c[1] == at[1] && c[2] == at[2]) return;
    int v = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx, ++v) {
          const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
          const std::uint32_t b = bucket_of(cx, cy, cz, mask);
          Run& r = runs[v];
          r = {ranges[3 * std::size_t{b}], ranges[3 * std::size_t{b} + 1], ranges[3 * std::size_t{b} + 2] != 0, cx, cy, cz};
          const int* rc = cells + 4 * std::size_t{r.begin};
          if (r.begin < r.end && !r.mixed && !(rc[0] == cx && rc[1] == cy && rc[2] == cz)) r.end = r.begin;
        }
    for (int k = 0; k < 3; ++k) at[k] = c[k];
    valid = true;
  }
};

/// How many of the particles s, s + 1, ... (at most 8, below `last`) share
/// particle s's cell: they are next to each other in sorted order.
inline std::uint32_t same_cell_run(const int* cells, std::uint32_t s, std::uint32_t last) {
  const int* c = cells + 4 * std::size_t{s};
  std::uint32_t k = 1;
  while (k < 8 && s + k < last && cells[4 * std::size_t{s + k}] == c[0] && cells[4 * std::size_t{s + k} + 1] == c[1] &&
         cells[4 * std::size_t{s + k} + 2] == c[2])
    ++k;
  return k;
}

}  // namespace sinew::kernels::avx2

#pragma GCC pop_options
