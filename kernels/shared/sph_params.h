/* sph_params.h — smoothed-particle hydrodynamics on the neighbour grid
 * (issue 15, part 2): the fluid's kernels visit the 27 cells around each
 * particle the way nbr_query does (kernels/shared/neighbour_params.h: the
 * sorted points, their cells, the bucket ranges with their mixed flags),
 * with the support radius h as the search radius.
 *
 * The kernel: the cubic spline of Monaghan, "Smoothed particle
 * hydrodynamics", Rep. Prog. Phys. 68, 2005 (as Becker and Teschner 2007
 * use it), with smoothing length l = h / 2 (support h), q = r / l:
 *   W = sigma w(q), sigma = 1 / (pi l^3),
 *   w(q) = (1 - 1.5 q q) + 0.75 q q q for q < 1, 0.25 (2 - q)^3 for 1 <= q < 2,
 *   dW/dr = (sigma / l) w'(q), w'(q) = -3 q + 2.25 q q, or -0.75 (2 - q)^2.
 * On a lattice of spacing h / 2 it sums to 1.0000 / spacing^3 and its
 * gradient's first moment to 1.020 (poly6 and spiky, Müller et al. 2003,
 * which this replaced: 1.0098 and 0.956; README, "SPH"). Each is written
 * in that order of operations in every language:
 *   q < 1:  w = (1 - (1.5 q) q) + ((0.75 q) q) q,  w' = (2.25 q) q - 3 q
 *   q < 2:  t = 2 - q, w = ((0.25 t) t) t,          w' = (-0.75 t) t
 *
  * Particles. Each is a float4 xyz [m] and w: its mass m > 0 [kg] for a
 * fluid particle, minus its "mass" psi = rho0 V_b for a boundary particle
 * (Akinci, Ihmsen, Akinci, Solenthaler, Teschner, "Versatile rigid-fluid
 * coupling for incompressible SPH", TOG 31(4), 2012: V_b = 1 / sum_k W_bk
 * over the boundary particles k around b, computed on the host). Boundary
 * particles never move.
 *
 * ------------------------------------------------------------ sph_density
 * One item per sorted particle s < n: a boundary particle (w < 0) gets
 * rho0 at once (a step needs no boundary density; their volumes at
 * create are summed with w = +1 instead); a fluid particle
 * rho_s = sigma * sum_j |w_j| w(q_j)
 * over the particles j (itself included, d2 = 0) with d2 < h2, d2 = (dx dx
 * + dy dy) + dz dz in float, q = sqrt(d2) inv_l, summed in the query's
 * order (27 cells, dz outermost, each run in sorted order), then
 * multiplied by sigma once.
 * bindings: 0 counts uint [in]
 *           1 sorted_points float4 [in]: xyz [m], w the mass [kg]
 *           2 sorted_cells uint4 [in]
 *           3 ranges uint, 3 per bucket [in]
 *           4 density float, per sorted particle [out] [kg/m^3]
 * ------------------------------------------------------------ sph_gather
 * One item per sorted particle s < n: its velocity (xyz [m/s], w its id as
 * bits) copied from the particle order[s] into sorted order.
 * bindings: 0 counts uint [in]
 *           1 order uint [in]
 *           2 velocity float4 [in]
 *           3 sorted_velocity float4 [out]
 * ------------------------------------------------------------ sph_step
 * One item per sorted particle s < n: weakly compressible SPH (Becker and
 * Teschner, "Weakly compressible SPH for free surface flows", SCA 2007).
 * Pressure by Tait's equation, p = B ((rho / rho0)^7 - 1), negative values
 * taken as 0 (no tension at the free surface). Acceleration of a fluid
 * particle i:
 *   g - sum_fluid j m_j (p_i / rho_i^2 + p_j / rho_j^2 + Pi_ij) grad W_ij
 *     - sum_boundary b psi_b (p_i / rho_i^2 + Pi_ib) grad W_ib
 * with grad W = ((sigma / l) w'(q) / r) x_ij (0 < r < h) and Monaghan's viscosity Pi_ij = -viscosity
 * min(v_ij . x_ij, 0) / (rho_avg (r^2 + eta2)) (Monaghan, "Smoothed
 * particle hydrodynamics", Rep. Prog. Phys. 68, 2005), rho_avg the mean of
 * the two densities; against a boundary particle Pi_ib takes
 * boundary_viscosity, rho_i and the velocity relative to the boundary
 * particle's (0: a free-slip boundary; Akinci et al. 2012 give the
 * boundary its own coefficient too). Then symplectic Euler: v += dt a, x += dt v, written in sorted
 * order (the next step's input). Boundary particles are copied unchanged.
 * bindings: 0 counts uint [in]
 *           1 sorted_points float4 [in]
 *           2 sorted_cells uint4 [in]
 *           3 ranges uint [in]
 *           4 density float [in]
 *           5 sorted_velocity float4 [in]
 *           6 points float4 [out]: the next step's positions
 *           7 velocity float4 [out]: the next step's velocities (w the id)
 *           8 pressure float [out] [Pa], per sorted particle
 *           9 speed2 float [out]: |v|^2 after the step [m^2/s^2], 0 for a
 *             boundary particle (the host's CFL check takes its maximum)
 * ------------------------------------------------------ sph_fluid_cells
 * One item per sorted particle s < n: a fluid particle (w > 0) sets
 * near[bucket] = 1 for the bucket of each of the 27 cells around its own
 * (the caller zeroes near first). A boundary particle whose own cell's
 * bucket stays 0 has no fluid particle in the 27 cells around it, so none
 * within h: sph_boundary_force skips it. Buckets shared by far cells only
 * make it look where nothing is. Why: on an organ most boundary particles
 * are far from the fluid, and looking up their 27 cells every step cost a
 * third of the fluid's time (bench bleeding_organ).
 * bindings: 0 counts uint [in]
 *           1 sorted_points float4 [in]
 *           2 sorted_cells uint4 [in]
 *           3 near uint, one per bucket [out]
 * ------------------------------------------------------ sph_boundary_force
 * One item per sorted boundary particle b (w < 0) whose own cell's bucket
 * is marked in near (sph_fluid_cells; the others have no fluid within h
 * and are left as they are): the impulse the fluid
 * gives it in this step, the reaction to its pull on every fluid particle
 * i in sph_step (Akinci et al. 2012, eq. 11), so the pair's momentum is
 * conserved:  F_b = sum_i m_i psi_b (p_i / rho_i^2 + Pi_ib) gradW_ib-factor
 * (x_i - x_b), each term computed in sph_step's order of operations (e =
 * x_i - x_b, gw, Pi_ib from (v_i - v_b) . e); then impulse[id & 0x7fffffff]
 * += dt F_b (its own slot: no two items write one).
 * bindings: 0 counts uint [in]
 *           1 sorted_points float4 [in]
 *           2 sorted_cells uint4 [in]
 *           3 ranges uint [in]
 *           4 density float [in]
 *           5 sorted_velocity float4 [in]
 *           6 impulse float4 per boundary particle [in/out] [N s]
 *           7 near uint, one per bucket [in] (sph_fluid_cells) */
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
  float boundary_viscosity; /* alpha_b c0 h [m^2/s]: the viscosity against boundary particles (0: free slip) */
  float h2;         /* the support radius squared [m^2], float(h) * float(h) */
  float inv_l;      /* 1 / l, l = h / 2 the smoothing length [1/m] */
  float sigma;      /* 1 / (pi l^3) [1/m^3] */
  float grad_sigma; /* sigma / l [1/m^4] */
  float rho0;       /* rest density [kg/m^3] */
  float stiffness;  /* B = rho0 c0^2 / 7 [Pa] (Tait's equation) */
  float viscosity;  /* alpha c0 h [m^2/s] (Monaghan's artificial viscosity) */
  float eta2;       /* 0.01 h^2 [m^2] */
  float gx;         /* gravity [m/s^2] */
  float gy;
  float gz;
  float dt;         /* the step [s] */
SINEW_STRUCT_END(SphParams)

#ifdef __cplusplus
}  // namespace sinew::kernels
#endif

#endif /* SINEW_SPH_PARAMS_H */
