// xpbd_solve_stvk.cl — OpenCL twin of kernels/cpu/fem_kernels.cpp:xpbd_solve_stvk.
// Macklin, Müller, Chentanez, "XPBD", MIG 2016; the coupled solve of Macklin,
// Müller, "A Constraint-based Formulation of Stable Neo-Hookean Materials",
// MIG 2021. One work item per tet of one colour: St. Venant-Kirchhoff,
// C_D = |E|_F with E = (F^T F - I) / 2 and C_H = det F - 1, solved together
// as one 2x2 xPBD system (fem_math.h: fem_solve_tet).
#include "cl_math.h"
#include "fem_math.h"
#include "xpbd_params.h"

kernel void xpbd_solve_stvk(global float4* x, global const uint4* idx, global const float* data,
                            global float* lambda, global float* residual, SolveParams p) {
  const uint gid = get_global_id(0);
  if (gid >= p.count) return;
  fem_solve_tet(FEM_MODEL_STVK, x, idx, data, lambda, residual, &p, p.first + gid);
}
