// Compiled as OpenCL C 1.2 in the test suite: proves OpenCL reads kernels/shared as is.
#include "xpbd_params.h"
#include "contact_params.h"
#include "fem_params.h"
#include "thin_params.h"
#include "accelerator_params.h"
#include "bvh_params.h"
#include "mesh_contact_params.h"
kernel void uses_params(global float4* x, SolveParams p, PredictParams q) {
  uint i = get_global_id(0);
  if (i < p.count) x[p.first + i].x += p.inv_h2 * q.h * SINEW_FEM_DATA_STRIDE;
}
