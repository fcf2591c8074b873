// xpbd_solve_neo_hookean.comp — GLSL twin of
// kernels/cpu/fem_kernels.cpp:xpbd_solve_neo_hookean (and the OpenCL one).
// Macklin, Müller, Chentanez, "XPBD", MIG 2016; Macklin, Müller, "A
// Constraint-based Formulation of Stable Neo-Hookean Materials", MIG 2021.
// One invocation per tet of one colour: C_D = |F|_F and C_H = det F - gamma
// solved together as one 2x2 xPBD system (fem_math.h: fem_solve_tet).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "glsl_math.h"
#include "xpbd_params.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { SolveParams p; };
layout(std430, binding = 0) buffer Position { vec4 x[]; };
layout(std430, binding = 1) readonly buffer Indices { uvec4 idx[]; };
layout(std430, binding = 2) readonly buffer TetData { float fem_data[]; };
layout(std430, binding = 3) buffer Lambda { float lambda[]; };
layout(std430, binding = 4) writeonly buffer Residual { float residual[]; };

// After the buffers: fem_solve_tet uses them.
#include "fem_math.h"

void main() {
  const uint gid = gl_GlobalInvocationID.x;
  if (gid >= p.count) return;
  fem_solve_tet(FEM_MODEL_NEO_HOOKEAN, p.first + gid);
}
