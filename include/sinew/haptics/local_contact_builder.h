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
//  2. planes: each candidate's plane has its vertex normal (area-weighted
//     over its surface triangles at the frame's positions) and its gap is
//     the distance from the plane to the capsule's deepest point along the
//     normal; taken nearest first, a candidate whose normal lies within
//     `max_normal_angle` of a plane already kept adds nothing (that plane
//     stands for it), else it makes a new plane, up to `max_contacts`;
//  3. forces: the frame's contact force on the tool (ToolState::contact_force)
//     is split over the planes within `touch_distance` (and the nearest
//     plane, however far) as the non-negative
//     least-squares fit sum_i f_i n_i ~ F; a plane carrying f_i gets the
//     gap -f_i / k_i (the model then reproduces the frame's force at the
//     frame's pose), one carrying none a gap of at least 0;
//  4. stiffness: `stiffness` when > 0, else the body's flat-punch stiffness
//     k = 2 r E / (1 - nu^2) (a rigid circular punch of the capsule's radius
//     r on an elastic half-space; K. L. Johnson, "Contact Mechanics", 1985,
//     section 3.8), from the body's youngs_modulus and poisson_ratio.
// The positions are read with Simulation::read_positions (a host copy; on
// a GPU backend, a read-back per frame).
#pragma once

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
  double stiffness = 0.0;         ///< every contact's [N/m], > 0; 0: each body's flat-punch estimate from E, nu
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
  [[nodiscard]] LocalContactModel build(const std::vector<float>& xyzw, const ToolState& tool) const;

  [[nodiscard]] std::size_t tool() const { return tool_; }
  [[nodiscard]] const LocalContactSettings& settings() const { return settings_; }
  /// The stiffness each tet body's contacts get [N/m].
  [[nodiscard]] const std::vector<double>& body_stiffness() const { return body_stiffness_; }

 private:
  struct SurfaceVertex {
    std::uint32_t particle = 0;  // global particle index
    std::uint32_t body = 0;      // tet body
    std::uint32_t first = 0, count = 0;  // its triangles in vertex_triangles_
  };
  std::size_t tool_ = 0;
  LocalContactSettings settings_;
  double radius_ = 0.0, half_height_ = 0.0, friction_ = 0.0;
  std::vector<double> body_stiffness_;
  std::vector<SurfaceVertex> vertices_;
  std::vector<std::array<std::uint32_t, 3>> triangles_;  // global particle indices
  std::vector<std::uint32_t> vertex_triangles_;          // per vertex, its triangles (CSR)
};

}  // namespace sinew::haptics
