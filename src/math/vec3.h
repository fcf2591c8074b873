// src/math/vec3.h — the host's 3-vectors and unit quaternions, in double
// precision on std::array: one set of inline, allocation-free operations
// (tick-safe) for the haptics code, the rigid tools (src/runtime), the scene
// checks and the mesh code. Quaternions are (w, x, y, z). The kernels' float
// vectors are kernels/math/vec4.h, not these.
//
// Keep each operation's arithmetic as it is: the haptics tests and the
// tools' trajectories depend on its rounding bit for bit (e.g. norm is
// sqrt(dot), evaluated left to right; normalize scales first, qnorm does not).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace sinew::math {

using Vec3 = std::array<double, 3>;
using Quat = std::array<double, 4>;  ///< (w, x, y, z)

inline Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 mul(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
inline bool finite(const Vec3& a) { return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]); }
inline bool finite(const Quat& q) {
  return std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]) && std::isfinite(q[3]);
}
/// a + u (b - a)
inline Vec3 lerp(const Vec3& a, const Vec3& b, double u) {
  return {a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * (b[2] - a[2])};
}

inline Quat qmul(const Quat& a, const Quat& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3], a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1], a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}
inline Quat conj(const Quat& q) { return {q[0], -q[1], -q[2], -q[3]}; }
inline double qdot(const Quat& a, const Quat& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }
/// |q| = sqrt(qdot(q, q)), unscaled (see normalize for a robust unit quaternion).
inline double qnorm(const Quat& q) { return std::sqrt(qdot(q, q)); }
/// The product (0, o) q of the pure quaternion (0, o) and q: with o an
/// angular velocity, dq/dt = (0, o) q / 2.
inline Quat pure_mul(const Vec3& o, const Quat& q) {
  return {-(o[0] * q[1] + o[1] * q[2] + o[2] * q[3]), o[0] * q[0] + o[1] * q[3] - o[2] * q[2],
          o[1] * q[0] + o[2] * q[1] - o[0] * q[3], o[2] * q[0] + o[0] * q[2] - o[1] * q[1]};
}
/// v rotated by the unit quaternion q: v + 2 w (u x v) + 2 u x (u x v),
/// u = (x, y, z); rotate(conj(q), v) is the inverse rotation.
inline Vec3 rotate(const Quat& q, const Vec3& v) {
  const Vec3 u{q[1], q[2], q[3]};
  const Vec3 t = mul(cross(u, v), 2.0);
  const Vec3 ut = cross(u, t);
  return {v[0] + q[0] * t[0] + ut[0], v[1] + q[0] * t[1] + ut[1], v[2] + q[0] * t[2] + ut[2]};
}
/// q / |q|; the identity only for an exactly zero q. A NaN or Inf
/// component gives all NaN: a bad rotation must stay non-finite so the
/// coupling's finite check zeroes force and torque (mapped to the identity
/// it would be rendered as a real twist).
inline Quat normalize(const Quat& q) {
  if (!finite(q)) {
    const double nan = std::nan("");
    return {nan, nan, nan, nan};
  }
  // Scaled by the largest component first: |q|^2 neither overflows nor underflows.
  const double m = std::max(std::max(std::abs(q[0]), std::abs(q[1])), std::max(std::abs(q[2]), std::abs(q[3])));
  if (m == 0.0) return {1.0, 0.0, 0.0, 0.0};
  const Quat s{q[0] / m, q[1] / m, q[2] / m, q[3] / m};
  const double n = std::sqrt(qdot(s, s));
  return {s[0] / n, s[1] / n, s[2] / n, s[3] / n};
}
/// Normalised lerp from a to b (b taken on a's hemisphere), u may exceed 1 (extrapolation).
inline Quat nlerp(const Quat& a, const Quat& b, double u) {
  const double s = qdot(a, b) < 0.0 ? -1.0 : 1.0;
  return normalize({a[0] + u * (s * b[0] - a[0]), a[1] + u * (s * b[1] - a[1]), a[2] + u * (s * b[2] - a[2]),
                    a[3] + u * (s * b[3] - a[3])});
}
/// The rotation vector (axis * angle, angle in [0, pi]) of a unit quaternion.
inline Vec3 rotation_vector(const Quat& q_in) {
  const Quat q = q_in[0] < 0.0 ? Quat{-q_in[0], -q_in[1], -q_in[2], -q_in[3]} : q_in;
  const double s = std::sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (s < 1e-12) return {2.0 * q[1], 2.0 * q[2], 2.0 * q[3]};  // small angle: 2 v
  const double angle = 2.0 * std::atan2(s, q[0]);
  return {q[1] * angle / s, q[2] * angle / s, q[3] * angle / s};
}
/// The angular velocity [rad/s] that turns a into b in dt [s] (world frame).
inline Vec3 angular_velocity(const Quat& a, const Quat& b, double dt) {
  if (!(dt > 0.0)) return {0.0, 0.0, 0.0};
  return mul(rotation_vector(qmul(b, conj(a))), 1.0 / dt);
}

}  // namespace sinew::math
