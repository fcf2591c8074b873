// penalty_contact.cpp — a tool's surface points against a solid level set
// (issue 14, part 3): the force and torque a penalty on each point's depth
// gives, after McNeely, Neff and Troy, "Six degree-of-freedom haptic
// rendering using voxel sampling", SIGGRAPH 1999 (the voxmap-pointshell:
// points on the tool, a distance field for the other body). See
// sinew/level_set.h.
#include <cmath>
#include <string>

#include "math/vec3.h"
#include "sinew/level_set.h"

namespace sinew {

using math::Vec3;

SurfacePoints surface_points(const TriMesh& mesh) {
  SurfacePoints out;
  out.points.assign(mesh.vertices.begin(), mesh.vertices.end());
  out.areas.assign(mesh.vertices.size(), 0.0);
  for (const auto& t : mesh.triangles) {
    if (t[0] >= mesh.vertices.size() || t[1] >= mesh.vertices.size() || t[2] >= mesh.vertices.size()) continue;
    const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    const double third = math::norm(math::cross(math::sub(b, a), math::sub(c, a))) / 6.0;
    for (std::uint32_t v : t) out.areas[v] += third;
  }
  return out;
}

Result<PenaltyContact> penalty_contact(const LevelSet& solid, const SurfacePoints& tool, const Pose& tool_pose,
                                       double stiffness) {
  constexpr const char* call = "penalty_contact";
  if (!(stiffness > 0.0) || !std::isfinite(stiffness))
    return Error(ErrorCode::bad_parameter, std::string(call) + ": stiffness must be finite and > 0 [N/m^3]");
  for (double c : tool_pose.position)
    if (!std::isfinite(c)) return Error(ErrorCode::bad_parameter, std::string(call) + ": the tool's position is not finite");
  const math::Quat q = tool_pose.rotation;
  if (!(std::abs(math::qdot(q, q) - 1.0) <= 1e-6))
    return Error(ErrorCode::bad_parameter, std::string(call) + ": the tool's rotation is not a unit quaternion");
  if (tool.points.size() != tool.areas.size())
    return Error(ErrorCode::bad_parameter, std::string(call) + ": " + std::to_string(tool.points.size()) +
                                               " points but " + std::to_string(tool.areas.size()) + " areas");
  PenaltyContact out;
  Vec3 force{0.0, 0.0, 0.0}, torque{0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < tool.points.size(); ++i) {
    const Vec3 arm = math::rotate(q, tool.points[i]);
    const Vec3 p = math::add(tool_pose.position, arm);
    const double depth = -solid.value(p);
    if (!(depth > 0.0)) continue;
    const Vec3 g = solid.gradient(p);
    const double n = math::norm(g);
    ++out.touching;
    out.deepest = std::max(out.deepest, depth);
    if (!(n > 0.0)) continue;  // beyond the solid's band: no direction
    const Vec3 f = math::mul(g, stiffness * depth * tool.areas[i] / n);
    force = math::add(force, f);
    torque = math::add(torque, math::cross(arm, f));
  }
  out.force = force;
  out.torque = torque;
  return out;
}

}  // namespace sinew
