/* pbf_params.h — position-based fluids (Macklin and Müller, "Position Based
 * Fluids", SIGGRAPH 2013), the alternative to WCSPH (issue 15, part 2):
 * each fluid particle's density constraint C_i = max(rho_i / rho0 - 1, 0)
 * (only compression is resisted: no tension pulls the free surface into
 * clumps) projected by Jacobi iterations on the predicted positions, with
 * the same cubic spline, neighbour grid and Akinci boundary particles as
 * the WCSPH kernels (sph_params.h; w > 0 a fluid particle's mass, w < 0
 * minus a boundary particle's psi).
 *
 * With masses (m_i = w_i), grad_k C_i = (m_k / rho0) grad W_ik, inverse
 * masses 1 / m_k (0 for boundary particles), so
 *   lambda_i = -C_i / (sum_k |grad_k C_i|^2 / m_k + epsilon)
 *   dx_i = (1 / rho0) sum_j (m_j lambda_i / m_i + lambda_j) grad W_ij
 *        + (1 / rho0) sum_b (psi_b lambda_i / m_i) grad W_ib
 * which for equal masses is the paper's (lambda_i + lambda_j) grad W_ij /
 * rho0. grad W_ij = ((sigma / l) w'(q) / r) (x_i - x_j), 0 < r < h.
 * Float order: as written, left to right, in every language.
 *
 * ------------------------------------------------------------ pbf_predict
 * One item per particle i < n (unsorted): previous[i] = x_i; a fluid
 * particle v += dt g, x += dt v (velocity xyz, w its id, kept).
 * bindings: 0 counts uint [in]
 *           1 points float4 [in/out]     2 velocity float4 [in/out]
 *           3 previous float4 [out]
 * ------------------------------------------------------------ pbf_lambda
 * One item per sorted particle s < n: a fluid particle's density rho
 * (sph_density's sum, with itself), C = max(rho / rho0 - 1, 0), and
 * lambda = -C / (|sum_j (m_j / rho0) gW_ij|^2 / m_i + sum_{fluid j}
 * |(m_j / rho0) gW_ij|^2 / m_j + epsilon), the neighbours in the query's
 * order; lambda 0 and density rho0 for a boundary particle.
 * bindings: 0 counts uint [in]      1 sorted_points float4 [in]
 *           2 sorted_cells uint4 [in] 3 ranges uint [in]
 *           4 density float [out] [kg/m^3]   5 lambda float [out]
 * ------------------------------------------------------------ pbf_delta
 * One item per sorted particle s < n: moved[s] = x_s + dx_s (above) for a
 * fluid particle, x_s for a boundary particle.
 * bindings: 0 counts uint [in]      1 sorted_points float4 [in]
 *           2 sorted_cells uint4 [in] 3 ranges uint [in]
 *           4 lambda float [in]       5 moved float4 [out]
 * ------------------------------------------------------------ pbf_finish
 * One item per sorted particle s < n: a fluid particle's velocity (x_s -
 * previous[order[s]]) / dt; points[s] = x_s, velocity[s] = (v, its id from
 * sorted_velocity.w), speed2[s] = |v|^2 ((vx vx + vy vy) + vz vz);
 * pressure[s] = 0 (PBF has none). A boundary particle is copied, speed2 0.
 * bindings: 0 counts uint [in]      1 sorted_points float4 [in]
 *           2 order uint [in]         3 previous float4 [in]
 *           4 sorted_velocity float4 [in]
 *           5 points float4 [out]     6 velocity float4 [out]
 *           7 speed2 float [out]      8 pressure float [out] */
#ifndef SINEW_PBF_PARAMS_H
#define SINEW_PBF_PARAMS_H

#include "sinew_lang.h"

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(PbfParams)
  uint count_word;  /* n = min(counts[count_word], capacity) */
  uint capacity;    /* particles */
  uint table_mask;  /* the neighbour grid's buckets - 1 */
  float h2;         /* the support radius squared [m^2] */
  float inv_l;      /* 1 / l, l = h / 2 [1/m] */
  float sigma;      /* 1 / (pi l^3) [1/m^3] */
  float grad_sigma; /* sigma / l [1/m^4] */
  float rho0;       /* rest density [kg/m^3] */
  float inv_rho0;   /* 1 / rho0 [m^3/kg] */
  float epsilon;    /* the relaxation of lambda's denominator [1/kg] */
  float dt;         /* the step [s] */
  float gx;         /* gravity [m/s^2] */
  float gy;
  float gz;
  float inv_dt;     /* 1 / dt [1/s] */
  uint pad;
SINEW_STRUCT_END(PbfParams)

#ifdef __cplusplus
}  // namespace sinew::kernels
#endif

#endif /* SINEW_PBF_PARAMS_H */
