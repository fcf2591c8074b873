// scene_checks.cpp — parameter checks for SceneDesc. Every message names the
// parameter path and the offending value so a user can fix the scene.
#include <cmath>
#include <sstream>
#include <string>

#include "sinew/scene.h"

namespace sinew {
namespace {

std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

Status positive(const std::string& name, double v) {
  if (!std::isfinite(v) || v <= 0.0) return Error(name + " must be finite and > 0 (got " + str(v) + ")");
  return {};
}

Status non_negative(const std::string& name, double v) {
  if (!std::isfinite(v) || v < 0.0) return Error(name + " must be finite and >= 0 (got " + str(v) + ")");
  return {};
}

Status check_pinned(const std::string& body, const std::vector<std::uint32_t>& pinned, std::size_t vertex_count) {
  for (std::size_t i = 0; i < pinned.size(); ++i)
    if (pinned[i] >= vertex_count)
      return Error(body + ".pinned[" + std::to_string(i) + "] = " + std::to_string(pinned[i]) +
                   " is not a vertex (the body has " + std::to_string(vertex_count) + ")");
  return {};
}

Status check_tet_body(const TetBodyDesc& b, const std::string& name) {
  if (Status s = check_tet_mesh(b.mesh, name + ".mesh"); !s) return s;
  if (Status s = positive(name + ".density", b.density); !s) return s;
  if (Status s = non_negative(name + ".distance_compliance", b.distance_compliance); !s) return s;
  if (Status s = non_negative(name + ".volume_compliance", b.volume_compliance); !s) return s;
  return check_pinned(name, b.pinned, b.mesh.vertices.size());
}

Status check_line_body(const LineBodyDesc& b, const std::string& name) {
  const std::size_t n = b.vertices.size();
  if (n == 0) return Error(name + ".vertices is empty");
  if (b.masses.size() != n)
    return Error(name + ".masses has " + std::to_string(b.masses.size()) + " entries for " + std::to_string(n) +
                 " vertices");
  for (std::size_t i = 0; i < n; ++i) {
    for (double c : b.vertices[i])
      if (!std::isfinite(c)) return Error(name + ".vertices[" + std::to_string(i) + "] is not finite");
    if (Status s = positive(name + ".masses[" + std::to_string(i) + "]", b.masses[i]); !s) return s;
  }
  for (std::size_t i = 0; i < b.segments.size(); ++i) {
    const auto [a, c] = b.segments[i];
    const std::string seg = name + ".segments[" + std::to_string(i) + "]";
    if (a >= n || c >= n)
      return Error(seg + " = (" + std::to_string(a) + ", " + std::to_string(c) + ") refers past the " +
                   std::to_string(n) + " vertices");
    const Vec3d& p = b.vertices[a];
    const Vec3d& q = b.vertices[c];
    const double len = std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    if (!(len > 0.0)) return Error(seg + " has zero rest length");
  }
  if (Status s = non_negative(name + ".compliance", b.compliance); !s) return s;
  return check_pinned(name, b.pinned, n);
}

}  // namespace

Status TetBodyDesc::set_elastic(double youngs_modulus, double poisson_ratio) {
  if (Status s = positive("youngs_modulus", youngs_modulus); !s) return s;
  if (!std::isfinite(poisson_ratio) || poisson_ratio <= -1.0 || poisson_ratio >= 0.5)
    return Error("poisson_ratio must be in (-1, 0.5) (got " + str(poisson_ratio) + ")");
  distance_compliance = 1.0 / youngs_modulus;
  volume_compliance = 3.0 * (1.0 - 2.0 * poisson_ratio) / youngs_modulus;
  return {};
}

Status check_scene(const SceneDesc& scene) {
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(scene.gravity[k]))
      return Error("gravity[" + std::to_string(k) + "] must be finite (got " + str(scene.gravity[k]) + ")");
  if (Status s = positive("solver.time_step", scene.solver.time_step); !s) return s;
  if (scene.solver.substeps < 1)
    return Error("solver.substeps must be >= 1 (got " + std::to_string(scene.solver.substeps) + ")");
  if (scene.solver.iterations < 1)
    return Error("solver.iterations must be >= 1 (got " + std::to_string(scene.solver.iterations) + ")");
  if (scene.tet_bodies.empty() && scene.line_bodies.empty()) return Error("the scene has no bodies");
  for (std::size_t i = 0; i < scene.tet_bodies.size(); ++i)
    if (Status s = check_tet_body(scene.tet_bodies[i], "tet_bodies[" + std::to_string(i) + "]"); !s) return s;
  for (std::size_t i = 0; i < scene.line_bodies.size(); ++i)
    if (Status s = check_line_body(scene.line_bodies[i], "line_bodies[" + std::to_string(i) + "]"); !s) return s;
  return {};
}

}  // namespace sinew
