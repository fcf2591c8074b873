// src/math/mat3.h — the host's 3x3 matrices in double precision, rows of
// math::Vec3: determinant, Cramer's-rule solve, inverse and product, inline
// and allocation-free (tick-safe). Used by the rigid tools' integration
// (src/runtime) and the haptic thread's contact solve (src/haptics).
//
// As in vec3.h, keep each operation's arithmetic as it is: the tools'
// trajectories depend on its rounding bit for bit.
#pragma once

#include <array>
#include <cmath>

#include "math/vec3.h"

namespace sinew::math {

using Mat3 = std::array<Vec3, 3>;  ///< row-major

inline double det3(const Mat3& a) {
  return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
         a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

/// Solves a x = f by Cramer's rule; false (x untouched) when a is singular.
inline bool solve3(const Mat3& a, const Vec3& f, Vec3& x) {
  const double d = det3(a);
  if (!(std::abs(d) > 0.0) || !std::isfinite(d)) return false;
  Vec3 out;
  for (int k = 0; k < 3; ++k) {
    Mat3 m = a;
    for (int r = 0; r < 3; ++r) m[r][k] = f[r];
    out[k] = det3(m) / d;
  }
  x = out;
  return true;
}

/// a^-1, column by column (solve3 on the unit vectors); false (inverse
/// untouched) when a is singular.
inline bool invert3(const Mat3& a, Mat3& inverse) {
  Mat3 out;
  for (int c = 0; c < 3; ++c) {
    Vec3 e{0.0, 0.0, 0.0}, x{0.0, 0.0, 0.0};
    e[c] = 1.0;
    if (!solve3(a, e, x)) return false;
    for (int r = 0; r < 3; ++r) out[r][c] = x[r];
  }
  inverse = out;
  return true;
}

/// a v.
inline Vec3 mul3(const Mat3& a, const Vec3& v) { return {dot(a[0], v), dot(a[1], v), dot(a[2], v)}; }

}  // namespace sinew::math
