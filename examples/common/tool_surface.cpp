// tool_surface.cpp — a tool's surface written as a VTU (tool_surface.h).
#include "tool_surface.h"

#include <vector>

namespace sinew::examples {

Status write_capsule_vtu(const std::filesystem::path& path, double radius, double half_height, const Pose& pose) {
  const TriMesh mesh = capsule_surface(radius, half_height, pose);
  std::vector<float> xyz;
  for (const auto& v : mesh.vertices) xyz.insert(xyz.end(), {float(v[0]), float(v[1]), float(v[2])});
  return write_vtu_triangles(path, xyz, 3, mesh.triangles);
}

}  // namespace sinew::examples
