// src/haptics/local_contact_builder.cpp — the tissue near a capsule tool as
// a few compliant planes for the haptic thread's local contact model
// (steps and references in sinew/haptics/local_contact_builder.h; the
// flat-punch stiffness: K. L. Johnson, "Contact Mechanics", 1985, 3.8).
#include "sinew/haptics/local_contact_builder.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "math/proximity_math.h"
#include "math/vec3.h"
#include "sinew/mesh.h"

namespace sinew::haptics {
namespace {

using V3 = math::Vec3;

Error bad(const std::string& what) { return Error(ErrorCode::bad_parameter, "local contacts: " + what); }

// The closest point to p on the segment a-b (proximity_math.h's parameter).
V3 closest_on_segment(const V3& a, const V3& b, const V3& p) {
  using V = kernels::vec4<double>;
  const double t = kernels::proximity::closest_on_segment(V{p[0], p[1], p[2], 0.0}, V{a[0], a[1], a[2], 0.0},
                                                          V{b[0], b[1], b[2], 0.0});
  return math::add(a, math::mul(math::sub(b, a), t));
}

V3 particle(const std::vector<float>& xyzw, std::uint32_t i) {
  return {double(xyzw[4 * std::size_t(i)]), double(xyzw[4 * std::size_t(i) + 1]), double(xyzw[4 * std::size_t(i) + 2])};
}

}  // namespace

Status check(const LocalContactSettings& s) {
  if (!(s.margin > 0.0) || !std::isfinite(s.margin))
    return bad("margin must be finite and > 0 [m] (got " + std::to_string(s.margin) + ")");
  if (!(s.stiffness >= 0.0) || !std::isfinite(s.stiffness))
    return bad("stiffness must be finite and >= 0 [N/m] (0: estimated from each body's E and nu; got " +
               std::to_string(s.stiffness) + ")");
  if (!(s.touch_distance >= 0.0) || !std::isfinite(s.touch_distance))
    return bad("touch_distance must be finite and >= 0 [m] (got " + std::to_string(s.touch_distance) + ")");
  if (!(s.max_normal_angle > 0.0) || !(s.max_normal_angle <= 3.14159265358979323846))
    return bad("max_normal_angle must be in (0, pi] [rad] (got " + std::to_string(s.max_normal_angle) + ")");
  if (s.max_contacts < 1 || s.max_contacts > kMaxLocalContacts)
    return bad("max_contacts must be in 1.." + std::to_string(kMaxLocalContacts) + " (got " +
               std::to_string(s.max_contacts) + ")");
  return {};
}

Result<LocalContactBuilder> LocalContactBuilder::create(const SceneDesc& scene, const SceneInfo& info,
                                                        std::size_t tool, const LocalContactSettings& settings) {
  if (auto s = check(settings); !s) return s.error();
  if (tool >= scene.tools.size())
    return bad("tool " + std::to_string(tool) + " is past the scene's " + std::to_string(scene.tools.size()) +
               " tools");
  const ToolDesc& t = scene.tools[tool];
  if (t.shape != ToolShape::capsule) return bad("tools[" + std::to_string(tool) + "] is not a capsule");
  if (scene.tet_bodies.empty()) return bad("the scene has no tet body to touch");
  if (info.tet_body_first_particle.size() != scene.tet_bodies.size())
    return bad("the SceneInfo is not the scene's (" + std::to_string(info.tet_body_first_particle.size()) +
               " tet bodies, the scene has " + std::to_string(scene.tet_bodies.size()) + ")");
  LocalContactBuilder b;
  b.tool_ = tool;
  b.settings_ = settings;
  b.radius_ = t.radius;
  b.half_height_ = t.half_height;
  b.friction_ = t.dynamic_friction;
  for (std::size_t body = 0; body < scene.tet_bodies.size(); ++body) {
    const TetBodyDesc& d = scene.tet_bodies[body];
    double k = settings.stiffness;
    if (k == 0.0) {
      const double e = d.youngs_modulus, nu = d.poisson_ratio;
      if (!(e > 0.0) || !(nu > -1.0 && nu < 0.5))
        return bad("tet_bodies[" + std::to_string(body) +
                   "] has no youngs_modulus/poisson_ratio to estimate its contact stiffness from; give "
                   "LocalContactSettings::stiffness [N/m]");
      k = 2.0 * t.radius * e / (1.0 - nu * nu);  // the flat punch of radius r: a full contact
      b.body_modulus_.push_back(e / (1.0 - nu * nu));
    } else {
      b.body_modulus_.push_back(0.0);
    }
    b.body_stiffness_.push_back(k);
    const std::uint32_t first = info.tet_body_first_particle[body];
    // The boundary's vertices, each once.
    std::vector<char> seen(d.mesh.vertices.size(), 0);
    for (const auto& tri : extract_boundary_surface(d.mesh).triangles)
      for (std::uint32_t v : tri)
        if (!seen[v]) {
          seen[v] = 1;
          b.vertices_.push_back({first + v, std::uint32_t(body)});
        }
  }
  return b;
}

// Hertz: a sphere of radius R pressed delta into a half-space of plane
// strain modulus E* = E / (1 - nu^2) carries F = 4/3 E* sqrt(R) delta^(3/2)
// over a contact of radius a = sqrt(R delta); its stiffness dF/ddelta is
// 2 E* a (Johnson 1985, 4.2), which reaches the flat punch's 2 E* R when
// a = R. The depth follows from the frame's force; a plane not yet touched
// gets the stiffness at delta = R / 10 (the contact's start, not zero).
double LocalContactBuilder::stiffness(std::uint32_t body, double force) const {
  const double e_star = body_modulus_[body];
  if (e_star == 0.0) return body_stiffness_[body];  // LocalContactSettings::stiffness
  const double r = radius_;
  const double delta = std::max(std::pow(3.0 * force / (4.0 * e_star * std::sqrt(r)), 2.0 / 3.0), 0.1 * r);
  return 2.0 * e_star * std::min(std::sqrt(r * delta), r);
}

// The tissue's stiffness as the frames show it: the least-squares slope of
// the force against the tool's depth along it over the last kStiffnessFrames
// frames in contact, once the depths span at least r / 100 and the slope is
// positive. The stiffness used is the greatest such slope of the contact so
// far, or Hertz's estimate (stiffness()) where that is more. Never lowered
// within a contact, for two reasons: a softer plane at the same force
// stores more energy (f^2 / 2k), which the renderer would have to take back
// from the hand (LocalContactRenderer), and the frames' force stops growing
// while the tool still sinks in (the solver settling, the tissue creeping):
// a slope that is the tissue's relaxation, not its stiffness.
double LocalContactBuilder::region_stiffness(std::uint32_t body, double force, const std::array<double, 3>& position,
                                             const std::array<double, 3>& force_vector) {
  if (settings_.stiffness > 0.0) return settings_.stiffness;
  history_[history_next_ % kStiffnessFrames] = {position[0], position[1], position[2], force};
  ++history_next_;
  const std::size_t n = std::min<std::size_t>(history_next_, kStiffnessFrames);
  const V3 dir = math::mul(force_vector, 1.0 / force);
  double mean_s = 0.0, mean_f = 0.0, lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < n; ++i) {
    const double depth = -math::dot(dir, V3{history_[i][0], history_[i][1], history_[i][2]});
    mean_s += depth / double(n);
    mean_f += history_[i][3] / double(n);
    lo = std::min(lo, depth);
    hi = std::max(hi, depth);
  }
  if (n >= 3 && hi - lo >= 0.01 * radius_) {
    double sf = 0.0, ss = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double depth = -math::dot(dir, V3{history_[i][0], history_[i][1], history_[i][2]}) - mean_s;
      sf += depth * (history_[i][3] - mean_f);
      ss += depth * depth;
    }
    if (sf > 0.0) measured_ = std::max(measured_, sf / ss);
  }
  return std::max(measured_, stiffness(body, force));
}

