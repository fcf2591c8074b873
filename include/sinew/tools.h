// sinew/tools.h — what moves the scene from outside (SceneDesc::tools,
// colliders, targets; runtime/rigid_tool.h, tool_contacts.h), reached
// through Simulation::tools(): rigid tools driven by forces, colliders
// and kinematic targets driven by poses, and what the tissue does back.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "sinew/ids.h"
#include "sinew/level_set.h"
#include "sinew/result.h"

namespace sinew {

class Simulation;

/// A tool's state at the end of the last frame.
struct ToolState {
  std::array<double, 3> position{};          ///< [m]
  std::array<double, 4> rotation{1, 0, 0, 0};  ///< unit quaternion (w, x, y, z)
  std::array<double, 3> velocity{};          ///< [m/s]
  std::array<double, 3> angular_velocity{};  ///< world frame [rad/s]
  std::array<double, 3> contact_force{};     ///< what the tissue pushed the tool with, frame average [N]
  std::array<double, 3> contact_torque{};    ///< about the tool's centre [N m]
  /// A level-set tool's penalty from the colliders and the other tools
  /// (or a capsule tool's from level-set tools), at the start of the last
  /// frame, which it drove (ToolDesc) [N], about its centre [N m].
  ///@{
  std::array<double, 3> penalty_force{};
  std::array<double, 3> penalty_torque{};
  ///@}
  std::uint32_t penalty_points = 0;  ///< a level-set tool's surface points inside other shapes then
  double penalty_depth = 0.0;        ///< the deepest one's depth [m]
  /// What a tool's trocar (ToolDesc::trocar) pushed it with over the last
  /// frame [N], at the pivot, sideways to the shaft, and its moment about
  /// the tool's centre [N m]; zero without a trocar.
  ///@{
  std::array<double, 3> trocar_force{};
  std::array<double, 3> trocar_torque{};
  ///@}
  /// A cutting tool's (ToolDesc::cuts) removed volume of its collider in
  /// the last frame [m^3], measured on the grid (CutReport::removed_volume).
  double cut_volume = 0.0;
};

/// A handle on a Simulation's tools, colliders and targets; a view of the
/// Simulation, valid while it is neither destroyed nor moved. A null id,
/// or one of another Simulation, is an error.
class Tools {
 public:
  /// Ids of the scene's tools, colliders and targets by their index in
  /// SceneDesc. Errors: an index past them.
  ///@{
  [[nodiscard]] Result<ToolId> tool(std::size_t index) const;
  [[nodiscard]] Result<ColliderId> collider(std::size_t index) const;
  [[nodiscard]] Result<TargetId> target(std::size_t index) const;
  ///@}

  /// Force [N] and torque [N m] (world frame, about the tool's centre)
  /// acting on `tool` during the next frame (then reset to zero); calls
  /// before one step add up.
  Status apply_force(ToolId tool, const std::array<double, 3>& force, const std::array<double, 3>& torque);
  /// `tool`'s pose, velocities and the last frame's contact reaction (ToolState).
  [[nodiscard]] Result<ToolState> state(ToolId tool) const;
  /// Moves `collider` to this pose [m, unit quaternion (w, x, y, z)] by the
  /// end of the next frame; its substeps interpolate the motion.
  Status set_pose(ColliderId collider, const std::array<double, 3>& position, const std::array<double, 4>& rotation);
  /// Cuts level-set `collider` (ColliderShape::level_set, built with its
  /// whole inside stored): LevelSet::cut with the tool's poses in the
  /// collider's frame. The collider's grid changes (and every LevelSet
  /// sharing it), and so does the device's copy, by the changed leaves,
  /// before this returns: the next step collides with the cut shape.
  /// Errors: not a level-set collider; LevelSet::cut's.
  Result<CutReport> cut(ColliderId collider, const CutterShape& shape, const Pose& from, const Pose& to);
  /// Moves kinematic `target` to `position` [m] by the end of the next frame.
  Status set_position(TargetId target, const std::array<double, 3>& position);

  /// A view of `sim` (Simulation::tools() makes one).
  explicit Tools(Simulation* sim) : sim_(sim) {}

 private:
  Simulation* sim_;
};

}  // namespace sinew
