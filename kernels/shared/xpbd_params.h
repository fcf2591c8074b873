/* xpbd_params.h — parameters of the xPBD kernels, shared by every kernel
 * language (see sinew_lang.h). Buffer bindings are listed per kernel in
 * binding order; every backend binds them in that order.
 *
 * Units: SI. h is the substep length [s]; positions [m]; velocities [m/s];
 * gravity [m/s^2]; compliances as stored per constraint (see scene.h). */
#ifndef SINEW_XPBD_PARAMS_H
#define SINEW_XPBD_PARAMS_H

#include "sinew_lang.h"

#ifdef __cplusplus
namespace sinew::kernels {
#endif

/* xpbd_predict: one item per particle.
 * bindings: 0 position float4 (xyz, w = inverse mass) [in/out]
 *           1 previous position float4 [out]
 *           2 velocity float4 (xyz) [in/out]
 * v = d v + h g; prev = x; x += h v — for particles with w > 0 only,
 * where d = v.w is the particle's velocity damping factor per substep,
 * exp(-k h) for a body's velocity_damping k [1/s] (1: none; then the
 * product is exact and changes no bit). Gravity's impulse is not damped,
 * so a body at rest balances g whatever d. w is kept. */
SINEW_STRUCT_BEGIN(PredictParams)
  float h;
  float gravity_x;
  float gravity_y;
  float gravity_z;
  uint count;
  uint pad0;
  uint pad1;
  uint pad2;
SINEW_STRUCT_END(PredictParams)

/* xpbd_external_force: one item per particle, before each substep's
 * xpbd_predict (only in scenes with SceneDesc::external_forces).
 * bindings: 0 position float4 (w = inverse mass [1/kg]) [in]
 *           1 force float4 (xyz [N], w unused) [in]
 *           2 velocity float4 (xyz [m/s]) [in/out]
 * v.xyz += (h w) f.xyz — for particles with w > 0 only (pinned and
 * kinematic particles take no force). v.w (the damping factor) is kept;
 * xpbd_predict then damps the impulse with the rest of the velocity. */
SINEW_STRUCT_BEGIN(ExternalForceParams)
  float h;     /* substep length [s], the very float xpbd_predict moves by */
  uint count;  /* particles */
  uint pad0;
  uint pad1;
SINEW_STRUCT_END(ExternalForceParams)

/* xpbd_update_velocity: one item per particle.
 * bindings: 0 position float4 [in], 1 previous position float4 [in],
 *           2 velocity float4 [in/out]: the predicted velocity v_p in,
 *           the substep's velocity out
 * v.xyz = v_p + (x - x_p) / h with x_p = prev + h v_p, the predicted
 * position exactly as xpbd_predict rounded it; that is (x - prev) / h, but
 * the part of the velocity that no constraint changed (inertia, gravity,
 * damping) never goes through a float position: see xpbd_kernels.cpp.
 * For particles with w > 0; 0 otherwise. v.w (the damping factor, see
 * xpbd_predict) is kept. */
SINEW_STRUCT_BEGIN(UpdateVelocityParams)
  float inv_h;
  uint count;
  float h;
  uint pad1;
SINEW_STRUCT_END(UpdateVelocityParams)

/* Every constraint-solve kernel (xpbd_solve_*) takes SolveParams: one work
 * item per constraint of one colour, constraints [first, first + count).
 * Bindings of every solve kernel, then any extra ones its block lists:
 *   0 position float4 (xyz, w = inverse mass) [in/out]
 *   1 particle indices, `arity` uint per constraint [in]
 *   2 constraint data, `data_stride` floats per constraint [in]
 *   3 lambda, `lambda_stride` floats per constraint [in/out] (reset to 0
 *     when reset_lambda != 0)
 *   4 residual, one float per constraint [out], written only in a measuring
 *     pass (measure_only != 0): |C + alpha~ lambda| normalised by the
 *     constraint's rest value (see each kernel). A measuring pass changes
 *     nothing else, so it may run over a whole block in one dispatch.
 * xpbd_solve_distance and xpbd_solve_volume also bind
 *   5 previous position float4 [in]: the positions at the substep's start,
 *     for constraint damping (SolveParams::damping).
 *
 * xpbd_solve_distance: arity 2, data (rest [m], alpha [m/N]).
 *   C = |x_a - x_b| - rest; residual / rest.
 * xpbd_solve_volume: arity 4, data (rest [m^3], alpha [m^3/Pa]).
 *   C = V - rest with V = dot(x1 - x0, cross(x2 - x0, x3 - x0)) / 6;
 *   residual / rest. */
SINEW_STRUCT_BEGIN(SolveParams)
  uint first;
  uint count;
  float inv_h2;         /* 1 / h^2 [1/s^2]: alpha~ = alpha / h^2 */
  uint reset_lambda;    /* nonzero in the first iteration of a substep */
  float h;              /* substep length [s] */
  float substep_end;    /* fraction of the frame done at the end of this substep, in (0, 1] */
  uint measure_only;    /* nonzero: write the residual only, after the frame's last sweep */
  /* gamma = tau / h of Macklin et al., "XPBD", MIG 2016, eq. 26 (tau the
   * body's stiffness_damping [s]): xpbd_solve_distance and xpbd_solve_volume
   * solve dlambda = (-C - alpha~ lambda - gamma grad C . (x - x_prev)) /
   * ((1 + gamma) sum w |grad C|^2 + alpha~). 0: undamped, and then the
   * kernels do exactly the undamped arithmetic. Other kernels ignore it. */
  float damping;
SINEW_STRUCT_END(SolveParams)

#ifdef __cplusplus
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_XPBD_PARAMS_H */