LocalContactModel LocalContactBuilder::build(const std::vector<float>& xyzw, const ToolState& tool) {
  LocalContactModel model;
  model.tool_position = tool.position;
  const V3 axis = math::rotate(tool.rotation, V3{0.0, half_height_, 0.0});
  const V3 end_a = math::sub(tool.position, axis), end_b = math::add(tool.position, axis);
  const double reach = radius_ + settings_.margin;

  // 1. Candidates: boundary vertices within the margin, with their gaps and planes.
  struct Candidate {
    double gap;
    V3 point, normal;
    std::uint32_t body;
  };
  std::vector<Candidate> candidates;
  for (const SurfaceVertex& v : vertices_) {
    if (4 * std::size_t(v.particle) + 3 >= xyzw.size()) continue;
    const V3 p = particle(xyzw, v.particle);
    const V3 d = math::sub(closest_on_segment(end_a, end_b, p), p);  // from the vertex to the tool's axis
    const double dist = math::norm(d);
    if (!(dist < reach) || !(dist > 0.0)) continue;
    // The plane through the vertex facing the tool's axis, the way the
    // solver's contact pushes the vertex; the gap is the vertex's distance
    // from the tool's surface.
    candidates.push_back({dist - radius_, p, math::mul(d, 1.0 / dist), v.body});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) { return a.gap < b.gap; });

  // 2. Planes, nearest first, one per direction.
  const double cos_max = std::cos(settings_.max_normal_angle);
  for (const Candidate& c : candidates) {
    if (model.count >= settings_.max_contacts) break;
    bool covered = false;
    for (std::uint64_t i = 0; i < model.count && !covered; ++i)
      covered = math::dot(model.contacts[i].normal, c.normal) > cos_max;
    if (covered) continue;
    LocalContact& out = model.contacts[model.count++];
    out.point = c.point;
    out.normal = c.normal;
    out.gap = c.gap;
    out.stiffness = stiffness(c.body, 0.0);
    out.body = c.body;
    out.friction = friction_;
  }

  // 3. The frame's force. The planes within touch distance (and the
  // nearest, however far: a frame's force is never dropped for want of a
  // plane) are where the tool touched; the tissue there answered with one
  // force, so they become one plane along it, at the depth |F| / k that
  // makes the plane push |F| at the frame's pose. The others are where the
  // tool may touch next; they start at its surface or beyond (a plane the
  // frame found no push on must not push at once).
  const V3 f_total = tool.contact_force;
  const double f = math::norm(f_total);
  LocalContactModel merged;
  merged.tool_position = model.tool_position;
  if (f > 0.0 && model.count > 0) {
    const double touch = std::max(settings_.touch_distance, model.contacts[0].gap);
    LocalContact region = model.contacts[0];
    region.normal = math::mul(f_total, 1.0 / f);
    region.force = f;
    region.stiffness = region_stiffness(std::uint32_t(region.body), f, tool.position, f_total);
    region.gap = -f / region.stiffness;
    merged.contacts[merged.count++] = region;
    for (std::uint64_t i = 1; i < model.count; ++i)
      if (model.contacts[i].gap > touch) merged.contacts[merged.count++] = model.contacts[i];
  } else {
    merged.count = model.count;
    merged.contacts = model.contacts;
    measured_ = 0.0;  // out of contact: the next contact is measured afresh
    history_next_ = 0;
  }
  for (std::uint64_t i = 0; i < merged.count; ++i)
    if (!(merged.contacts[i].force > 0.0)) merged.contacts[i].gap = std::max(merged.contacts[i].gap, 0.0);
  model = merged;
  return model;
}

}  // namespace sinew::haptics
