// body_attachment_checks.cpp — SceneDesc::body_attachments' parameters
// (BodyAttachmentDesc): each point's body and vertices exist, its weights
// are finite and sum to 1, the two points share no particle, the compliance
// and the breaking force are in range. Part of check_scene.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "compiler/scene_compiler.h"
#include "sinew/scene.h"

namespace sinew {

namespace {

std::string str(double v) { return number_text(v); }

const char* kind_name(BodyKind k) {
  switch (k) {
    case BodyKind::tet: return "tet_bodies";
    case BodyKind::tri: return "tri_bodies";
    case BodyKind::line: return "line_bodies";
  }
  return "?";
}

Status check_point(const SceneDesc& scene, const BarycentricPoint& p, const std::string& name) {
  const std::size_t n = vertex_count(scene, VertexRef{p.body_kind, p.body, 0});
  if (n == 0)
    return Error(ErrorCode::bad_parameter, name + ".body = " + std::to_string(p.body) + ": " + kind_name(p.body_kind) +
                                               "[" + std::to_string(p.body) + "] does not exist");
  if (p.vertices.empty() || p.vertices.size() > 4)
    return Error(ErrorCode::bad_parameter, name + ".vertices has " + std::to_string(p.vertices.size()) +
                                               " vertices; a barycentric point has 1 to 4");
  if (p.weights.size() != p.vertices.size())
    return Error(ErrorCode::bad_parameter, name + ".weights has " + std::to_string(p.weights.size()) +
                                               " weights for " + std::to_string(p.vertices.size()) + " vertices");
  double sum = 0.0;
  for (std::size_t k = 0; k < p.vertices.size(); ++k) {
    const std::string at = "[" + std::to_string(k) + "]";
    if (p.vertices[k] >= n)
      return Error(ErrorCode::bad_parameter, name + ".vertices" + at + " = " + std::to_string(p.vertices[k]) +
                                                 " is not a vertex (the body has " + std::to_string(n) + ")");
    if (std::find(p.vertices.begin(), p.vertices.begin() + static_cast<std::ptrdiff_t>(k), p.vertices[k]) !=
        p.vertices.begin() + static_cast<std::ptrdiff_t>(k))
      return Error(ErrorCode::bad_parameter,
                   name + ".vertices" + at + " = " + std::to_string(p.vertices[k]) + " appears twice in the point");
    if (!std::isfinite(p.weights[k]))
      return Error(ErrorCode::bad_parameter, name + ".weights" + at + " must be finite (got " + str(p.weights[k]) + ")");
    sum += p.weights[k];
  }
  if (!(std::abs(sum - 1.0) <= 1e-6))
    return Error(ErrorCode::bad_parameter, name + ".weights sum to " + str(sum) + "; they must sum to 1 (within 1e-6)");
  return {};
}

Status check_body_attachment(const SceneDesc& scene, const BodyAttachmentDesc& a, const std::string& name) {
  if (Status s = check_point(scene, a.a, name + ".a"); !s) return s;
  if (Status s = check_point(scene, a.b, name + ".b"); !s) return s;
  if (a.a.body_kind == a.b.body_kind && a.a.body == a.b.body)
    for (std::uint32_t v : a.a.vertices)
      if (std::find(a.b.vertices.begin(), a.b.vertices.end(), v) != a.b.vertices.end())
        return Error(ErrorCode::bad_parameter, name + ": vertex " + std::to_string(v) +
                                                   " is in both points (a point cannot be attached to itself)");
  if (!std::isfinite(a.compliance) || a.compliance < 0.0)
    return Error(ErrorCode::bad_parameter,
                 name + ".compliance must be finite and >= 0 [m/N] (got " + str(a.compliance) + ")");
  // Infinity: never breaks. Otherwise a positive float32 (the device's).
  if (!(a.break_force > 0.0) ||
      (std::isfinite(a.break_force) && !(std::isfinite(static_cast<float>(a.break_force)) &&
                                         static_cast<float>(a.break_force) >= std::numeric_limits<float>::min())))
    return Error(ErrorCode::bad_parameter, name + ".break_force must be > 0 [N] and a normal float32, or infinity "
                                                  "(never breaks) (got " + str(a.break_force) + ")");
  // 0, or a finite float32 (the device's) that is not rounded to zero.
  if (!(a.rest_length >= 0.0) || !std::isfinite(static_cast<float>(a.rest_length)) ||
      (a.rest_length > 0.0 && !(static_cast<float>(a.rest_length) >= std::numeric_limits<float>::min())))
    return Error(ErrorCode::bad_parameter, name + ".rest_length must be >= 0 [m] and 0 or a normal float32 (got " +
                                               str(a.rest_length) + ")");
  return {};
}

}  // namespace

Status check_body_attachments(const SceneDesc& scene) {
  for (std::size_t i = 0; i < scene.body_attachments.size(); ++i)
    if (Status s = check_body_attachment(scene, scene.body_attachments[i],
                                         "body_attachments[" + std::to_string(i) + "]");
        !s)
      return s;
  return {};
}

}  // namespace sinew
