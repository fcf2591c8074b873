// sph_spline.h — Monaghan's cubic spline (kernels/shared/sph_params.h) for
// the scalar CPU reference kernels of the fluids (sph_kernels.cpp,
// pbf_kernels.cpp, sph_tension_kernels.cpp), in the order of operations of
// the GPU twins (kernels/gpu/sph_math.h). The AVX2 kernels keep their own
// copies: an inline function shared with them could be emitted with AVX2
// instructions (sph_kernels_avx2.cpp says why).
#pragma once

namespace sinew::kernels::spline {

/// The shape w(q), 0 <= q < 2.
inline float shape(float q) {
  if (q < 1.0f) return (1.0f - (1.5f * q) * q) + ((0.75f * q) * q) * q;
  const float t = 2.0f - q;
  return ((0.25f * t) * t) * t;
}

/// The slope w'(q), 0 <= q < 2.
inline float slope(float q) {
  if (q < 1.0f) return (2.25f * q) * q - 3.0f * q;
  const float t = 2.0f - q;
  return (-0.75f * t) * t;
}

}  // namespace sinew::kernels::spline
