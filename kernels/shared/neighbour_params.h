/* neighbour_params.h — the fixed-radius neighbour search (issue 15, part
 * 1): a uniform grid of cells as wide as the radius, points sorted by
 * their cell's bucket, every query visiting the 27 cells around its own.
 * Green, "Particle Simulation using CUDA", NVIDIA 2010 (sort by cell, cell
 * ranges, 27-cell queries); Hoetzlein, "Fast Fixed-Radius Nearest
 * Neighbors: Interactive Million-Particle Fluids", GTC 2014 (buckets of a
 * hashed grid); the Morton order of the buckets keeps neighbouring cells
 * near in memory. Shared by every kernel language (sinew_lang.h).
 *
 * Cells. The cell of a point x (float, [m]) is c = floor(x * inv_cell) per
 * axis, as int; the cell is a little wider than the radius (the host sets
 * inv_cell = 1 / (radius (1 + 2^-6)), src/neighbours/neighbour_grid.cpp),
 * so two points closer than the radius lie in the same or adjacent cells
 * however the products round, for |x * inv_cell| < 2^16 (checked on the
 * host).
 * Buckets. A cell's bucket is the low bits (table_mask, 2^k - 1) of the
 * Morton interleave of the low 10 bits of its coordinates as uint (two's
 * complement): cells 2^(k/3) apart share a bucket (space tiled
 * periodically), so a bucket may hold points of several cells; a query
 * keeps only the points whose own cell is the one it visits.
 * Neighbours of point i: the points j != i with
 *   (xj - xi)^2 + (yj - yi)^2 + (zj - zi)^2 < radius2
 * computed in float in that order, each product and sum rounded (PRECISE),
 * so every backend and a brute-force float loop find the same sets.
 *
 * Every kernel reads its point count n = min(counts[count_word], capacity)
 * from binding 0 when it runs (kernels/shared/primitive_params.h).
 *
 * ------------------------------------------------------------ nbr_cells
 * One item per point i < n: its cell and its bucket, the sort's key.
 * bindings: 0 counts uint [in]
 *           1 points float4 [in]: xyz [m], w unused
 *           2 keys uint [out]: the bucket
 *           3 order uint [out]: i (the sort's payload)
 *           4 cells uint4 [out]: the cell (int bits), w unused
 * ------------------------------------------------------------ nbr_ranges
 * One item per sorted point s < n (after the keys are sorted): where each
 * bucket's run of points starts and ends, ranges[3 b] = first s, ranges[3 b
 * + 1] = last s + 1, and whether it mixes cells, ranges[3 b + 2] = 1 when
 * two neighbours in the run have different cells (buckets shared by cells
 * far apart); the caller zeroes ranges first (empty buckets: 0, 0, 0). A
 * query skips a run of one cell that is not the cell it visits at once, and
 * checks the cell of each point only in mixed runs.
 * bindings: 0 counts uint [in]
 *           1 keys uint [in]: sorted
 *           2 order uint [in]: sorted s -> point i
 *           3 cells uint4 [in]: per point
 *           4 ranges uint, 3 per bucket [out]
 * ------------------------------------------------------------ nbr_gather
 * One item per sorted point s < n: its point and cell, copied into sorted
 * order (a query then reads its candidates' runs from contiguous memory).
 * bindings: 0 counts uint [in]
 *           1 order uint [in]: sorted s -> point i
 *           2 points float4 [in]
 *           3 cells uint4 [in]
 *           4 sorted_points float4 [out]
 *           5 sorted_cells uint4 [out]
 * ------------------------------------------------------------ nbr_query
 * One item per sorted point s < n (point i = order[s]): visits the 27
 * cells around its own, dz outermost then dy then dx from -1 to 1, each
 * bucket's run in sorted order. mode 0 writes how many neighbours i has to
 * lists[i]; mode 1 writes their indices (points j) to neighbours[lists[i] +
 * k] (lists holding the counts' exclusive scan) where that is below
 * out_capacity.
 * bindings: 0 counts uint [in]
 *           1 sorted_points float4 [in]
 *           2 sorted_cells uint4 [in]
 *           3 ranges uint [in]
 *           4 order uint [in]
 *           5 lists uint [mode 0: out, counts; mode 1: in, offsets]
 *           6 neighbours uint [mode 1: out; unused in mode 0] */
#ifndef SINEW_NEIGHBOUR_PARAMS_H
#define SINEW_NEIGHBOUR_PARAMS_H

#include "sinew_lang.h"

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(NeighbourParams)
  uint count_word;   /* n = min(counts[count_word], capacity) */
  uint capacity;     /* points */
  uint table_mask;   /* buckets - 1, buckets a power of two <= 2^30 */
  uint mode;         /* nbr_query: 0 count, 1 fill */
  float inv_cell;    /* 1 / cell edge [1/m] */
  float radius2;     /* the radius squared, in float [m^2] */
  uint out_capacity; /* nbr_query mode 1: neighbour slots */
  uint pad0;
SINEW_STRUCT_END(NeighbourParams)

#ifdef __cplusplus
}  // namespace sinew::kernels
#endif

#endif /* SINEW_NEIGHBOUR_PARAMS_H */
