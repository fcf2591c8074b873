/* neighbour_math.h — the neighbour search's bucket of a cell, shared by the
 * nbr_*.gpu kernels (kernels/shared/neighbour_params.h). Cells are held as
 * uint (an int's two's-complement bits), so a neighbour cell's coordinate
 * c + d wraps alike in every language. */
#ifndef SINEW_NEIGHBOUR_MATH_H
#define SINEW_NEIGHBOUR_MATH_H

/* The low 10 bits of v spread to every third bit (bits 0, 3, ..., 27). */
uint nbr_spread10(uint v) {
  v = v & 0x3ffu;
  v = (v * 0x00010001u) & 0xFF0000FFu;
  v = (v * 0x00000101u) & 0x0F00F00Fu;
  v = (v * 0x00000011u) & 0xC30C30C3u;
  v = (v * 0x00000005u) & 0x49249249u;
  return v;
}

uint nbr_bucket(uint cx, uint cy, uint cz, uint mask) {
  return ((nbr_spread10(cx) << 2u) | (nbr_spread10(cy) << 1u) | nbr_spread10(cz)) & mask;
}

/* The point count n = min(counts[count_word], capacity), from its word. */
uint nbr_count_of(uint stored, uint capacity) { return stored < capacity ? stored : capacity; }

#endif /* SINEW_NEIGHBOUR_MATH_H */
