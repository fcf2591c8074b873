// tool_surface.h — what the examples write for their tools: a capsule's
// (or a ball's) triangle surface at its pose, and a rigid curve (a
// needle, a blade's edge) at its pose, as VTU files for ParaView next to
// the bodies'. The solver has no surface for an analytic tool; this is
// the display's version of the shape it collides with (sinew/scene.h).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "sinew/level_set.h"
#include "sinew/mesh.h"
#include "sinew/result.h"

namespace sinew::examples {

/// A unit quaternion [in] q (w, x, y, z) applied to [in] v.
std::array<double, 3> rotate(const std::array<double, 4>& q, const std::array<double, 3>& v);

/// A capsule's closed triangle surface (outward, counter-clockwise from
/// outside): the segment from (0, -half_height, 0) to (0, +half_height, 0)
/// [m] swollen by `radius` [m] (half_height 0: a ball), moved to [in] pose.
TriMesh capsule_surface(double radius, double half_height, const Pose& pose);

/// Writes capsule_surface(radius, half_height, pose) to [in] path. Errors:
/// the file's (write_vtu_triangles).
Status write_capsule_vtu(const std::filesystem::path& path, double radius, double half_height, const Pose& pose);

/// Writes to [in] path a box's surface: [in] half_extents [m] about its
/// centre, moved to [in] pose (e.g. a grasper's jaws).
Status write_box_vtu(const std::filesystem::path& path, const std::array<double, 3>& half_extents, const Pose& pose);

/// Writes to [in] path the polyline through [in] points (in the tool's
/// frame [m]) moved to [in] pose, one line cell per segment.
Status write_polyline_vtu(const std::filesystem::path& path, const std::vector<std::array<double, 3>>& points,
                          const Pose& pose);

}  // namespace sinew::examples
