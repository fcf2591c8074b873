/* level_set_params.h — sampling a level set inside the kernels (issue 14,
 * part 2): a float NanoVDB grid (the LevelSet's copy, sinew/level_set.h)
 * read through PNanoVDB.h (kernels/gpu/nanovdb_lang.h on the GPUs, its C
 * mode in the CPU reference). Shared by every kernel language
 * (sinew_lang.h). Units: metres.
 *
 * The value at p is trilinear between the voxel centres around it (voxel
 * (i, j, k) holds the distance at (i, j, k) * h; u = p / h, i0 = floor(u),
 * f = u - i0); the gradient is the trilinear interpolation, with the same
 * weights, of the eight corners' central differences (v(+1) - v(-1)) / 2h
 * along each axis: 32 voxels in all (the 8 corners, and along each axis
 * the 8 beyond them). Every item reads them in one order and combines
 * them in one order, written out alike in the CPU reference
 * (kernels/cpu/level_set_kernels.cpp) and the GPU kernel
 * (kernels/gpu/level_set_sample.gpu):
 *   lerp(a, b, t) = a + t (b - a);
 *   value = lerp(lerp(lerp(c000, c100, fx), lerp(c010, c110, fx), fy),
 *                lerp(lerp(c001, c101, fx), lerp(c011, c111, fx), fy), fz),
 *   c_abc the corner (i0 + a, j0 + b, k0 + c); each gradient component the
 *   same expression over the corners' differences, times 1 / 2h.
 *
 * ------------------------------------------------------------ level_set_sample
 * One item per point q < count.
 * bindings: 0 grid uint: the NanoVDB float grid, from byte 0 [in]
 *           1 points float4: xyz in the level set's frame [m], w unused [in]
 *           2 samples float4: (value [m], gradient xyz) [out] */
#ifndef SINEW_LEVEL_SET_PARAMS_H
#define SINEW_LEVEL_SET_PARAMS_H

#include "sinew_lang.h"

#ifdef __cplusplus
namespace sinew::kernels {
#endif

SINEW_STRUCT_BEGIN(LevelSetSampleParams)
  uint count;            /* points */
  float inv_voxel;       /* 1 / h [1/m] */
  float inv_two_voxel;   /* 1 / 2h [1/m] */
  uint pad0;             /* 16-byte size */
SINEW_STRUCT_END(LevelSetSampleParams)

#ifdef __cplusplus
}  // namespace sinew::kernels
#endif

#endif /* SINEW_LEVEL_SET_PARAMS_H */
