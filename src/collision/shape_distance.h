// shape_distance.h — the analytic shapes' signed distances in double on the
// host, and the deepest point of a capsule against a shape: the shape-shape
// cells of the collision table (a tool's capsule against the colliders and
// the other tools, src/runtime/tool_contacts.cpp).
//
// The same shapes as the contact kernels (kernels/shared/contact_params.h,
// include/sinew/scene.h: plane, sphere, capsule, box, cylinder and the
// implicit CSG), written for double precision; the kernels stay the
// reference for particles, this serves rigid bodies.
// Hart, "Sphere tracing: a geometric method for the antialiased ray tracing
// of implicit surfaces", The Visual Computer 12, 1996 (signed distances and
// their CSG by min and max).
#pragma once

#include <array>

#include "math/vec3.h"
#include "sinew/scene.h"

namespace sinew::collision {

/// A signed distance [m] (negative inside) and the outward unit normal there.
struct ShapeDistance {
  double distance = 0.0;
  math::Vec3 normal{0.0, 1.0, 0.0};
};

/// The collider's shape (its dimensions and, if implicit, its nodes; its
/// own position and rotation are ignored) placed at `position` [m] and unit
/// quaternion `rotation`, measured at world point p [m]; the normal is in
/// the world frame. Normals where the direction is undefined follow the
/// kernels (a sphere's centre: +y, a capsule's axis: +x in its frame).
ShapeDistance shape_distance(const ColliderDesc& shape, const math::Vec3& position, const math::Quat& rotation,
                             const math::Vec3& p);

/// The deepest point of a capsule (segment a..b [m] swollen by `radius`)
/// against a shape: depth = radius - the least signed distance along the
/// segment (> 0: they overlap), the shape's normal there, and the capsule's
/// surface point deepest inside it (the segment point moved by -radius
/// along the normal). The least distance along the segment is found by
/// golden-section search, exact (to 1e-12 of the segment) for the convex
/// shapes, where the distance along a segment is convex; for an implicit
/// shape (not convex in general) the search starts from the best of 33
/// samples, so a dip narrower than 1/32 of the segment can be missed.
struct CapsuleContact {
  double depth = 0.0;
  math::Vec3 normal{0.0, 1.0, 0.0};
  math::Vec3 point{0.0, 0.0, 0.0};
};
CapsuleContact capsule_against(const ColliderDesc& shape, const math::Vec3& position, const math::Quat& rotation,
                               const math::Vec3& a, const math::Vec3& b, double radius);

/// The point of a triangle (a, b, c [m]) deepest in a shape, when it is
/// closer than `reach` [m] to it: its barycentric weights, the signed
/// distance there (negative inside), the shape's normal there and its
/// surface point under it. Frank-Wolfe iterations (Frank and Wolfe, Naval
/// Research Logistics Quarterly 3, 1956) with a golden-section line search,
/// from the best of the corners, edge midpoints and centroid: a descent
/// that may stop above the least distance (on random triangles near convex
/// shapes up to 7% of the triangle's longest edge,
/// tests/shape_distance_test.cpp), so the point is deep, not always the
/// deepest. Whether the triangle is within reach is decided for the convex
/// shapes to 1.4e-6 of its size: when the descent stops beyond it and its
/// lower bound (the Frank-Wolfe gap) does not exclude the reach, nested
/// golden-section searches (Kiefer, Proc. AMS 4, 1953) decide and give the
/// point. For implicit shapes (not convex) both are local searches. A triangle whose centroid
/// is farther than reach + its circumradius is skipped after one
/// evaluation (signed distances are 1-Lipschitz), as is one whose best of
/// those seven points is farther than reach + half its longest edge; one
/// whose deepest point is a corner (the distance rising from it along both
/// edges) returns just that corner's weights (1 at the corner), the other
/// fields unset: a corner is a vertex, which meets the shape on its own.
/// Returns false when the triangle stays beyond reach.
struct TriangleContact {
  std::array<double, 3> weights{};
  double distance = 0.0;
  math::Vec3 normal{0.0, 1.0, 0.0};
  math::Vec3 surface{0.0, 0.0, 0.0};
};
bool triangle_against(const ColliderDesc& shape, const math::Vec3& position, const math::Quat& rotation,
                      const math::Vec3& a, const math::Vec3& b, const math::Vec3& c, double reach,
                      TriangleContact& out);

}  // namespace sinew::collision
