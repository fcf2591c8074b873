// tool_penalty.h — a level-set tool against the colliders and the other
// tools (the shape-shape cells of the collision table for ToolShape::
// level_set): a penalty on the tool's surface points, added to the force
// and torque that drive the tool through the coming frame (rigid_tool.h).
//
// Voxmap-pointshell: W. A. McNeely, K. D. Puterbaugh, J. J. Troy, "Six
// degree-of-freedom haptic rendering using voxel sampling", SIGGRAPH 1999.
// The tool is a shell of points, each standing for an area; a point at
// depth d > 0 inside the other shape (its signed distance, negative
// inside, collision/shape_distance.h: exact for the analytic shapes,
// trilinear for a level set) is pushed along that shape's outward normal
// by area * max(0, k d + c d'), d' its speed into the shape (relative to a
// tool, colliders taken at rest), the opposite going to the other tool.
// Summed, that is a pressure growing with depth: a sphere of radius R
// pressed delta into a flat face feels k pi R delta^2 (the cap's
// projected area times the mean depth, to first order in delta / R).
//
// Why a penalty and not the capsules' positional contacts: a burr must
// sink into bone to cut it, and a haptic device renders a stiffness, not a
// constraint. The force is explicit (computed at the frame's start pose),
// so it is stable only while sqrt(k_contact / M) dt < 2 (scene.h, ToolDesc).
#pragma once

#include <vector>

#include "runtime/rigid_tool.h"
#include "runtime/tool_contacts.h"
#include "sinew/scene.h"

namespace sinew {

/// For every level-set tool: its points against every collider (at its
/// pose in `colliders`) and against every other tool's shape
/// (`tool_shapes[j]`, a capsule or level set, at that tool's pose); a pair
/// of level-set tools is met once, the lower index's points against the
/// higher's shape. Adds the sums to the tools' `force` and `torque` (about
/// their centres) and records them in penalty_force, penalty_torque,
/// penalty_points and penalty_depth. Capsule tools against colliders and
/// each other are left to resolve_tool_contacts.
void add_tool_penalties(std::vector<ToolBody>& tools, const std::vector<ColliderDesc>& tool_shapes,
                        const std::vector<PosedShape>& colliders);

}  // namespace sinew
