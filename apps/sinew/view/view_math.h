// view_math.h — the little linear algebra the viewer needs (sinew view,
// docs/viewer.md): float 3-vectors and column-major 4x4 matrices as
// OpenGL takes them, a perspective, a look-at and a pose's matrix.
#pragma once

#include <array>
#include <cmath>

namespace sinew::view {

/// A float 3-vector (positions [m], directions, colours).
struct V3 {
  float x = 0, y = 0, z = 0;
  V3() = default;
  V3(float a, float b, float c) : x(a), y(b), z(c) {}
  explicit V3(const std::array<double, 3>& a)
      : x(static_cast<float>(a[0])), y(static_cast<float>(a[1])), z(static_cast<float>(a[2])) {}
  [[nodiscard]] std::array<double, 3> to_double() const { return {x, y, z}; }
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline float length(V3 a) { return std::sqrt(dot(a, a)); }
inline V3 normalize(V3 a) {
  const float l = length(a);
  return l > 0 ? a * (1.0f / l) : V3{0, 0, 0};
}

/// A column-major 4x4 matrix (m[column * 4 + row]), as glUniformMatrix4fv takes it.
struct M4 {
  std::array<float, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  float& at(int row, int col) { return m[col * 4 + row]; }
  [[nodiscard]] float at(int row, int col) const { return m[col * 4 + row]; }
};
inline M4 operator*(const M4& a, const M4& b) {
  M4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += a.at(i, k) * b.at(k, j);
      r.at(i, j) = s;
    }
  return r;
}
/// a applied to the point p (w = 1), divided by w: clip -> normalised device coordinates.
inline V3 transform_point(const M4& a, V3 p, float* w_out = nullptr) {
  const float x = a.at(0, 0) * p.x + a.at(0, 1) * p.y + a.at(0, 2) * p.z + a.at(0, 3);
  const float y = a.at(1, 0) * p.x + a.at(1, 1) * p.y + a.at(1, 2) * p.z + a.at(1, 3);
  const float z = a.at(2, 0) * p.x + a.at(2, 1) * p.y + a.at(2, 2) * p.z + a.at(2, 3);
  const float w = a.at(3, 0) * p.x + a.at(3, 1) * p.y + a.at(3, 2) * p.z + a.at(3, 3);
  if (w_out) *w_out = w;
  return w != 0 ? V3{x / w, y / w, z / w} : V3{x, y, z};
}

/// A right-handed perspective projection: [in] fov_y [rad], aspect (width / height), near and far [m] > 0.
inline M4 perspective(float fov_y, float aspect, float near, float far) {
  M4 r;
  r.m.fill(0);
  const float f = 1.0f / std::tan(fov_y / 2);
  r.at(0, 0) = f / aspect;
  r.at(1, 1) = f;
  r.at(2, 2) = (far + near) / (near - far);
  r.at(2, 3) = 2 * far * near / (near - far);
  r.at(3, 2) = -1;
  return r;
}

/// The view matrix of an eye at `eye` looking at `target` with `up` up.
inline M4 look_at(V3 eye, V3 target, V3 up) {
  const V3 f = normalize(target - eye), s = normalize(cross(f, up)), u = cross(s, f);
  M4 r;
  r.at(0, 0) = s.x, r.at(0, 1) = s.y, r.at(0, 2) = s.z, r.at(0, 3) = -dot(s, eye);
  r.at(1, 0) = u.x, r.at(1, 1) = u.y, r.at(1, 2) = u.z, r.at(1, 3) = -dot(u, eye);
  r.at(2, 0) = -f.x, r.at(2, 1) = -f.y, r.at(2, 2) = -f.z, r.at(2, 3) = dot(f, eye);
  return r;
}

/// The matrix of a pose: [in] position [m], rotation a unit quaternion
/// (w, x, y, z), then a scale along each local axis.
inline M4 pose_matrix(const std::array<double, 3>& position, const std::array<double, 4>& q,
                      V3 scale = {1, 1, 1}) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  const float s[3] = {scale.x, scale.y, scale.z};
  M4 m;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.at(i, j) = static_cast<float>(r[i][j]) * s[j];
    m.at(i, 3) = static_cast<float>(position[i]);
  }
  return m;
}

/// The matrix that turns local +y into `direction` (any length > 0) at `origin`, scaled
/// by `width` across and by |direction| along (an arrow, a segment).
inline M4 along_matrix(V3 origin, V3 direction, float width) {
  const float len = length(direction);
  const V3 y = len > 0 ? direction * (1.0f / len) : V3{0, 1, 0};
  const V3 helper = std::fabs(y.x) < 0.9f ? V3{1, 0, 0} : V3{0, 0, 1};
  const V3 x = normalize(cross(helper, y)), z = cross(x, y);
  M4 m;
  const V3 cols[3] = {x * width, y * len, z * width};
  for (int j = 0; j < 3; ++j) m.at(0, j) = cols[j].x, m.at(1, j) = cols[j].y, m.at(2, j) = cols[j].z;
  m.at(0, 3) = origin.x, m.at(1, 3) = origin.y, m.at(2, 3) = origin.z;
  return m;
}

}  // namespace sinew::view
