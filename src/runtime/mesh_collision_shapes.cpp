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

// The part of a capsule's axis (ends `axis`) over triangle (a, b, c): the
// axis projected onto the triangle's plane and clipped to the triangle
// (Sutherland and Hodgman's clipping, CACM 17(1), 1974, of a segment
// against the three edges' half-planes). False when it misses the
// triangle or the triangle has no area; else its two ends in `span` (one
// point twice when the axis stands across the plane).
bool axis_span(const std::array<math::Vec3, 2>& axis, const math::Vec3 (&corner)[3], math::Vec3 (&span)[2]) {
  const math::Vec3 normal = math::cross(math::sub(corner[1], corner[0]), math::sub(corner[2], corner[0]));
  const double area2 = math::dot(normal, normal);
  if (!(area2 > 0.0)) return false;
  math::Vec3 p[2];
  for (int k = 0; k < 2; ++k)
    p[k] = math::sub(axis[k], math::mul(normal, math::dot(normal, math::sub(axis[k], corner[0])) / area2));
  const math::Vec3 along = math::sub(p[1], p[0]);
  double t0 = 0.0, t1 = 1.0;
  for (int e = 0; e < 3; ++e) {
    const math::Vec3& from = corner[e];
    const math::Vec3 inward = math::cross(normal, math::sub(corner[(e + 1) % 3], from));  // towards the third corner
    const double at0 = math::dot(inward, math::sub(p[0], from)), rate = math::dot(inward, along);
    if (rate == 0.0) {
      if (at0 < 0.0) return false;
    } else if (rate > 0.0) {
      t0 = std::max(t0, -at0 / rate);
    } else {
      t1 = std::min(t1, -at0 / rate);
    }
  }
  if (t0 > t1) return false;
  span[0] = math::add(p[0], math::mul(along, t0));
  span[1] = math::add(p[0], math::mul(along, t1));
  return true;
}

// The barycentric weights of a point in triangle (a, b, c)'s plane.
std::array<double, 3> barycentric(const math::Vec3& p, const math::Vec3 (&corner)[3]) {
  const math::Vec3 e0 = math::sub(corner[1], corner[0]), e1 = math::sub(corner[2], corner[0]);
  const math::Vec3 d = math::sub(p, corner[0]);
  const double d00 = math::dot(e0, e0), d01 = math::dot(e0, e1), d11 = math::dot(e1, e1);
  const double d20 = math::dot(d, e0), d21 = math::dot(d, e1);
  const double den = d00 * d11 - d01 * d01;
  const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  return {1.0 - v - w, v, w};
}

// The point of segment (a, b) nearest to p.
math::Vec3 nearest_on_segment(const math::Vec3& a, const math::Vec3& b, const math::Vec3& p) {
  const math::Vec3 ab = math::sub(b, a);
  const double l2 = math::dot(ab, ab);
  const double t = l2 > 0.0 ? std::clamp(math::dot(math::sub(p, a), ab) / l2, 0.0, 1.0) : 0.0;
  return math::add(a, math::mul(ab, t));
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
    // A capsule's manifold (MeshCollisionDesc::face_manifold): its axis
    // where the contacts are found (a tool's start, a collider's end pose).
    const bool manifold = desc_.face_manifold && !level_set && shape.shape->shape == ColliderShape::capsule;
    const std::array<math::Vec3, 2> axis = tools ? first : capsule_ends(shape);
    // Triangles in parallel (one evaluation each for most), joined in
    // triangle order so the contacts do not depend on the threads.
    found_.assign(kManifold * triangles, Contact{});
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
        const double reach = common + 2.0 * dt * speed + moved;
        if (!collision::triangle_against(*shape.shape, shape.position, shape.rotation, corner[0], corner[1],
                                         corner[2], reach, hit))
          continue;
        if (std::max({hit.weights[0], hit.weights[1], hit.weights[2]}) > 1.0 - 1e-6) continue;  // a corner
        Contact& c = found_[kManifold * t];
        c.kind = Contact::Kind::shape_face;
        c.v = {v[0], v[0], v[1], v[2]};
        c.w = {0.0f, float(hit.weights[0]), float(hit.weights[1]), float(hit.weights[2])};
        c.normal = {float(hit.normal[0]), float(hit.normal[1]), float(hit.normal[2])};
        c.distance = float(hit.distance);
        plane(c, hit.normal, hit.surface);
        c.shape = which;
        std::uint8_t made = 1;
        // A capsule lying along the face: the two ends of its axis's span
        // over the triangle too, each against the capsule's surface nearest
        // to it (as the deepest point is), so the face is held along the
        // whole line it touches instead of pivoting on one point. Kept
        // where within reach, facing as the deepest point's contact does
        // (within 30 degrees), inside the face or on an edge, and apart from
        // the deepest point and each other (a tenth of the longest edge).
        math::Vec3 span[2];
        if (manifold && axis_span(axis, corner, span)) {
          math::Vec3 deepest{0.0, 0.0, 0.0};
          double longest = 0.0;
          for (int k = 0; k < 3; ++k) {
            deepest = math::add(deepest, math::mul(corner[k], hit.weights[k]));
            longest = std::max(longest, math::norm(math::sub(corner[(k + 1) % 3], corner[k])));
          }
          math::Vec3 kept[kManifold] = {deepest, deepest, deepest};
          for (const math::Vec3& p : span) {
            bool near = false;
            for (int k = 0; k < made; ++k) near |= math::norm(math::sub(p, kept[k])) < 0.1 * longest;
            if (near) continue;
            const std::array<double, 3> w = barycentric(p, corner);
            if (std::min({w[0], w[1], w[2]}) < -1e-6 || std::max({w[0], w[1], w[2]}) > 1.0 - 1e-6) continue;
            const math::Vec3 q = nearest_on_segment(axis[0], axis[1], p);
            const double length = math::norm(math::sub(p, q));
            if (!(length > 0.0)) continue;
            const math::Vec3 n = math::mul(math::sub(p, q), 1.0 / length);
            if (math::dot(n, hit.normal) < 0.866 || length - shape.shape->radius > reach) continue;
            Contact& m = found_[kManifold * t + made];
            m = c;
            m.w = {0.0f, float(std::max(w[0], 0.0)), float(std::max(w[1], 0.0)), float(std::max(w[2], 0.0))};
            m.normal = {float(n[0]), float(n[1]), float(n[2])};
            m.distance = float(length - shape.shape->radius);
            plane(m, n, math::add(q, math::mul(n, shape.shape->radius)));
            kept[made++] = p;
          }
        }
        face_hit_[t] = made;
      }
    });
    for (std::size_t t = 0; t < triangles; ++t)
      for (std::uint8_t k = 0; k < face_hit_[t]; ++k) all_.push_back(found_[kManifold * t + k]);
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
