// sinew/haptics/local_contact_builder.h — the physics thread's side of the
// local contact model (local_contacts.h): after each frame, the tissue
// surface near a capsule tool as at most kMaxLocalContacts planes, each with
// the force the frame found on it and the tissue's stiffness there.
//
//   auto builder = LocalContactBuilder::create(scene, sim.info(), tool, {});
//   bridge.set_local_contacts(std::move(*builder));   // publish() then fills HapticSnapshot::local_contacts
//
// How a frame's model is made (build()):
//  1. candidates: the tet bodies' boundary vertices (their surfaces at
//     creation) within `margin` of the capsule's surface;
//  2. planes: each candidate's plane faces the tool's axis (its normal is
//     the direction from the vertex to the axis's nearest point, the way
//     the solver's contact pushes the vertex) and its gap is the vertex's
//     distance from the tool's surface; taken nearest first, a candidate
//     whose normal lies within `max_normal_angle` of a plane already kept
//     adds nothing (that plane stands for it), else it makes a new plane,
//     up to `max_contacts`;
//  3. forces: the planes within `touch_distance` of the tool (and the
//     nearest, however far) are where it touched; they become one plane
//     along the frame's contact force F on the tool
//     (ToolState::contact_force) with the gap -|F| / k, so the model
//     reproduces the frame's force at the frame's pose. (A corner the tool
//     presses into is then one plane along the resultant.) The other planes
//     are where the tool may touch next, each with a gap of at least 0;
//  4. stiffness: `stiffness` when > 0; else the greater of two
//     estimates, never lowered within a contact (a softer plane at the same
//     force would store more energy, and a force that stops growing while
//     the tool sinks in is the tissue relaxing, not softening):
//     - measured: the greatest least-squares slope of the frames' force
//       against the tool's depth along it over the last 10 frames in
//       contact (when their depths span at least r / 100);
//     - Hertz's for a sphere of the capsule's radius r on an elastic
//       half-space (K. L. Johnson, "Contact Mechanics", 1985, 4.2): 2 E* a
//       with E* = E / (1 - nu^2) from the body's youngs_modulus and
//       poisson_ratio and the contact radius a = sqrt(r delta), the depth
//       delta following from the force F = 4/3 E* sqrt(r) delta^(3/2), at
//       least r / 10 (the only estimate for a plane not yet touched), at
//       most the flat punch's 2 E* r (a = r; section 3.8).
// The positions are read with Simulation::read_positions (a host copy; on
// a GPU backend, a read-back per frame).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sinew/haptics/local_contacts.h"
#include "sinew/result.h"
#include "sinew/scene.h"
#include "sinew/simulation.h"
#include "sinew/tools.h"

namespace sinew::haptics {

/// What the builder publishes (docs/haptics.md).
struct LocalContactSettings {
  double margin = 0.005;          ///< tissue within this distance of the tool's surface is published [m], > 0
  double stiffness = 0.0;         ///< every contact's [N/m], >= 0; 0: estimated (step 4 above)
  double touch_distance = 5e-4;   ///< planes this close to the tool may carry the frame's force [m], >= 0
  double max_normal_angle = 0.5;  ///< candidates whose normals differ less share a plane [rad], in (0, pi]
  std::uint32_t max_contacts = static_cast<std::uint32_t>(kMaxLocalContacts);  ///< 1..kMaxLocalContacts
};
/// Errors name the bad parameter.
Status check(const LocalContactSettings& settings);

/// Builds a tool's LocalContactModel from a frame's positions. Not thread-safe.
class LocalContactBuilder {
 public:
  /// [in] scene: the scene the Simulation was created from (its tet bodies'
  /// meshes and materials, the tool's shape); [in] info: the Simulation's
  /// (each body's first particle); [in] tool: index into scene.tools.
  /// Errors: a bad setting, a tool index past the tools, a tool that is not
  /// a capsule, a tet body with no youngs_modulus while settings.stiffness
  /// is 0 (naming the body), a scene with no tet body.
  static Result<LocalContactBuilder> create(const SceneDesc& scene, const SceneInfo& info, std::size_t tool,
                                            const LocalContactSettings& settings = {});

  /// [in] xyzw: every particle's position (Simulation::read_positions);
  /// [in] tool: the tool's state at the frame's end. Returns the model.
  /// Keeps the stiffness measured over the frames (4. above): call it once
  /// per frame, in order.
  [[nodiscard]] LocalContactModel build(const std::vector<float>& xyzw, const ToolState& tool);

  [[nodiscard]] std::size_t tool() const { return tool_; }
  [[nodiscard]] const LocalContactSettings& settings() const { return settings_; }
  /// The stiffness each tet body's contacts get at most [N/m] (a full contact: the flat punch).
  [[nodiscard]] const std::vector<double>& body_stiffness() const { return body_stiffness_; }

 private:
  struct SurfaceVertex {
    std::uint32_t particle = 0;  // global particle index
    std::uint32_t body = 0;      // tet body
  };
  std::size_t tool_ = 0;
  LocalContactSettings settings_;
  double radius_ = 0.0, half_height_ = 0.0, friction_ = 0.0;
  std::vector<double> body_stiffness_;  // the most: the flat punch's, or LocalContactSettings::stiffness
  std::vector<double> body_modulus_;     // E / (1 - nu^2) [Pa]; 0: the fixed LocalContactSettings::stiffness
  [[nodiscard]] double stiffness(std::uint32_t body, double force) const;
  double region_stiffness(std::uint32_t body, double force, const std::array<double, 3>& position,
                          const std::array<double, 3>& force_vector);
  // The stiffness measured over the frames in contact (0: none yet), from
  // the last frames' tool positions and contact forces (x, y, z, |F|).
  static constexpr std::size_t kStiffnessFrames = 10;
  double measured_ = 0.0;
  std::array<std::array<double, 4>, kStiffnessFrames> history_{};
  std::size_t history_next_ = 0;
  std::vector<SurfaceVertex> vertices_;  // the tet bodies' boundary vertices
};

}  // namespace sinew::haptics
