// neighbour_cells.h — the neighbour grid's cells and buckets for the CPU
// reference kernels that visit them (neighbour_kernels.cpp, sph_kernels.cpp;
// the contract: kernels/shared/neighbour_params.h; the GPU's twin:
// kernels/gpu/neighbour_math.h). Not for the AVX2 file, which keeps its own
// copies inside its target region (avx2_lanes.h says why).
#pragma once

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

}  // namespace sinew::kernels::cells
