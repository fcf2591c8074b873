// kidney_case.h — kidney_57k hanging from one side, as benchmarks/organ_step.cpp
// pins it: the mesh (millimetres scaled to metres, the mesher's order), the
// vertices within 5 mm of its lowest x (pinned) and of its highest x (the free
// end whose sag is measured). Used by tests/organ_weight_test.cpp and
// benchmarks/vbd_benchmark.cpp (docs/materials.md, docs/benchmarks.md).
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "sinew/mesh.h"

namespace sinew::test {

struct Kidney {
  TetMesh mesh;
  std::vector<std::uint32_t> pinned, free_end;  // within 5 mm of the lowest / highest x
  std::string error;                            // why the mesh could not be read (empty: it was)
};

inline Kidney kidney_case() {
  Kidney k;
  auto mesh = read_tet_mesh(std::string(SINEW_DATA_DIR) + "/meshes/tet/kidney_57k.node");
  if (!mesh) {
    k.error = mesh.error().message();
    return k;
  }
  scale_mesh(*mesh, 1e-3);
  k.mesh = std::move(*mesh);
  double lo = 1e30, hi = -1e30;
  for (const auto& v : k.mesh.vertices) lo = std::min(lo, v[0]), hi = std::max(hi, v[0]);
  for (std::uint32_t v = 0; v < k.mesh.vertices.size(); ++v) {
    if (k.mesh.vertices[v][0] < lo + 0.005) k.pinned.push_back(v);
    if (k.mesh.vertices[v][0] > hi - 0.005) k.free_end.push_back(v);
  }
  return k;
}

}  // namespace sinew::test
