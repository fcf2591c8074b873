// sinew/fluid_coupling.h — two-way coupling of a fluid (sinew/fluid.h) with
// tissue (sinew/simulation.h): the tissue's surfaces are
// sampled with boundary particles that follow them (Akinci et al., TOG
// 31(4), 2012), so tissue holds fluid in a cavity; the fluid pushes back on
// those particles and that push, spread to the surfaces' vertices by the
// samples' barycentric weights, drives the tissue.
//
// One coupled frame (step()): the tissue's positions and velocities are
// read and carried to the boundary particles; the fluid takes the frame's
// steps (SolverSettings::time_step / FluidSettings::time_step of them);
// the impulse J the fluid gave each sample over them becomes a constant
// force J / frame on the vertices (Simulation::set_particle_forces) for
// the tissue's frame, which then runs. So the tissue gains in its frame
// exactly the momentum the fluid lost to it (up to float rounding): total
// momentum is conserved, but for what lands on pinned or kinematic
// vertices (they take no force: the fixed world takes it). The coupling is explicit, one frame apart: it is
// stable while the fluid's push moves the tissue's surface by much less
// than a spacing per frame.
//
// Cost: per frame the host reads the tissue's positions and velocities (32
// bytes per particle), writes the boundary (32 bytes per boundary
// particle) and reads the impulses (16 per boundary particle).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "sinew/fluid.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace sinew {

/// A surface of a tissue body that holds fluid: triangles over the body's
/// vertices (e.g. extract_boundary_surface of its TetMesh, or the part of
/// it that faces the fluid), with rest positions [m].
struct CoupledSurface {
  TriMesh surface;  ///< the triangles over the body's vertices, with rest positions [m]
  /// The Simulation particle of the surface's vertex 0 (SceneInfo::
  /// tet_body_first_particle or tri_body_first_particle of the body).
  std::uint32_t first_particle = 0;
};

/// Deprecated: a scene's fluid is SceneDesc::fluid (sinew/scene.h), run on
/// the Simulation's device as a stage of its frame with the same coupling
/// (the very floats on the CPU backend) and no read-back of the tissue.
/// Kept for one release.
class [[deprecated("describe the fluid in SceneDesc::fluid (sinew/scene.h) and reach it through Simulation::fluid()")]]
FluidCoupling {
 public:
  /// Samples the surfaces at the fluid's spacing, appends the samples to
  /// desc.boundary (after the fixed boundary it holds, which stays put),
  /// turns on its moving boundary and boundary forces, and creates the
  /// fluid on desc.device. [in] simulation: made with
  /// SceneDesc::external_forces; it must outlive the coupling. Errors: the
  /// simulation's frame not a whole number of fluid steps (naming both), a
  /// surface's vertex beyond the simulation's particles, no surface;
  /// surfaces that give no boundary particle, a simulation without
  /// SceneDesc::external_forces; sample_surface's and Fluid::create's.
  static Result<FluidCoupling> create(Simulation& simulation, FluidDesc desc,
                                      std::span<const CoupledSurface> surfaces);
  /// Moves the coupling.
  ///@{
  FluidCoupling(FluidCoupling&&) noexcept;
  FluidCoupling& operator=(FluidCoupling&&) noexcept;
  ///@}
  ~FluidCoupling();

  /// One coupled frame (above). Errors: the fluid's and the simulation's;
  /// an emitter past the fluid's capacity finishes the frame (both sides)
  /// and then returns capacity_exceeded.
  Status step();

  /// The coupled fluid.
  ///@{
  [[nodiscard]] Fluid& fluid();
  [[nodiscard]] const Fluid& fluid() const;
  ///@}
  /// The boundary particles that follow the tissue: [first, first + count).
  ///@{
  [[nodiscard]] std::uint32_t first_coupled() const;
  [[nodiscard]] std::uint32_t coupled_count() const;
  ///@}
  /// The impulse the fluid gave the tissue in the last frame, summed [N s].
  [[nodiscard]] std::array<double, 3> last_impulse() const;
  /// The impulse it gave the fixed boundary in the last frame [N s].
  [[nodiscard]] std::array<double, 3> last_fixed_impulse() const;

  struct Impl;  ///< opaque (src/fluid/fluid_coupling.cpp)
 private:
  explicit FluidCoupling(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sinew
