// level_set_sampling.h — the CPU reference's sampling of a level set's
// NanoVDB grid (PNanoVDB.h's C mode, libnanovdb-dev): value and gradient at
// a point, in the float operations and order of
// kernels/shared/level_set_params.h, which the GPU twin
// (kernels/gpu/level_set_math.h) repeats. Used by level_set_sample and by
// the contacts' level-set colliders (contact_kernels.cpp). Only with
// NanoVDB (SINEW_HAS_OPENVDB).
#pragma once

#include <cmath>
#include <cstdint>

#include "math/vec4.h"

#define PNANOVDB_C
#define PNANOVDB_ADDRESS_32
#include <nanovdb/PNanoVDB.h>

namespace sinew::kernels {

inline float level_set_lerp(float a, float b, float t) { return a + t * (b - a); }

// Trilinear over the 8 corners c[a][b][c] (x first, then y, then z).
inline float level_set_trilinear(const float c[2][2][2], float fx, float fy, float fz) {
  const float y0 = level_set_lerp(level_set_lerp(c[0][0][0], c[1][0][0], fx), level_set_lerp(c[0][1][0], c[1][1][0], fx), fy);
  const float y1 = level_set_lerp(level_set_lerp(c[0][0][1], c[1][0][1], fx), level_set_lerp(c[0][1][1], c[1][1][1], fx), fy);
  return level_set_lerp(y0, y1, fz);
}

/// (value [m], gradient) at p [m] (xyz; w ignored) of the grid starting at
/// byte `grid_offset` of `words`; inv_voxel = 1 / h, inv_two_voxel = 1 / 2h.
inline float4 sample_level_set_grid(std::uint32_t* words, std::uint32_t grid_offset, float inv_voxel,
                                    float inv_two_voxel, float4 x) {
  const pnanovdb_buf_t buf = pnanovdb_make_buf(words, 0);
  pnanovdb_grid_handle_t grid = {pnanovdb_address_null()};
  grid.address.byte_offset = grid_offset;
  const pnanovdb_root_handle_t root = pnanovdb_tree_get_root(buf, pnanovdb_grid_get_tree(buf, grid));
  pnanovdb_readaccessor_t access;
  pnanovdb_readaccessor_init(&access, root);
  auto at = [&](int vx, int vy, int vz) {
    pnanovdb_coord_t ijk = {vx, vy, vz};
    return pnanovdb_read_float(buf, pnanovdb_readaccessor_get_value_address(PNANOVDB_GRID_TYPE_FLOAT, buf, &access, &ijk));
  };
  const float u[3] = {x.x * inv_voxel, x.y * inv_voxel, x.z * inv_voxel};
  int i0[3];
  float f[3];
  for (int k = 0; k < 3; ++k) {
    const float fl = std::floor(u[k]);
    i0[k] = static_cast<int>(fl);
    f[k] = u[k] - fl;
  }
  // Along x: the lines (j0 + b, k0 + c), x = i0 - 1 .. i0 + 2; along y and
  // z only the two beyond the corners (the corners are read with x).
  float lx[2][2][4], ly[2][2][2], lz[2][2][2];
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      for (int t = 0; t < 4; ++t) lx[b][c][t] = at(i0[0] - 1 + t, i0[1] + b, i0[2] + c);
  for (int a = 0; a < 2; ++a)
    for (int c = 0; c < 2; ++c) {
      ly[a][c][0] = at(i0[0] + a, i0[1] - 1, i0[2] + c);
      ly[a][c][1] = at(i0[0] + a, i0[1] + 2, i0[2] + c);
    }
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      lz[a][b][0] = at(i0[0] + a, i0[1] + b, i0[2] - 1);
      lz[a][b][1] = at(i0[0] + a, i0[1] + b, i0[2] + 2);
    }
  float corner[2][2][2], dx[2][2][2], dy[2][2][2], dz[2][2][2];
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) corner[a][b][c] = lx[b][c][a + 1];
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) {
        dx[a][b][c] = lx[b][c][a + 2] - lx[b][c][a];
        dy[a][b][c] = (b == 0 ? corner[a][1][c] : ly[a][c][1]) - (b == 0 ? ly[a][c][0] : corner[a][0][c]);
        dz[a][b][c] = (c == 0 ? corner[a][b][1] : lz[a][b][1]) - (c == 0 ? lz[a][b][0] : corner[a][b][0]);
      }
  return float4{level_set_trilinear(corner, f[0], f[1], f[2]), level_set_trilinear(dx, f[0], f[1], f[2]) * inv_two_voxel,
                level_set_trilinear(dy, f[0], f[1], f[2]) * inv_two_voxel,
                level_set_trilinear(dz, f[0], f[1], f[2]) * inv_two_voxel};
}

}  // namespace sinew::kernels
