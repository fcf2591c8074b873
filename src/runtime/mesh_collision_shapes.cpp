// mesh_collision_shapes.cpp — the contacts of the meshes' triangles and
// the threads' segments with the colliders' and the rigid tools' shapes
// (shape_faces, see mesh_collision.h): where a primitive's deepest point is
// inside a shape or on an edge, so that a sharp or thin shape pressed
// between a coarse mesh's or thread's vertices still meets it. A tool's are
// found where it starts the frame and hold the face beyond the plane that
// touches it where it ends; their reaction goes back to the tool
// (add_tool_reactions).
#include "runtime/mesh_collision.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>


#include "collision/shape_distance.h"
#include "hooks/hooks_internal.h"

namespace sinew {
namespace {

using collision::Contact;

// A capsule's ends (the segment its radius swells) at a pose.
std::array<math::Vec3, 2> capsule_ends(const PosedShape& s) {
  const math::Vec3 axis = math::rotate(s.rotation, math::Vec3{0.0, s.shape->half_height, 0.0});
  return {math::sub(s.position, axis), math::add(s.position, axis)};
}

// A point of a shape's frame [m] at the shape's pose.
math::Vec3 carried(const PosedShape& s, const math::Vec3& local) {
  return math::add(s.position, math::rotate(s.rotation, local));
}

}  // namespace

void MeshCollision::shape_faces(std::span<const PosedShape> shapes, std::span<const PosedShape> ends, double common) {
  const double dt = time_step_;
  const std::size_t triangles = triangle_body_.size();
  const bool tools = !ends.empty();
  for (std::size_t index = 0; index < shapes.size(); ++index) {
    const PosedShape& shape = shapes[index];
    const std::uint32_t which = tools ? static_cast<std::uint32_t>(index) : Contact::kNoShape;
    // A tool: how far any point of its capsule moves in the frame (its
    // segment's ends move linearly between the poses, and so bound it), and
    // the offset of the plane that touches it where it ends, on the face's
    // side (n points from the tool to the face): thickness - the largest
    // n . p over the capsule.
    // A level-set tool: the bound from its box's corners (a rigid motion's
    // displacement is affine in the point, so its length is convex and
    // largest at a corner), and the plane through the contact's surface
    // point carried along with the tool (its surface there, to first order).
    const bool level_set = tools && shape.shape->shape == ColliderShape::level_set;
    double moved = 0.0;
    std::array<math::Vec3, 2> first{}, last{};
    if (level_set) {
      const std::array<double, 6> box = shape.shape->level_set->bounds();
      for (int corner = 0; corner < 8; ++corner) {
        const math::Vec3 local{box[corner & 1 ? 3 : 0], box[corner & 2 ? 4 : 1], box[corner & 4 ? 5 : 2]};
        moved = std::max(moved, math::norm(math::sub(carried(ends[index], local), carried(shape, local))));
      }
    } else if (tools) {
      first = capsule_ends(shape);
      last = capsule_ends(ends[index]);
      for (int k = 0; k < 2; ++k) moved = std::max(moved, math::norm(math::sub(last[k], first[k])));
    }
    const auto offset_at = [&](const std::array<math::Vec3, 2>& ends_at, const math::Vec3& n) {
      return desc_.thickness - (std::max(math::dot(n, ends_at[0]), math::dot(n, ends_at[1])) + shape.shape->radius);
    };
    // The contact plane's offset at the frame's end and its motion over the
    // frame, for a tool (c.offset, c.motion) given its surface point at the
    // start, or for a collider (at rest over the frame).
    const auto plane = [&](Contact& c, const math::Vec3& normal, const math::Vec3& surface) {
      if (level_set) {
        const math::Vec3 local = math::rotate(math::conj(shape.rotation), math::sub(surface, shape.position));
        c.offset = float(desc_.thickness - math::dot(normal, carried(ends[index], local)));
        c.motion = float(desc_.thickness - math::dot(normal, surface)) - c.offset;
      } else if (tools) {
        c.offset = float(offset_at(last, normal));
        c.motion = float(offset_at(first, normal)) - c.offset;
      } else {
        c.offset = float(desc_.thickness - math::dot(normal, surface));
      }
    };
    if (shape.shape->shape == ColliderShape::plane) continue;
    // Triangles in parallel (one evaluation each for most), joined in
    // triangle order so the contacts do not depend on the threads.
    found_.assign(triangles, Contact{});
    face_hit_.assign(triangles, 0);
    hooks::parallel_for(triangles, 256, [&](std::size_t begin, std::size_t end) {
      for (std::size_t t = begin; t < end; ++t) {
        const std::uint32_t* v = &triangles_[3 * t];
        if (!movable_[v[0]] && !movable_[v[1]] && !movable_[v[2]]) continue;
        math::Vec3 corner[3];
        float speed = 0.0f;
        for (int k = 0; k < 3; ++k) {
          for (int a = 0; a < 3; ++a) corner[k][a] = positions_[4 * std::size_t{v[k]} + a];
          speed = std::max(speed, speed_[v[k]]);
        }
        collision::TriangleContact hit;
        if (!collision::triangle_against(*shape.shape, shape.position, shape.rotation, corner[0], corner[1],
                                         corner[2], common + 2.0 * dt * speed + moved, hit))
          continue;
        if (std::max({hit.weights[0], hit.weights[1], hit.weights[2]}) > 1.0 - 1e-6) continue;  // a corner
        Contact& c = found_[t];
        c.kind = Contact::Kind::shape_face;
        c.v = {v[0], v[0], v[1], v[2]};
        c.w = {0.0f, float(hit.weights[0]), float(hit.weights[1]), float(hit.weights[2])};
        c.normal = {float(hit.normal[0]), float(hit.normal[1]), float(hit.normal[2])};
        c.distance = float(hit.distance);
        plane(c, hit.normal, hit.surface);
        c.shape = which;
        face_hit_[t] = 1;
      }
    });
    for (std::size_t t = 0; t < triangles; ++t)
      if (face_hit_[t]) all_.push_back(found_[t]);
    // Segments (threads): the point deepest in the shape along each, by
    // golden-section search (collision::capsule_against, radius 0), kept
    // between its ends, on particles (a, a, b, b) with c = (0, 1 - s, 0, s).
    for (std::size_t e = 0; e < segment_body_.size(); ++e) {
      const std::uint32_t* v = &segments_[2 * e];
      if (!movable_[v[0]] && !movable_[v[1]]) continue;
      math::Vec3 end[2];
      for (int k = 0; k < 2; ++k)
        for (int a = 0; a < 3; ++a) end[k][a] = positions_[4 * std::size_t{v[k]} + a];
      const double reach = common + 2.0 * dt * std::max(speed_[v[0]], speed_[v[1]]) + moved;
      const math::Vec3 ab = math::sub(end[1], end[0]);
      const double length2 = math::dot(ab, ab);
      if (!(length2 > 0.0)) continue;
      const collision::CapsuleContact hit = collision::capsule_against(*shape.shape, shape.position, shape.rotation,
                                                                      end[0], end[1], 0.0);
      if (-hit.depth > reach) continue;
      const double along = math::dot(math::sub(hit.point, end[0]), ab) / length2;
      if (along < 1e-6 || along > 1.0 - 1e-6) continue;  // an end: the vertex's own contact
      Contact c;
      c.kind = Contact::Kind::shape_face;
      c.v = {v[0], v[0], v[1], v[1]};
      c.w = {0.0f, float(1.0 - along), 0.0f, float(along)};
      c.normal = {float(hit.normal[0]), float(hit.normal[1]), float(hit.normal[2])};
      c.distance = float(-hit.depth);
      // The shape's surface under the segment's deepest point.
      plane(c, hit.normal, math::add(hit.point, math::mul(hit.normal, hit.depth)));
      c.shape = which;
      all_.push_back(c);
    }
  }
}

}  // namespace sinew
