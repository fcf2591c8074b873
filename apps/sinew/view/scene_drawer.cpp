// scene_drawer.cpp — see scene_drawer.h.
#include "view/scene_drawer.h"

#include <algorithm>
#include <cmath>

namespace sinew::view {
namespace {

// One colour per body, in turn: tissue pinks and reds, then others.
const V3 kBodyColours[] = {{0.86f, 0.45f, 0.45f}, {0.93f, 0.68f, 0.55f}, {0.75f, 0.35f, 0.55f},
                           {0.55f, 0.70f, 0.85f}, {0.65f, 0.80f, 0.50f}, {0.90f, 0.80f, 0.45f}};
const V3 kToolColour{0.72f, 0.74f, 0.80f}, kDrivenToolColour{0.95f, 0.80f, 0.25f};
const V3 kColliderColour{0.50f, 0.55f, 0.60f}, kThreadColour{0.15f, 0.25f, 0.75f};
const V3 kNeedleColour{0.85f, 0.85f, 0.90f}, kFluidColour{0.70f, 0.05f, 0.08f};
const V3 kHandleColour{0.25f, 0.90f, 0.95f}, kForceColour{1.0f, 0.25f, 0.15f}, kContactColour{0.2f, 0.85f, 0.3f};

V3 body_colour(std::size_t i) { return kBodyColours[i % std::size(kBodyColours)]; }

// A shape's mesh in its own frame (the pose and size are in the model matrix for the unit ones).
std::optional<GpuMesh> collider_mesh(const ColliderDesc& c, const TriMesh* surface) {
  switch (c.shape) {
    case ColliderShape::capsule: return GpuMesh(capsule(c.radius, c.half_height));
    case ColliderShape::cylinder: return GpuMesh(cylinder(c.radius, c.half_height));
    case ColliderShape::level_set:
      if (surface && !surface->triangles.empty()) return GpuMesh(surface_mesh(*surface));
      return std::nullopt;
    case ColliderShape::plane:
    case ColliderShape::sphere:
    case ColliderShape::box:
    case ColliderShape::implicit: break;  // unit meshes scaled (implicit shapes are not drawn)
  }
  return std::nullopt;
}

}  // namespace

SceneDrawer::SceneDrawer(const SceneDesc& scene)
    : scene_(scene), sphere_(unit_sphere()), box_(unit_box()), square_(unit_square()), arrow_(unit_arrow()) {
  for (std::size_t i = 0; i < scene.tet_bodies.size(); ++i) tets_.push_back({GpuMesh{}, {}, body_colour(i)});
  for (std::size_t i = 0; i < scene.tri_bodies.size(); ++i)
    tris_.push_back({GpuMesh{}, {}, body_colour(scene.tet_bodies.size() + i)});
  for (std::size_t i = 0; i < scene.line_bodies.size(); ++i) {
    lines_.push_back({GpuMesh{}, {}, kThreadColour});
    lines_.back().surface.set_primitive(Primitive::lines);
  }
  for (const ToolDesc& t : scene.tools) {
    if (t.shape == ToolShape::capsule) tool_meshes_.emplace_back(GpuMesh(capsule(t.radius, t.half_height)));
    else if (t.level_set) tool_meshes_.emplace_back(GpuMesh(surface_mesh(t.level_set->surface())));
    else tool_meshes_.emplace_back(std::nullopt);
  }
  for (const ColliderDesc& c : scene.colliders) collider_meshes_.push_back(collider_mesh(c, nullptr));
  for (const NeedleDesc& n : scene.needles) {
    // A tube a fiftieth of the curve's length thick (a needle's size is not in its description).
    double curve_length = 0.0;
    for (std::size_t k = 1; k < n.curve.size(); ++k) curve_length += length(V3(n.curve[k]) - V3(n.curve[k - 1]));
    needle_meshes_.emplace_back(tube(n.curve, std::max(0.01 * curve_length, 1e-5)));
  }
  fluid_.set_primitive(Primitive::points);
  spring_.set_primitive(Primitive::lines);
}

void SceneDrawer::bounds(const ViewSnapshot& snap, V3& lo, V3& hi) {
  lo = {1e30f, 1e30f, 1e30f}, hi = {-1e30f, -1e30f, -1e30f};
  const auto grow = [&](V3 p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  };
  for (std::size_t p = 0; p + 3 < snap.positions.size(); p += 4)
    grow({snap.positions[p], snap.positions[p + 1], snap.positions[p + 2]});
  for (const ToolState& t : snap.tools) grow(V3(t.position));
  for (std::size_t p = 0; p + 2 < snap.fluid.size(); p += 3) grow({snap.fluid[p], snap.fluid[p + 1], snap.fluid[p + 2]});
  if (lo.x > hi.x) lo = {-0.05f, -0.05f, -0.05f}, hi = {0.05f, 0.05f, 0.05f};
}

void SceneDrawer::upload_elements(const ViewSnapshot& snap) {
  std::vector<std::uint32_t> indices;
  const auto upload = [&](Body& body, const auto& elements) {
    indices.clear();
    for (const auto& e : elements) indices.insert(indices.end(), e.begin(), e.end());
    body.surface.set_indices(indices);
  };
  for (std::size_t b = 0; b < tets_.size() && b < snap.tet_surfaces.size(); ++b) upload(tets_[b], snap.tet_surfaces[b]);
  for (std::size_t b = 0; b < tris_.size() && b < snap.tri_surfaces.size(); ++b) upload(tris_[b], snap.tri_surfaces[b]);
  for (std::size_t b = 0; b < lines_.size() && b < snap.line_segments.size(); ++b)
    upload(lines_[b], snap.line_segments[b]);
  if (snap.collider_surfaces && snap.collider_surfaces != level_set_surfaces_) {
    level_set_surfaces_ = snap.collider_surfaces;
    for (std::size_t c = 0; c < scene_.colliders.size() && c < level_set_surfaces_->size(); ++c)
      if (scene_.colliders[c].shape == ColliderShape::level_set)
        collider_meshes_[c] = collider_mesh(scene_.colliders[c], &(*level_set_surfaces_)[c]);
  }
  elements_generation_ = snap.generation;
  elements_version_ = snap.shape_version;
}

void SceneDrawer::update(const ViewSnapshot& snap, const DrawOptions& options) {
  if (snap.generation != elements_generation_ || snap.shape_version != elements_version_) upload_elements(snap);
  V3 lo, hi;
  bounds(snap, lo, hi);
  extent_ = std::max(length(hi - lo), 1e-3f);
  centre_ = (lo + hi) * 0.5f;
  arrow_scale_ = 0.1f * extent_;
  // The speed scale: the fastest particle, at least 1 cm/s (a still scene stays blue).
  float top = 0.01f;
  for (float s : snap.speeds) top = std::max(top, s);
  const auto update_body = [&](Body& body, std::uint32_t first, std::size_t count,
                               std::span<const std::array<std::uint32_t, 3>> triangles) {
    if (4 * (first + count) > snap.positions.size()) return;
    const std::span<const float> x = std::span<const float>(snap.positions).subspan(4 * first, 4 * count);
    colours_.clear();
    if (options.colour_by_speed && first + count <= snap.speeds.size())
      for (std::size_t p = 0; p < count; ++p) {
        const V3 c = speed_colour(snap.speeds[first + p], top);
        colours_.insert(colours_.end(), {c.x, c.y, c.z});
      }
    body_vertices(x, triangles, colours_, body.cpu);
    body.surface.set_vertices(body.cpu.vertices);
  };
  for (std::size_t b = 0; b < tets_.size() && b < snap.tet_first.size() && b < snap.tet_surfaces.size(); ++b)
    update_body(tets_[b], snap.tet_first[b], scene_.tet_bodies[b].mesh.vertices.size(), snap.tet_surfaces[b]);
  for (std::size_t b = 0; b < tris_.size() && b < snap.tri_first.size() && b < snap.tri_surfaces.size(); ++b)
    update_body(tris_[b], snap.tri_first[b], scene_.tri_bodies[b].mesh.vertices.size(), snap.tri_surfaces[b]);
  for (std::size_t b = 0; b < lines_.size() && b < snap.line_first.size(); ++b)
    update_body(lines_[b], snap.line_first[b], scene_.line_bodies[b].vertices.size(), {});
  if (options.fluid && !snap.fluid.empty()) {
    MeshData points;
    for (std::size_t p = 0; p + 2 < snap.fluid.size(); p += 3) {
      points.add({snap.fluid[p], snap.fluid[p + 1], snap.fluid[p + 2]}, {0, 1, 0});
      points.indices.push_back(static_cast<std::uint32_t>(p / 3));
    }
    fluid_.set_vertices(points.vertices);
    fluid_.set_indices(points.indices);
  }
}

void SceneDrawer::draw_arrow(Renderer& r, V3 from, V3 vector, V3 colour) {
  if (length(vector) < 1e-6f) return;
  r.draw(arrow_, along_matrix(from, vector, std::max(length(vector), 0.02f * extent_)), {.colour = colour});
}

void SceneDrawer::draw(Renderer& r, const ViewSnapshot& snap, const DrawOptions& options, const HandleView& handle) {
  const M4 identity;
  for (Body& b : tets_) r.draw(b.surface, identity, {.colour = b.colour, .vertex_colours = options.colour_by_speed});
  for (Body& b : tris_) r.draw(b.surface, identity, {.colour = b.colour, .vertex_colours = options.colour_by_speed});
  for (Body& b : lines_) r.draw(b.surface, identity, {.colour = b.colour, .lit = false});
  for (std::size_t t = 0; t < snap.tools.size() && t < tool_meshes_.size(); ++t) {
    if (!tool_meshes_[t]) continue;
    const ToolState& s = snap.tools[t];
    r.draw(*tool_meshes_[t], pose_matrix(s.position, s.rotation),
           {.colour = static_cast<int>(t) == handle.tool ? kDrivenToolColour : kToolColour});
    if (options.contacts) draw_arrow(r, V3(s.position), V3(s.contact_force) * arrow_scale_, kContactColour);
  }
  if (options.colliders)
    for (std::size_t c = 0; c < scene_.colliders.size() && c < snap.colliders.size(); ++c) {
      const ColliderDesc& d = scene_.colliders[c];
      const Pose& p = snap.colliders[c];
      const DrawStyle style{.colour = kColliderColour};
      switch (d.shape) {
        case ColliderShape::sphere: {
          const auto rr = static_cast<float>(d.radius);
          r.draw(sphere_, pose_matrix(p.position, p.rotation, {rr, rr, rr}), style);
          break;
        }
        case ColliderShape::box:
          r.draw(box_, pose_matrix(p.position, p.rotation, V3(d.half_extents)), style);
          break;
        case ColliderShape::plane: {
          // Big enough to reach under the whole scene from wherever its origin is.
          const float half = extent_ + length(centre_ - V3(p.position));
          r.draw(square_, pose_matrix(p.position, p.rotation, {half, 1, half}), {.colour = kColliderColour, .alpha = 0.55f});
          break;
        }
        default:
          if (collider_meshes_[c]) r.draw(*collider_meshes_[c], pose_matrix(p.position, p.rotation), style);
      }
    }
  for (std::size_t n = 0; n < snap.needles.size() && n < needle_meshes_.size(); ++n) {
    const NeedleState& s = snap.needles[n];
    r.draw(needle_meshes_[n], pose_matrix(s.position, s.rotation), {.colour = kNeedleColour});
    if (options.contacts) draw_arrow(r, V3(s.position), V3(s.reaction_force) * arrow_scale_, kContactColour);
  }
  if (options.fluid && !snap.fluid.empty()) r.draw(fluid_, identity, {.colour = kFluidColour, .lit = false, .point_size = 3.0f});
  if (handle.tool >= 0 && static_cast<std::size_t>(handle.tool) < snap.tools.size()) {
    const V3 tool = V3(snap.tools[static_cast<std::size_t>(handle.tool)].position);
    const float knob = 0.012f * extent_;
    r.draw(sphere_, pose_matrix(handle.position.to_double(), {1, 0, 0, 0}, {knob, knob, knob}),
           {.colour = kHandleColour, .alpha = 0.8f, .on_top = true});
    MeshData spring;
    spring.add(handle.position, {0, 1, 0});
    spring.add(tool, {0, 1, 0});
    spring.indices = {0, 1};
    spring_.set_vertices(spring.vertices);
    spring_.set_indices(spring.indices);
    r.draw(spring_, identity, {.colour = kHandleColour, .lit = false, .on_top = true});
    draw_arrow(r, handle.position, handle.force * arrow_scale_, kForceColour);
  }
}

}  // namespace sinew::view
