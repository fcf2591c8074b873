/* vbd_params.h — parameters of the Vertex Block Descent kernels
 * (SolverSettings::method = vbd; src/program/vbd_program.cpp), shared by
 * every kernel language (see sinew_lang.h).
 *
 * Anka He Chen, Ziheng Liu, Yin Yang, Cem Yuksel, "Vertex Block Descent",
 * ACM TOG 43(4), SIGGRAPH 2024. Units: SI; h the substep length [s]. */
#ifndef SINEW_VBD_PARAMS_H
#define SINEW_VBD_PARAMS_H

#include "sinew_lang.h"

#ifdef __cplusplus
namespace sinew::kernels {
#endif

/* vbd_initial_guess: one item per particle, right after xpbd_predict
 * (which left x = y = x_prev + h v + h^2 g, the inertia target).
 * bindings: 0 position float4 (xyz, w = inverse mass) [in/out]
 *           1 inertia target float4 [out]
 * inertia = x (w kept); then, for particles with w > 0,
 * x.xyz -= (h2g_x, h2g_y, h2g_z): the sweeps start from x_prev + h v (the
 * paper's "previous velocity" initial guess), which for a body resting in
 * equilibrium is its equilibrium, where y is h^2 g below it. */
SINEW_STRUCT_BEGIN(VbdInitParams)
  float h2g_x; /* h^2 g [m] */
  float h2g_y;
  float h2g_z;
  uint count;  /* particles */
SINEW_STRUCT_END(VbdInitParams)

/* vbd_solve_vertices: one item per vertex of one colour, entries
 * [first, first + count) of the colour-ordered vertex list; the vertices of
 * a colour share no tet, so each item reads and writes tets (and their
 * rotations) no other item of the dispatch touches.
 * bindings: 0 position float4 (xyz, w = inverse mass [1/kg]) [in/out]
 *           1 inertia target y float4 [in]
 *           2 vertices uint: particle index per entry, colour by colour [in]
 *           3 offsets uint, entries + 1: entry e's incidences are
 *             [offsets[e], offsets[e + 1]) [in]
 *           4 incidences uint: tet slot * 4 + corner (0..3) [in]
 *           5 tet particles uint4 (the FEM block's, fem_params.h) [in]
 *           6 tet data, SINEW_FEM_DATA_STRIDE floats per tet [in]
 *           7 tet state, lambda_stride floats per tet [in/out]:
 *             corotational: the rotation quaternion at SINEW_FEM_ROTATION
 *             (xpbd_solve_corotational's layout; all zero before a tet's
 *             first solve); neo_hookean: unused.
 * Per vertex i (skipped when w == 0, pinned):
 *   H = m / h^2 I + sum_t H_t,  f = -m / h^2 (x - y) - sum_t grad_i E_t,
 *   x += H^-1 f, unless det H is not safely positive (then unchanged),
 * with E_t = C_D^2 / (2 alpha_D) + C_H^2 / (2 alpha_H), the tet's
 * constraints and compliances of fem_params.h (the material's energy), and
 * H_t its 3x3 block of vertex i: corotational with R held fixed,
 * neo_hookean exact (kernels/math/vbd_math.h; both positive
 * semi-definite). */
SINEW_STRUCT_BEGIN(VbdSolveParams)
  uint first;
  uint count;
  float inv_h2;         /* 1 / h^2 [1/s^2] */
  uint model;           /* SINEW_VBD_COROTATIONAL or SINEW_VBD_NEO_HOOKEAN */
  uint lambda_stride;   /* floats of tet state per tet (binding 7) */
  uint pad0;
  uint pad1;
  uint pad2;
SINEW_STRUCT_END(VbdSolveParams)

#define SINEW_VBD_COROTATIONAL 0u
#define SINEW_VBD_NEO_HOOKEAN 1u

#ifdef __cplusplus
}  /* namespace sinew::kernels */
#endif

#endif /* SINEW_VBD_PARAMS_H */
