/* stats_math.h — what the statistics' GPU kernels share; twin of the
 * helpers in kernels/cpu/stats_kernels.cpp (same float operations in the
 * same order, so the backends agree bitwise). */
#ifndef SINEW_GPU_STATS_MATH_H
#define SINEW_GPU_STATS_MATH_H

/* dot(a - r, cross(b - r, c - r)), six times the signed volume of the tet
 * (r, a, b, c), as a double-float from exact differences (the difference of
 * two floats is exact as a pair). */
float2 dd_six_volume(float4 a, float4 b, float4 c, float4 r) {
  const float2 e1x = dd_two_sum(a.x, -r.x);
  const float2 e1y = dd_two_sum(a.y, -r.y);
  const float2 e1z = dd_two_sum(a.z, -r.z);
  const float2 e2x = dd_two_sum(b.x, -r.x);
  const float2 e2y = dd_two_sum(b.y, -r.y);
  const float2 e2z = dd_two_sum(b.z, -r.z);
  const float2 e3x = dd_two_sum(c.x, -r.x);
  const float2 e3y = dd_two_sum(c.y, -r.y);
  const float2 e3z = dd_two_sum(c.z, -r.z);
  const float2 nx = dd_sub(dd_mul(e2y, e3z), dd_mul(e2z, e3y));
  const float2 ny = dd_sub(dd_mul(e2z, e3x), dd_mul(e2x, e3z));
  const float2 nz = dd_sub(dd_mul(e2x, e3y), dd_mul(e2y, e3x));
  return dd_add(dd_add(dd_mul(e1x, nx), dd_mul(e1y, ny)), dd_mul(e1z, nz));
}

#endif
