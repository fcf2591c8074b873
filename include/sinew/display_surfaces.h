// display_surfaces.h — triangle surfaces of the analytic shapes (capsules,
// balls, boxes, cylinders, planes) at a pose, for drawing tools and
// colliders (SceneOutput, the examples). The solver has no surface for an
// analytic shape; these are the display's version of the shape it
// collides with (sinew/scene.h), closed and wound outward.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "sinew/level_set.h"
#include "sinew/mesh.h"

namespace sinew {

/// A unit quaternion [in] q (w, x, y, z) applied to [in] v.
std::array<double, 3> rotate(const std::array<double, 4>& q, const std::array<double, 3>& v);

/// A capsule's closed surface (counter-clockwise from outside): the segment
/// from (0, -half_height, 0) to (0, +half_height, 0) [m] swollen by
/// `radius` [m] (half_height 0: a ball), moved to [in] pose.
TriMesh capsule_surface(double radius, double half_height, const Pose& pose);

/// A box's closed surface: [in] half_extents [m] about its centre, at [in] pose.
TriMesh box_surface(const std::array<double, 3>& half_extents, const Pose& pose);

/// A cylinder's closed surface: `radius` [m] about the y axis, flat caps at
/// y = +-half_height [m], at [in] pose.
TriMesh cylinder_surface(double radius, double half_height, const Pose& pose);

/// A square of side 2 half_size [m] in the plane y = 0, facing +y, at [in] pose.
TriMesh plane_surface(double half_size, const Pose& pose);

/// [in] surface (in a shape's own frame) moved to [in] pose.
TriMesh posed_surface(const TriMesh& surface, const Pose& pose);

/// [in] points (in a tool's frame [m]) moved to [in] pose.
std::vector<std::array<double, 3>> posed_points(std::span<const std::array<double, 3>> points, const Pose& pose);

}  // namespace sinew
