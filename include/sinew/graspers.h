// sinew/graspers.h — a running scene's graspers (SceneDesc::graspers;
// runtime/graspers.h), reached through Simulation::graspers(): jaws that
// close on tissue, move it, and let it go.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sinew/ids.h"
#include "sinew/level_set.h"
#include "sinew/result.h"

namespace sinew {

class Simulation;

/// A surface point a grasper holds: sum weights[k] x[particles[k]].
struct HeldPoint {
  std::array<std::uint32_t, 3> particles{};  ///< the triangle's particles (user order)
  std::array<double, 3> weights{};           ///< barycentric, each in [0, 1], summing to 1
};

/// A handle on a Simulation's graspers; a view of the Simulation, valid
/// while it is neither destroyed nor moved. A null id, or one of another
/// Simulation, is an error.
class Graspers {
 public:
  /// The id of grasper `index` (SceneDesc::graspers). Errors: an index past them.
  [[nodiscard]] Result<GrasperId> grasper(std::size_t index) const;
  [[nodiscard]] std::size_t count() const;  ///< the scene's graspers

  /// Closes `grasper` at `pose` [m, unit quaternion (w, x, y, z)]: every
  /// movable particle (of any body) inside the jaws, the box of
  /// `half_extents` [m] (> 0) centred on the pose in its frame, is held
  /// where it is now, at a point fixed in the grasper's frame. So is every
  /// surface triangle (a tet body's boundary face, a tri body's triangle)
  /// that crosses the box with none of its vertices inside it: at its
  /// point nearest the pose's position, through its barycentric weights
  /// (a coarse mesh grasped between its vertices; held_points lists them).
  /// Of such triangles sharing a vertex only the one whose point is
  /// nearest is held. Returns the held particles (the user's order, as
  /// read_positions). Errors: a bad pose or box; closed already; more
  /// particles than its capacity, or points than its point_capacity
  /// (capacity_exceeded, nothing held).
  Result<std::vector<std::uint32_t>> close(GrasperId grasper, const Pose& pose, const std::array<double, 3>& half_extents);
  /// Moves `grasper` to `pose` by the end of the next frame (its held
  /// particles' targets move across the frame's substeps).
  Status move(GrasperId grasper, const Pose& pose);
  /// Opens `grasper`: what it held is free from the next frame on. Returns the released particles.
  Result<std::vector<std::uint32_t>> open(GrasperId grasper);
  /// The surface points `grasper` holds (none while open).
  [[nodiscard]] Result<std::vector<HeldPoint>> held_points(GrasperId grasper) const;

  /// A view of `sim` (Simulation::graspers() makes one).
  explicit Graspers(Simulation* sim) : sim_(sim) {}

 private:
  Simulation* sim_;
};

}  // namespace sinew
