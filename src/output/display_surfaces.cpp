// display_surfaces.cpp — the analytic shapes' display surfaces (display_surfaces.h).
#include "sinew/display_surfaces.h"

#include <cmath>
#include <numbers>

namespace sinew {

std::array<double, 3> rotate(const std::array<double, 4>& q, const std::array<double, 3>& v) {
  // v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z).
  const double w = q[0], u[3] = {q[1], q[2], q[3]};
  const double t[3] = {2 * (u[1] * v[2] - u[2] * v[1]), 2 * (u[2] * v[0] - u[0] * v[2]), 2 * (u[0] * v[1] - u[1] * v[0])};
  std::array<double, 3> r{};
  for (int k = 0; k < 3; ++k) r[k] = v[k] + w * t[k] + u[(k + 1) % 3] * t[(k + 2) % 3] - u[(k + 2) % 3] * t[(k + 1) % 3];
  return r;
}

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kAround = 24;  // segments around a round shape's axis

std::array<double, 3> place(const Pose& pose, const std::array<double, 3>& local) {
  const auto p = rotate(pose.rotation, local);
  return {pose.position[0] + p[0], pose.position[1] + p[1], pose.position[2] + p[2]};
}

// A surface of revolution about y: a top pole, rings of (radius, y) and a
// bottom pole, triangles wound outward.
TriMesh revolve(double top, const std::vector<std::array<double, 2>>& rings, double bottom, const Pose& pose) {
  TriMesh mesh;
  mesh.vertices.push_back(place(pose, {0.0, top, 0.0}));  // vertex 0
  for (const auto& [r, y] : rings)
    for (int a = 0; a < kAround; ++a) {
      const double phi = 2.0 * kPi * a / kAround;
      mesh.vertices.push_back(place(pose, {r * std::cos(phi), y, r * std::sin(phi)}));
    }
  const auto last = static_cast<std::uint32_t>(mesh.vertices.size());
  mesh.vertices.push_back(place(pose, {0.0, bottom, 0.0}));
  const auto at = [](std::size_t ring, int a) { return static_cast<std::uint32_t>(1 + ring * kAround + (a % kAround)); };
  for (int a = 0; a < kAround; ++a) {
    mesh.triangles.push_back({0, at(0, a + 1), at(0, a)});
    for (std::size_t r = 0; r + 1 < rings.size(); ++r) {
      mesh.triangles.push_back({at(r, a), at(r, a + 1), at(r + 1, a + 1)});
      mesh.triangles.push_back({at(r, a), at(r + 1, a + 1), at(r + 1, a)});
    }
    mesh.triangles.push_back({last, at(rings.size() - 1, a), at(rings.size() - 1, a + 1)});
  }
  return mesh;
}

}  // namespace

TriMesh capsule_surface(double radius, double half_height, const Pose& pose) {
  // Rings of latitude: the upper half-sphere's lifted by +half_height, the
  // lower one's by -half_height (two rings at the equator: the cylinder).
  constexpr int kLatitudes = 12;  // even
  std::vector<std::array<double, 2>> rings;
  const auto ring = [&](int k, double lift) {
    const double theta = kPi * k / kLatitudes;
    rings.push_back({radius * std::sin(theta), lift + radius * std::cos(theta)});
  };
  for (int k = 1; k <= kLatitudes / 2; ++k) ring(k, half_height);
  for (int k = kLatitudes / 2 + (half_height > 0.0 ? 0 : 1); k < kLatitudes; ++k) ring(k, -half_height);
  return revolve(radius + half_height, rings, -radius - half_height, pose);
}

TriMesh cylinder_surface(double radius, double half_height, const Pose& pose) {
  // The caps' rims twice (one ring per side of the edge keeps the cap flat).
  return revolve(half_height, {{radius, half_height}, {radius, -half_height}}, -half_height, pose);
}

TriMesh box_surface(const std::array<double, 3>& half_extents, const Pose& pose) {
  TriMesh mesh;
  for (int corner = 0; corner < 8; ++corner)  // bit k: + or - along axis k
    mesh.vertices.push_back(place(pose, {(corner & 1 ? 1 : -1) * half_extents[0], (corner & 2 ? 1 : -1) * half_extents[1],
                                         (corner & 4 ? 1 : -1) * half_extents[2]}));
  // Two triangles per face, outward.
  mesh.triangles = {{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}, {0, 1, 5}, {0, 5, 4},
                    {2, 6, 7}, {2, 7, 3}, {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};
  return mesh;
}

TriMesh plane_surface(double half_size, const Pose& pose) {
  TriMesh mesh;
  const double s = half_size;
  for (const auto& c : {std::array<double, 3>{-s, 0, -s}, {s, 0, -s}, {s, 0, s}, {-s, 0, s}})
    mesh.vertices.push_back(place(pose, c));
  mesh.triangles = {{0, 2, 1}, {0, 3, 2}};  // normal +y
  return mesh;
}

TriMesh posed_surface(const TriMesh& surface, const Pose& pose) {
  TriMesh mesh;
  mesh.triangles = surface.triangles;
  mesh.vertices.reserve(surface.vertices.size());
  for (const auto& v : surface.vertices) mesh.vertices.push_back(place(pose, v));
  return mesh;
}

std::vector<std::array<double, 3>> posed_points(std::span<const std::array<double, 3>> points, const Pose& pose) {
  std::vector<std::array<double, 3>> out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(place(pose, p));
  return out;
}

}  // namespace sinew
