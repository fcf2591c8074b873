/* sph_params.h — smoothed-particle hydrodynamics on the neighbour grid
 * (issue 15, part 2): the fluid's kernels visit the 27 cells around each
 * particle the way nbr_query does (kernels/shared/neighbour_params.h: the
 * sorted points, their cells, the bucket ranges with their mixed flags),
 * with the support radius h as the search radius.
 *
 * Density: the poly6 kernel of Müller, Charypar and Gross, "Particle-Based
 * Fluid Simulation for Interactive Applications", SCA 2003:
 *   W(r) = 315 / (64 pi h^9) (h^2 - r^2)^3 for r < h, 0 beyond,
 * a function of r^2 only: no square root, so every backend rounds it alike.
 *
 * ------------------------------------------------------------ sph_density
 * One item per sorted particle s < n: rho_s = poly6 * sum_j m_j (h2 -
 * d2)^3 over the particles j (itself included, d2 = 0) with d2 < h2, d2 =
 * (dx dx + dy dy) + dz dz in float, (h2 - d2)^3 = ((h2 - d2)(h2 - d2))(h2 -
 * d2), summed in the query's order (27 cells, dz outermost, each run in
 * sorted order), then multiplied by poly6 once.
 * bindings: 0 counts uint [in]
 *           1 sorted_points float4 [in]: xyz [m], w the mass [kg]
 *           2 sorted_cells uint4 [in]
 *           3 ranges uint, 3 per bucket [in]
 *           4 density float, per sorted particle [out] [kg/m^3] */
#ifndef SINEW_SPH_PARAMS_H
#define SINEW_SPH_PARAMS_H

#include "sinew_lang.h"

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(SphParams)
  uint count_word;  /* n = min(counts[count_word], capacity) */
  uint capacity;    /* particles */
  uint table_mask;  /* the neighbour grid's buckets - 1 */
  uint pad0;
  float h2;         /* the support radius squared [m^2], float(h) * float(h) */
  float poly6;      /* 315 / (64 pi h^9) [1/m^9] */
  float pad1;
  float pad2;
SINEW_STRUCT_END(SphParams)

#ifdef __cplusplus
}  // namespace sinew::kernels
#endif

#endif /* SINEW_SPH_PARAMS_H */
