/* sph_tension_params.h — surface tension for the WCSPH fluid (issue 15,
 * part 2): Akinci, Akinci and Teschner, "Versatile surface tension and
 * adhesion for SPH fluids", TOG 32(6), 2013: cohesion between fluid
 * particles and a curvature term from the surface normals, both scaled
 * by K_ij = 2 rho0 / (rho_i + rho_j), applied after sph_step as a further
 * acceleration over the step (v += dt a, x += dt dt a), from the positions
 * and densities at the step's start. Pairwise antisymmetric: momentum is
 * kept.
 *
 * Normals: n_i = h sum_{fluid j} (m_j / rho_j) grad W_ij, grad W from the
 * cubic spline (sph_params.h). Cohesion spline, support h, r = |x_ij|:
 *   C(r) = c (h - r)^3 r^3                    for h / 2 < r < h
 *   C(r) = c (2 (h - r)^3 r^3 - h^6 / 64)     for 0 < r <= h / 2
 * with c = 32 / (pi h^9). Acceleration of fluid particle i:
 *   a_i = -gamma sum_{fluid j != i} K_ij (m_j C(r) x_ij / r + (n_i - n_j))
 * Float order: as written, left to right, in every language.
 *
 * ------------------------------------------------------------ sph_normals
 * One item per sorted particle s < n: n_s (float4, w 0); 0 for a boundary
 * particle.
 * bindings: 0 counts uint [in]      1 sorted_points float4 [in]
 *           2 sorted_cells uint4 [in] 3 ranges uint [in]
 *           4 density float [in]      5 normals float4 [out]
 * ------------------------------------------------------------ sph_tension
 * One item per sorted fluid particle s < n: a_s as above, then
 * velocity[s] += dt a_s and points[s] += (dt dt) a_s (sph_step's outputs,
 * in the same sorted order).
 * bindings: 0 counts uint [in]      1 sorted_points float4 [in]
 *           2 sorted_cells uint4 [in] 3 ranges uint [in]
 *           4 density float [in]      5 normals float4 [in]
 *           6 points float4 [in/out]  7 velocity float4 [in/out] */
#ifndef SINEW_SPH_TENSION_PARAMS_H
#define SINEW_SPH_TENSION_PARAMS_H

#include "sinew_lang.h"

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(TensionParams)
  uint count_word;  /* n = min(counts[count_word], capacity) */
  uint capacity;    /* particles */
  uint table_mask;  /* the neighbour grid's buckets - 1 */
  float h2;         /* the support radius squared [m^2] */
  float h;          /* the support radius [m] */
  float inv_l;      /* 1 / l, l = h / 2 [1/m] */
  float grad_sigma; /* sigma / l of the cubic spline [1/m^4] */
  float gamma;      /* Akinci et al.'s surface tension coefficient */
  float cohesion;   /* c = 32 / (pi h^9) [1/m^9] */
  float h6_64;      /* h^6 / 64 [m^6] */
  float rho0;       /* rest density [kg/m^3] */
  float dt;         /* the step [s] */
  float dt2;        /* dt dt [s^2] */
  uint pad0, pad1, pad2;
SINEW_STRUCT_END(TensionParams)

#ifdef __cplusplus
}  // namespace sinew::kernels
#endif

#endif /* SINEW_SPH_TENSION_PARAMS_H */
