/* fem_params.h — the per-tet data of the FEM constraint kernels
 * (xpbd_solve_neo_hookean, xpbd_solve_stvk, xpbd_solve_corotational), shared
 * by every kernel language (see sinew_lang.h). The kernels take SolveParams
 * and the standard solve bindings (xpbd_params.h) with:
 *   arity 4 (the tet's particles, in mesh order),
 *   data  SINEW_FEM_DATA_STRIDE floats per tet, laid out below,
 *   lambda SINEW_FEM_LAMBDA_STRIDE floats per tet: (lambda_D, lambda_H);
 *          corotational: SINEW_FEM_COROTATIONAL_LAMBDA_STRIDE, the lambdas
 *          then the tet's rotation as a unit quaternion (w, x, y, z) at
 *          SINEW_FEM_ROTATION, kept from solve to solve (the warm start of
 *          kernels/math/fem_math.h: refine_rotation); all zero before the
 *          first solve, which starts from the exact rotation instead.
 *
 * Per tet, from its rest edge matrix Dm = [x1 - x0, x2 - x0, x3 - x0] [m]:
 *   [0..8]  Dm^-1, row-major [1/m]: F = Ds Dm^-1 with Ds the current edges;
 *   [9]     V, rest volume [m^3] = det(Dm) / 6;
 *   [10]    alpha_D, compliance of the deviatoric constraint C_D [1/(Pa m^3)];
 *   [11]    alpha_H, compliance of the hydrostatic constraint C_H [1/(Pa m^3)];
 *   [12]    h0, the rest offset of C_H = h(F) - h0 (dimensionless):
 *           neo_hookean: h = det F, h0 = gamma = 1 + mu / lambda';
 *           stvk:        h = det F, h0 = 1;
 *           corotational: h = tr(R^T F), h0 = 3;
 *   [13..15] zero (pads a tet's data to four float4s).
 * C_D is dimensionless: |F|_F (neo_hookean), |E|_F with E = (F^T F - I) / 2
 * (stvk), |F - R|_F (corotational); compliances as include/sinew/scene.h.
 *
 * Residual (measuring pass): sqrt((C_D + alpha~_D lambda_D)^2 +
 * (C_H + alpha~_H lambda_H)^2), dimensionless. */
#ifndef SINEW_FEM_PARAMS_H
#define SINEW_FEM_PARAMS_H

#define SINEW_FEM_DATA_STRIDE 16
#define SINEW_FEM_LAMBDA_STRIDE 2
#define SINEW_FEM_COROTATIONAL_LAMBDA_STRIDE 6
#define SINEW_FEM_ROTATION 2
/* Iterations of the warm-started rotation per corotational solve. */
#define SINEW_FEM_ROTATION_ITERATIONS 1
#define SINEW_FEM_DM_INV 0
#define SINEW_FEM_REST_VOLUME 9
#define SINEW_FEM_ALPHA_D 10
#define SINEW_FEM_ALPHA_H 11
#define SINEW_FEM_H0 12

#endif /* SINEW_FEM_PARAMS_H */
