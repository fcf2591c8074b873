// sinew/needles.h — a running scene's needles and sutures
// (SceneDesc::needles; runtime/sutures.h), reached through
// Simulation::needles(): driving a needle and reading its punctures and
// the force to render.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sinew/ids.h"
#include "sinew/result.h"
#include "sinew/scene.h"

namespace sinew {

class Simulation;

/// A tissue point held on a needle or its thread (NeedleDesc).
struct Puncture {
  BodyKind body_kind = BodyKind::tet;  ///< tet (its boundary surface) or tri
  std::uint32_t body = 0;              ///< index among the scene's bodies of that kind
  /// The triangle: of extract_boundary_surface(mesh) for a tet body, of
  /// mesh.triangles for a tri body.
  std::uint32_t triangle = 0;
  std::array<double, 3> weights{};  ///< barycentric weights of the point on it
  bool exit = false;       ///< made leaving a tet body (else entering a surface)
  bool on_thread = false;  ///< the needle has passed it: it holds the thread
  std::uint32_t thread_segment = 0;  ///< on_thread: the thread's segment through it
  double thread_s = 0.0;             ///< on_thread: where along that segment, in [0, 1]
};

/// A needle at the end of the last frame.
struct NeedleState {
  std::array<double, 3> position{};            ///< [m]
  std::array<double, 4> rotation{1, 0, 0, 0};  ///< unit quaternion (w, x, y, z)
  std::array<double, 3> velocity{};            ///< over the last frame [m/s]
  std::array<double, 3> angular_velocity{};    ///< over the last frame, world frame [rad/s]
  /// What the tissue and the thread did to the needle, averaged over the
  /// last frame: the force [N] of its tip's push, its punctures and its
  /// tie to the thread, and their torque about its origin [N m] (world
  /// frame). Kinematic needles report it too: it is the force to render
  /// on a haptic device.
  std::array<double, 3> reaction_force{};
  std::array<double, 3> reaction_torque{};  ///< see reaction_force
  std::vector<Puncture> punctures;             ///< in the order they were made
  bool pushing = false;    ///< the tip pushes a surface it has not punctured
  double tip_force = 0.0;  ///< that push, along the tip, averaged over the frame [N]
  /// Since the start: surface triangles the tip met that it could not
  /// puncture because they were degenerate (no area) or inverted (their
  /// tet turned inside out), and frames in which the push passed
  /// puncture_force at more than max_puncture_angle.
  std::uint32_t refused_degenerate = 0;
  std::uint32_t refused_inverted = 0;  ///< see refused_degenerate
  std::uint32_t refused_angle = 0;     ///< see refused_degenerate
};

/// A handle on a Simulation's needles; a view of the Simulation, valid
/// while it is neither destroyed nor moved. A null id, or one of another
/// Simulation, is an error.
class Needles {
 public:
  /// The id of needle `index` (SceneDesc::needles). Errors: an index past them.
  [[nodiscard]] Result<NeedleId> needle(std::size_t index) const;
  [[nodiscard]] std::size_t count() const;  ///< the scene's needles
  /// Moves kinematic `needle` to this pose [m, unit quaternion (w, x, y,
  /// z)] by the end of the next frame (NeedleDesc); its substeps
  /// interpolate each of its points linearly. Errors: a force-driven needle.
  Status set_pose(NeedleId needle, const std::array<double, 3>& position, const std::array<double, 4>& rotation);
  /// Force [N] and torque [N m] (world frame, about the needle's origin,
  /// its centre of mass) acting on force-driven `needle` during the next
  /// frame (then reset to zero); calls before one step add up. Errors: a
  /// kinematic needle.
  Status apply_force(NeedleId needle, const std::array<double, 3>& force, const std::array<double, 3>& torque);
  /// `needle`'s pose, velocity, reaction, punctures and refusals (NeedleState).
  [[nodiscard]] Result<NeedleState> state(NeedleId needle) const;

  /// A view of `sim` (Simulation::needles() makes one).
  explicit Needles(Simulation* sim) : sim_(sim) {}

 private:
  Simulation* sim_;
};

}  // namespace sinew
