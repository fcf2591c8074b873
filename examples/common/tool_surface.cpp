// tool_surface.cpp — the tools' display surfaces (tool_surface.h).
#include "tool_surface.h"

#include <cmath>


namespace sinew::examples {

std::array<double, 3> rotate(const std::array<double, 4>& q, const std::array<double, 3>& v) {
  // v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z).
  const double w = q[0], u[3] = {q[1], q[2], q[3]};
  const double t[3] = {2 * (u[1] * v[2] - u[2] * v[1]), 2 * (u[2] * v[0] - u[0] * v[2]), 2 * (u[0] * v[1] - u[1] * v[0])};
  std::array<double, 3> r{};
  for (int k = 0; k < 3; ++k) r[k] = v[k] + w * t[k] + u[(k + 1) % 3] * t[(k + 2) % 3] - u[(k + 2) % 3] * t[(k + 1) % 3];
  return r;
}

namespace {
void place(const Pose& pose, const std::array<double, 3>& local, std::vector<float>& xyz) {
  const auto p = rotate(pose.rotation, local);
  for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(pose.position[k] + p[k]));
}
}  // namespace

TriMesh capsule_surface(double radius, double half_height, const Pose& pose) {
  // Rings of latitude: the upper half-sphere's lifted by +half_height, the
  // lower one's by -half_height (two rings at the equator: the cylinder).
  constexpr int kAround = 24, kLatitudes = 12;  // kLatitudes even
  std::vector<std::array<double, 2>> rings;     // (polar angle, lift)
  for (int k = 1; k <= kLatitudes / 2; ++k) rings.push_back({M_PI * k / kLatitudes, half_height});
  for (int k = kLatitudes / 2 + (half_height > 0.0 ? 0 : 1); k < kLatitudes; ++k)
    rings.push_back({M_PI * k / kLatitudes, -half_height});
  TriMesh mesh;
  const auto place = [&](const std::array<double, 3>& local) {
    const auto p = rotate(pose.rotation, local);
    mesh.vertices.push_back({pose.position[0] + p[0], pose.position[1] + p[1], pose.position[2] + p[2]});
  };
  place({0.0, radius + half_height, 0.0});  // the top pole: vertex 0
  for (const auto& [theta, lift] : rings)
    for (int a = 0; a < kAround; ++a) {
      const double phi = 2.0 * M_PI * a / kAround;
      place({radius * std::sin(theta) * std::cos(phi), lift + radius * std::cos(theta),
             radius * std::sin(theta) * std::sin(phi)});
    }
  const auto bottom = static_cast<std::uint32_t>(mesh.vertices.size());
  place({0.0, -radius - half_height, 0.0});
  const auto at = [](std::size_t ring, int a) {
    return static_cast<std::uint32_t>(1 + ring * kAround + (a % kAround));
  };
  for (int a = 0; a < kAround; ++a) {
    mesh.triangles.push_back({0, at(0, a + 1), at(0, a)});
    for (std::size_t r = 0; r + 1 < rings.size(); ++r) {
      mesh.triangles.push_back({at(r, a), at(r, a + 1), at(r + 1, a + 1)});
      mesh.triangles.push_back({at(r, a), at(r + 1, a + 1), at(r + 1, a)});
    }
    mesh.triangles.push_back({bottom, at(rings.size() - 1, a), at(rings.size() - 1, a + 1)});
  }
  return mesh;
}

Status write_capsule_vtu(const std::filesystem::path& path, double radius, double half_height, const Pose& pose) {
  const TriMesh mesh = capsule_surface(radius, half_height, pose);
  std::vector<float> xyz;
  for (const auto& v : mesh.vertices) xyz.insert(xyz.end(), {float(v[0]), float(v[1]), float(v[2])});
  return write_vtu_triangles(path, xyz, 3, mesh.triangles);
}

Status write_box_vtu(const std::filesystem::path& path, const std::array<double, 3>& half_extents, const Pose& pose) {
  std::vector<float> xyz;
  for (int corner = 0; corner < 8; ++corner)  // bit k: + or - along axis k
    place(pose,
          {(corner & 1 ? 1 : -1) * half_extents[0], (corner & 2 ? 1 : -1) * half_extents[1],
           (corner & 4 ? 1 : -1) * half_extents[2]},
          xyz);
  // Two triangles per face, outward.
  const std::vector<std::array<std::uint32_t, 3>> triangles{{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5},
                                                            {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                                            {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};
  return write_vtu_triangles(path, xyz, 3, triangles);
}

Status write_polyline_vtu(const std::filesystem::path& path, const std::vector<std::array<double, 3>>& points,
                          const Pose& pose) {
  std::vector<float> xyz;
  for (const auto& p : points) place(pose, p, xyz);
  std::vector<std::array<std::uint32_t, 2>> cells;
  for (std::uint32_t i = 0; i + 1 < points.size(); ++i) cells.push_back({i, i + 1});
  return write_vtu_lines(path, xyz, 3, cells);
}

}  // namespace sinew::examples
