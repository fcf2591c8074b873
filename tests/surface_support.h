// surface_support.h — boundary surfaces of the test meshes as the collision
// code takes them (tests/bvh_test.cpp, tests/narrow_phase_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
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

// A smooth bend of amplitude `amount` (mesh units), different per frame: the
// organ deforms, its triangles keep their neighbours (as in
// benchmarks/broad_phase_benchmark.cpp): tests/normal_cones_test.cpp,
// tests/device_narrow_phase_test.cpp.
inline std::vector<float> bent(const Surface& s, float amount, int frame) {
  float lo = INFINITY, hi = -INFINITY;
  for (std::size_t v = 0; v < s.positions.size(); v += 4) lo = std::min(lo, s.positions[v]), hi = std::max(hi, s.positions[v]);
  const float k = 6.2831853f / (hi - lo);
  std::vector<float> x = s.positions;
  for (std::size_t v = 0; v < x.size(); v += 4) {
    const float* r = &s.positions[v];
    x[v] += amount * std::sin(k * r[1] + 0.1f * float(frame));
    x[v + 1] += amount * std::sin(k * r[2] + 0.2f * float(frame));
    x[v + 2] += amount * std::sin(k * r[0] + 0.3f * float(frame));
  }
  return x;
}

}  // namespace sinew::test
