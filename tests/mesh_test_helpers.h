// mesh_test_helpers.h — small helpers shared by the tests/mesh_*_test.cpp
// files: a scratch folder per test file and 3-vector arithmetic on Vec3d.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include "sinew/mesh.h"

namespace sinew::mesh_test {

/// SINEW_TEST_TMP_DIR/<name>, created if missing.
inline std::filesystem::path tmp_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(SINEW_TEST_TMP_DIR) / name;
  std::filesystem::create_directories(dir);
  return dir;
}

inline Vec3d sub(const Vec3d& a, const Vec3d& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Signed volume of tet t of m (positive when positively oriented).
inline double signed_volume(const TetMesh& m, const std::array<std::uint32_t, 4>& t) {
  const Vec3d& a = m.vertices[t[0]];
  return dot(sub(m.vertices[t[1]], a), cross(sub(m.vertices[t[2]], a), sub(m.vertices[t[3]], a))) / 6.0;
}

}  // namespace sinew::mesh_test
