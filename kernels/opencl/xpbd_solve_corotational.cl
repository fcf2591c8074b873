// xpbd_solve_corotational.cl — OpenCL twin of
// kernels/cpu/fem_kernels.cpp:xpbd_solve_corotational.
// Macklin, Müller, Chentanez, "XPBD", MIG 2016; the coupled solve of Macklin,
// Müller, "A Constraint-based Formulation of Stable Neo-Hookean Materials",
// MIG 2021; corotational linear: Müller, Gross, "Interactive Virtual
// Materials", GI 2004; inversion: Irving, Teran, Fedkiw, "Invertible Finite
// Elements for Robust Simulation of Large Deformation", SCA 2004; rotation:
// Horn, "Closed-form solution of absolute orientation using unit
// quaternions", JOSA A 4(4), 1987, by cyclic Jacobi (Golub, Van Loan,
// "Matrix Computations", 4th ed., section 8.5). One work item per tet of one
// colour: C_D = |F - R|_F and C_H = tr(R^T F) - 3 solved together as one
// 2x2 xPBD system (fem_math.h: fem_solve_tet).
#include "cl_math.h"
#include "fem_math.h"
#include "xpbd_params.h"

kernel void xpbd_solve_corotational(global float4* x, global const uint4* idx, global const float* data,
                                    global float* lambda, global float* residual, SolveParams p) {
  const uint gid = get_global_id(0);
  if (gid >= p.count) return;
  fem_solve_tet(FEM_MODEL_COROTATIONAL, x, idx, data, lambda, residual, &p, p.first + gid);
}
