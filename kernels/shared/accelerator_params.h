/* accelerator_params.h — the Chebyshev semi-iterative accelerator of the
 * xPBD sweeps (src/program/solve_programs.cpp). Shared by every kernel
 * language (sinew_lang.h).
 *
 * Wang, "A Chebyshev Semi-Iterative Approach for Accelerating Projective
 * and Position-Based Dynamics", ACM TOG 34(6) (SIGGRAPH Asia 2015), eq. 12:
 * after sweep k + 1 has produced q^ from q^k,
 *   q^{k+1} = omega_{k+1} (gamma (q^ - q^k) + q^k - q^{k-1}) + q^{k-1}.
 * The state q is the positions AND the lambdas of every block: xPBD keeps
 * x - x~ = M^-1 grad C^T lambda, a linear relation that any affine
 * combination of states (weights summing to 1, as here) preserves, so the
 * extrapolated positions and lambdas stay consistent (extrapolating the
 * positions alone would break it and move the answer the sweeps converge
 * to). */
#ifndef SINEW_ACCELERATOR_PARAMS_H
#define SINEW_ACCELERATOR_PARAMS_H

#include "sinew_lang.h"

#ifdef __cplusplus
namespace sinew::kernels {
#endif

/* xpbd_chebyshev: one item per float j < count of a state buffer, viewed
 * as records of `stride` floats of which the first `width` are state (the
 * rest, e.g. a particle's inverse mass or the corotational rotation kept
 * in the lambda buffer, is never touched).
 * bindings: 0 values float [in/out] (q^ in, q^{k+1} out when mix != 0)
 *           1 newer float [in/out] (q^k in, q^{k+1} out)
 *           2 older float [in/out] (q^{k-1} in, q^k out)
 * mix == 0 (record, the sweeps before acceleration starts): older = newer,
 *   newer = values; values unchanged.
 * mix != 0: the update above with omega and gamma; values = newer = q^{k+1},
 *   older = q^k. */
SINEW_STRUCT_BEGIN(ChebyshevParams)
  uint count;    /* floats in the buffer (records * stride) */
  uint stride;   /* floats per record, >= 1 */
  uint width;    /* leading floats of a record that are state, <= stride */
  uint mix;      /* 0: record; else extrapolate */
  float omega;   /* omega_{k+1} of the recurrence */
  float gamma;   /* under-relaxation, (0, 1] */
  uint pad0;
  uint pad1;
SINEW_STRUCT_END(ChebyshevParams)

/* xpbd_warm_start: the lambda warm start (SolverSettings::warm_start), one
 * item per constraint of one colour of a distance (arity 2) or volume
 * (arity 4) block, constraints [first, first + count). Each substep's
 * sweeps start from lambda = the last substep's final lambda instead of 0,
 * and the positions from the correction that lambda makes,
 *   x_i += w_i lambda grad_i C(x_prev)
 * (x_prev: the positions at the substep's start, `previous`), so that
 * x - x~ = M^-1 grad C^T lambda holds (xPBD's invariant; up to the change
 * of grad C). At a static equilibrium the start is then the solution
 * itself (x~ = x + h^2 g, and grad C^T lambda = -M h^2 g there), and the
 * sweeps' fixed point is the equilibrium however few sweeps run.
 * bindings: 0 position float4 [in/out], 1 previous position float4 [in],
 *           2 particle indices uint, `arity` per constraint [in],
 *           3 lambda float [in] */
SINEW_STRUCT_BEGIN(WarmStartParams)
  uint first;
  uint count;
  uint arity;    /* 2: distance (grad_a C = (x_a - x_b) / |x_a - x_b|); 4: volume (tet_volume_gradients) */
  uint pad0;
SINEW_STRUCT_END(WarmStartParams)

#ifdef __cplusplus
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_ACCELERATOR_PARAMS_H */
