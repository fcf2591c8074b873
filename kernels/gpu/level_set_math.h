/* level_set_math.h — a level set's value and gradient at a point, read
 * from its NanoVDB grid with PNanoVDB.h (nanovdb_lang.h, which the kernel
 * includes first with its grid binding): the GPU twin of
 * kernels/cpu/level_set_sampling.h, the same float operations in the same
 * order (kernels/shared/level_set_params.h). Used by level_set_sample and
 * by the contacts' level-set colliders (xpbd_solve_contacts). */
#ifndef SINEW_LEVEL_SET_MATH_H
#define SINEW_LEVEL_SET_MATH_H

#if SINEW_HAS_NANOVDB

// The grid's value at voxel (x, y, z), through the accessor's cached nodes.
float level_set_voxel(pnanovdb_buf_t buf, PNANOVDB_INOUT(pnanovdb_readaccessor_t) access, int x, int y, int z) {
  pnanovdb_coord_t ijk;
  ijk.x = x;
  ijk.y = y;
  ijk.z = z;
  return pnanovdb_read_float(
      buf, pnanovdb_readaccessor_get_value_address(PNANOVDB_GRID_TYPE_FLOAT, buf, access, PNANOVDB_REF(ijk)));
}
PRECISE float level_set_lerp(float a, float b, float t) {
  PRECISE float r = a + t * (b - a);
  return r;
}
// Trilinear over 8 corners, c[a + 2 b + 4 c] (x first, then y, then z).
PRECISE float level_set_trilinear(float c[8], float fx, float fy, float fz) {
  PRECISE float y0 = level_set_lerp(level_set_lerp(c[0], c[1], fx), level_set_lerp(c[2], c[3], fx), fy);
  PRECISE float y1 = level_set_lerp(level_set_lerp(c[4], c[5], fx), level_set_lerp(c[6], c[7], fx), fy);
  return level_set_lerp(y0, y1, fz);
}

// (value [m], gradient) at point (x, y, z) [m] of the grid that starts at
// byte `grid_offset` of the buffer; inv_voxel = 1 / h, inv_two_voxel = 1 / 2h.
float4 level_set_sample_at(pnanovdb_buf_t buf, uint grid_offset, float inv_voxel, float inv_two_voxel, float px,
                           float py, float pz) {
  pnanovdb_grid_handle_t handle;
  handle.address.byte_offset = grid_offset;
  pnanovdb_root_handle_t root = pnanovdb_tree_get_root(buf, pnanovdb_grid_get_tree(buf, handle));
  pnanovdb_readaccessor_t access;
  pnanovdb_readaccessor_init(PNANOVDB_REF(access), root);
  PRECISE float ux = px * inv_voxel;
  PRECISE float uy = py * inv_voxel;
  PRECISE float uz = pz * inv_voxel;
  const float flx = floor(ux), fly = floor(uy), flz = floor(uz);
  const int i0 = to_int(flx), j0 = to_int(fly), k0 = to_int(flz);
  PRECISE float fx = ux - flx;
  PRECISE float fy = uy - fly;
  PRECISE float fz = uz - flz;
  // Along x: the lines (j0 + b, k0 + c), x = i0 - 1 .. i0 + 2, at
  // lx[4 (b + 2 c) + t]; along y and z the two beyond the corners.
  float lx[16];
  float ly[8];
  float lz[8];
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      for (int t = 0; t < 4; ++t)
        lx[4 * (b + 2 * c) + t] = level_set_voxel(buf, PNANOVDB_REF(access), i0 - 1 + t, j0 + b, k0 + c);
  for (int a = 0; a < 2; ++a)
    for (int c = 0; c < 2; ++c) {
      ly[2 * (a + 2 * c)] = level_set_voxel(buf, PNANOVDB_REF(access), i0 + a, j0 - 1, k0 + c);
      ly[2 * (a + 2 * c) + 1] = level_set_voxel(buf, PNANOVDB_REF(access), i0 + a, j0 + 2, k0 + c);
    }
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      lz[2 * (a + 2 * b)] = level_set_voxel(buf, PNANOVDB_REF(access), i0 + a, j0 + b, k0 - 1);
      lz[2 * (a + 2 * b) + 1] = level_set_voxel(buf, PNANOVDB_REF(access), i0 + a, j0 + b, k0 + 2);
    }
  float corner[8];
  float dx[8];
  float dy[8];
  float dz[8];
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) corner[a + 2 * b + 4 * c] = lx[4 * (b + 2 * c) + a + 1];
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) {
        const int n = a + 2 * b + 4 * c;
        PRECISE float gx = lx[4 * (b + 2 * c) + a + 2] - lx[4 * (b + 2 * c) + a];
        PRECISE float gy = (b == 0 ? corner[a + 2 + 4 * c] : ly[2 * (a + 2 * c) + 1]) -
                           (b == 0 ? ly[2 * (a + 2 * c)] : corner[a + 4 * c]);
        PRECISE float gz = (c == 0 ? corner[a + 2 * b + 4] : lz[2 * (a + 2 * b) + 1]) -
                           (c == 0 ? lz[2 * (a + 2 * b)] : corner[a + 2 * b]);
        dx[n] = gx;
        dy[n] = gy;
        dz[n] = gz;
      }
  PRECISE float value = level_set_trilinear(corner, fx, fy, fz);
  PRECISE float gx = level_set_trilinear(dx, fx, fy, fz) * inv_two_voxel;
  PRECISE float gy = level_set_trilinear(dy, fx, fy, fz) * inv_two_voxel;
  PRECISE float gz = level_set_trilinear(dz, fx, fy, fz) * inv_two_voxel;
  return make_float4(value, gx, gy, gz);
}

#endif /* SINEW_HAS_NANOVDB */
#endif /* SINEW_LEVEL_SET_MATH_H */
