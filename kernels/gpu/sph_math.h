/* sph_math.h — the cubic spline's shape and slope for the sph_*.gpu
 * kernels, in the order of operations kernels/shared/sph_params.h fixes
 * (the CPU reference: kernels/cpu/sph_kernels.cpp). */
#ifndef SINEW_SPH_MATH_H
#define SINEW_SPH_MATH_H

float sph_cubic(float q) {
  if (q < 1.0f) {
    PRECISE float a = (1.5f * q) * q;
    PRECISE float b = ((0.75f * q) * q) * q;
    return (1.0f - a) + b;
  }
  PRECISE float t = 2.0f - q;
  PRECISE float w = ((0.25f * t) * t) * t;
  return w;
}

float sph_cubic_slope(float q) {
  if (q < 1.0f) {
    PRECISE float a = (2.25f * q) * q;
    PRECISE float b = 3.0f * q;
    return a - b;
  }
  PRECISE float t = 2.0f - q;
  PRECISE float d = (-0.75f * t) * t;
  return d;
}

#endif /* SINEW_SPH_MATH_H */
