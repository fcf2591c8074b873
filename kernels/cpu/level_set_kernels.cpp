// level_set_kernels.cpp — CPU reference of level_set_sample: a level set's
// value and gradient at points, read from its NanoVDB grid with
// PNanoVDB.h's C mode (libnanovdb-dev; Museth, "NanoVDB: A GPU-friendly
// and portable VDB data structure for real-time rendering and simulation",
// SIGGRAPH 2021 Talks). The interpolation and its order of operations:
// kernels/shared/level_set_params.h; the GPU twin,
// kernels/gpu/level_set_sample.gpu, does the same float operations.
#include <cmath>
#include <cstdint>

#include "cpu/cpu_kernels.h"
#include "level_set_params.h"
#include "math/vec4.h"

#if SINEW_HAS_OPENVDB
#define PNANOVDB_C
#define PNANOVDB_ADDRESS_32
#include <nanovdb/PNanoVDB.h>
#endif

namespace sinew::kernels {

#if SINEW_HAS_OPENVDB
namespace {

float lerp(float a, float b, float t) { return a + t * (b - a); }

// Trilinear over the 8 corners c[a][b][c] (x first, then y, then z).
float trilinear(const float c[2][2][2], float fx, float fy, float fz) {
  const float y0 = lerp(lerp(c[0][0][0], c[1][0][0], fx), lerp(c[0][1][0], c[1][1][0], fx), fy);
  const float y1 = lerp(lerp(c[0][0][1], c[1][0][1], fx), lerp(c[0][1][1], c[1][1][1], fx), fy);
  return lerp(y0, y1, fz);
}

}  // namespace

void level_set_sample(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const LevelSetSampleParams*>(params);
  const pnanovdb_buf_t buf = pnanovdb_make_buf(reinterpret_cast<std::uint32_t*>(bindings[0]), 0);
  const auto* points = reinterpret_cast<const float4*>(bindings[1]);
  auto* samples = reinterpret_cast<float4*>(bindings[2]);
  const pnanovdb_grid_handle_t grid = {pnanovdb_address_null()};
  const pnanovdb_root_handle_t root = pnanovdb_tree_get_root(buf, pnanovdb_grid_get_tree(buf, grid));
  pnanovdb_readaccessor_t access;
  pnanovdb_readaccessor_init(&access, root);
  auto at = [&](int x, int y, int z) {
    pnanovdb_coord_t ijk = {x, y, z};
    return pnanovdb_read_float(buf, pnanovdb_readaccessor_get_value_address(PNANOVDB_GRID_TYPE_FLOAT, buf, &access, &ijk));
  };
  for (std::uint32_t q = begin; q < end && q < p.count; ++q) {
    const float4 x = points[q];
    const float u[3] = {x.x * p.inv_voxel, x.y * p.inv_voxel, x.z * p.inv_voxel};
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
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c)
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
    samples[q] = float4{trilinear(corner, f[0], f[1], f[2]), trilinear(dx, f[0], f[1], f[2]) * p.inv_two_voxel,
                        trilinear(dy, f[0], f[1], f[2]) * p.inv_two_voxel,
                        trilinear(dz, f[0], f[1], f[2]) * p.inv_two_voxel};
  }
}

#else

// Without NanoVDB nothing makes a grid, so nothing dispatches this.
void level_set_sample(const void*, std::byte* const*, std::uint32_t, std::uint32_t) {}

#endif

}  // namespace sinew::kernels
