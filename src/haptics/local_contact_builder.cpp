// src/haptics/local_contact_builder.cpp — the tissue near a capsule tool as
// a few compliant planes for the haptic thread's local contact model
// (steps and references in sinew/haptics/local_contact_builder.h; the
// flat-punch stiffness: K. L. Johnson, "Contact Mechanics", 1985, 3.8).
#include "sinew/haptics/local_contact_builder.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "math/vec3.h"
#include "sinew/mesh.h"

namespace sinew::haptics {
namespace {

using V3 = math::Vec3;

Error bad(const std::string& what) { return Error(ErrorCode::bad_parameter, "local contacts: " + what); }

// The closest point to p on the segment a-b.
V3 closest_on_segment(const V3& a, const V3& b, const V3& p) {
  const V3 ab = math::sub(b, a);
  const double len2 = math::dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(math::dot(math::sub(p, a), ab) / len2, 0.0, 1.0) : 0.0;
  return math::add(a, math::mul(ab, t));
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
      k = 2.0 * t.radius * e / (1.0 - nu * nu);
    }
    b.body_stiffness_.push_back(k);
    const std::uint32_t first = info.tet_body_first_particle[body];
    const TriMesh surface = extract_boundary_surface(d.mesh);
    // The boundary's vertices, each with its triangles (CSR).
    std::vector<std::uint32_t> slot(d.mesh.vertices.size(), UINT32_MAX);
    std::vector<std::uint32_t> counts;
    const std::size_t base = b.vertices_.size();
    for (const auto& tri : surface.triangles)
      for (std::uint32_t v : tri) {
        if (slot[v] == UINT32_MAX) {
          slot[v] = std::uint32_t(b.vertices_.size() - base);
          b.vertices_.push_back({first + v, std::uint32_t(body), 0, 0});
          counts.push_back(0);
        }
        ++counts[slot[v]];
      }
    const std::size_t tri_base = b.triangles_.size();
    for (const auto& tri : surface.triangles) b.triangles_.push_back({first + tri[0], first + tri[1], first + tri[2]});
    std::uint32_t offset = std::uint32_t(b.vertex_triangles_.size());
    for (std::size_t i = 0; i < counts.size(); ++i) {
      b.vertices_[base + i].first = offset;
      offset += counts[i];
    }
    b.vertex_triangles_.resize(offset);
    for (std::size_t ti = 0; ti < surface.triangles.size(); ++ti)
      for (std::uint32_t v : surface.triangles[ti]) {
        SurfaceVertex& sv = b.vertices_[base + slot[v]];
        b.vertex_triangles_[sv.first + sv.count++] = std::uint32_t(tri_base + ti);
      }
  }
  return b;
}

LocalContactModel LocalContactBuilder::build(const std::vector<float>& xyzw, const ToolState& tool) const {
  LocalContactModel model;
  model.tool_position = tool.position;
  const V3 axis = math::rotate(tool.rotation, V3{0.0, half_height_, 0.0});
  const V3 end_a = math::sub(tool.position, axis), end_b = math::add(tool.position, axis);
  const double reach = radius_ + settings_.margin;

  // 1. Candidates: boundary vertices within the margin, with their gaps.
  struct Candidate {
    double gap;
    V3 point, normal;
    std::uint32_t body;
  };
  std::vector<Candidate> candidates;
  for (const SurfaceVertex& v : vertices_) {
    if (4 * std::size_t(v.particle) + 3 >= xyzw.size()) continue;
    const V3 p = particle(xyzw, v.particle);
    const V3 d = math::sub(p, closest_on_segment(end_a, end_b, p));
    if (!(math::dot(d, d) < reach * reach)) continue;
    V3 n{0.0, 0.0, 0.0};  // area-weighted: the cross products' sum
    for (std::uint32_t k = 0; k < v.count; ++k) {
      const auto& t = triangles_[vertex_triangles_[v.first + k]];
      const V3 a = particle(xyzw, t[0]);
      n = math::add(n, math::cross(math::sub(particle(xyzw, t[1]), a), math::sub(particle(xyzw, t[2]), a)));
    }
    const double len = math::norm(n);
    if (!(len > 0.0) || !std::isfinite(len)) continue;
    n = math::mul(n, 1.0 / len);
    // The capsule's deepest point along -n: the axis end lower along n, minus r n.
    const V3& low = math::dot(n, end_a) < math::dot(n, end_b) ? end_a : end_b;
    candidates.push_back({math::dot(n, math::sub(low, p)) - radius_, p, n, v.body});
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
    out.stiffness = body_stiffness_[c.body];
    out.friction = friction_;
  }

  // 3. The frame's force over the touching planes: min |sum f_i n_i - F|^2,
  // f >= 0, by projected Gauss-Seidel (each n_i is unit: the diagonal is 1).
  // The nearest plane always qualifies: a frame's force is never dropped
  // for want of a plane close enough.
  const V3 f_total = tool.contact_force;
  std::array<double, kMaxLocalContacts> f{};
  const double touch = model.count > 0 ? std::max(settings_.touch_distance, model.contacts[0].gap) : 0.0;
  if (math::dot(f_total, f_total) > 0.0) {
    for (int sweep = 0; sweep < 50; ++sweep)
      for (std::uint64_t i = 0; i < model.count; ++i) {
        const LocalContact& c = model.contacts[i];
        if (!(c.gap <= touch)) continue;
        V3 r = f_total;
        for (std::uint64_t j = 0; j < model.count; ++j)
          if (j != i) r = math::sub(r, math::mul(model.contacts[j].normal, f[j]));
        f[i] = std::max(0.0, math::dot(r, c.normal));
      }
  }
  for (std::uint64_t i = 0; i < model.count; ++i) {
    LocalContact& c = model.contacts[i];
    c.force = f[i];
    // With a force: the gap that makes the plane push f_i at the frame's
    // pose. Without: the tissue starts at the tool's surface or beyond (a
    // plane the frame found no push on must not push at once).
    c.gap = f[i] > 0.0 ? -f[i] / c.stiffness : std::max(c.gap, 0.0);
  }
  return model;
}

}  // namespace sinew::haptics
