// Compiled by glslc in the test suite: proves GLSL reads kernels/shared as is.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "xpbd_params.h"
#include "contact_params.h"
#include "fem_params.h"
#include "thin_params.h"
#include "accelerator_params.h"
#include "bvh_params.h"
#include "mesh_contact_params.h"
layout(local_size_x = 64) in;
layout(push_constant) uniform Push { SolveParams p; };
layout(std430, binding = 0) buffer Positions { vec4 x[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < p.count) x[p.first + i].x += p.inv_h2 * p.h * SINEW_FEM_DATA_STRIDE;
}
