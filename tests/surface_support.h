// surface_support.h — boundary surfaces of the test meshes as the collision
// code takes them (tests/bvh_test.cpp, tests/narrow_phase_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sinew/mesh.h"
#include "test_support.h"

namespace sinew::test {

struct Surface {
  std::vector<float> positions;  // xyzw per vertex (w = 0), float like the device's
  std::vector<std::uint32_t> triangles;
  float mean_edge = 0.0f;  // [the mesh's units]
};

inline Surface surface_of(const TriMesh& tri) {
  Surface s;
  for (const auto& v : tri.vertices) s.positions.insert(s.positions.end(), {float(v[0]), float(v[1]), float(v[2]), 0.0f});
  double sum = 0.0;
  for (const auto& t : tri.triangles) {
    s.triangles.insert(s.triangles.end(), t.begin(), t.end());
    for (int e = 0; e < 3; ++e) {
      const auto& a = tri.vertices[t[e]];
      const auto& b = tri.vertices[t[(e + 1) % 3]];
      sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    }
  }
  s.mean_edge = tri.triangles.empty() ? 0.0f : float(sum / (3.0 * double(tri.triangles.size())));
  return s;
}

/// The boundary surface of a tet mesh file under the test data folder.
inline Surface surface_of(const std::string& mesh_file) {
  auto mesh = read_tet_mesh(data_path(mesh_file));
  EXPECT_TRUE(mesh.ok()) << mesh_file << ": " << (mesh.ok() ? "" : mesh.error().message());
  if (!mesh.ok()) return {};
  return surface_of(extract_boundary_surface(*mesh));
}

}  // namespace sinew::test
