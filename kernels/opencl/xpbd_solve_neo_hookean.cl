// xpbd_solve_neo_hookean.cl — OpenCL twin of
// kernels/cpu/fem_kernels.cpp:xpbd_solve_neo_hookean.
// Macklin, Müller, Chentanez, "XPBD", MIG 2016; Macklin, Müller, "A
// Constraint-based Formulation of Stable Neo-Hookean Materials", MIG 2021.
// One work item per tet of one colour: C_D = |F|_F and C_H = det F - gamma
// solved together as one 2x2 xPBD system (fem_math.h: fem_solve_tet).
#include "cl_math.h"
#include "fem_math.h"
#include "xpbd_params.h"

kernel void xpbd_solve_neo_hookean(global float4* x, global const uint4* idx, global const float* data,
                                   global float* lambda, global float* residual, SolveParams p) {
  const uint gid = get_global_id(0);
  if (gid >= p.count) return;
  fem_solve_tet(FEM_MODEL_NEO_HOOKEAN, x, idx, data, lambda, residual, &p, p.first + gid);
}
