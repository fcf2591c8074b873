// sinew/scene_fluid.h — the fluid of a scene (SceneDesc::fluid), reached
// through Simulation::fluid(): its particles, counts, emitters and sinks,
// and what it pushed the tissue with. The fluid runs on the Simulation's
// device as a stage of its frame (SceneFluidDesc says what one frame does).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "sinew/fluid.h"
#include "sinew/result.h"

namespace sinew {

/// Sizes of a scene's fluid, fixed at Simulation::create.
struct SceneFluidInfo {
  std::uint32_t capacity = 0;        ///< the most fluid particles at once
  std::uint32_t fixed_boundary = 0;  ///< boundary particles that stay put (FluidDesc::boundary)
  std::uint32_t coupled_boundary = 0;  ///< boundary particles on the tissue's surfaces (after the fixed ones)
  std::uint32_t steps_per_frame = 0;   ///< fluid steps in one frame of the scene
  double particle_mass = 0.0;          ///< rho0 spacing^3 [kg]
};

/// The impulses the fluid gave its boundary in the last frame [N s].
struct FluidImpulses {
  std::array<double, 3> tissue{};  ///< to the coupled boundary: what the tissue took (as forces over the frame)
  std::array<double, 3> fixed{};   ///< to the fixed boundary
};

/// A handle on the scene's fluid; valid while its Simulation lives (moving
/// the Simulation keeps it valid). Every call on a scene without a fluid
/// is an error naming SceneDesc::fluid.
class SceneFluid {
 public:
  /// [out] the fluid particles by increasing id (Fluid::read). Reads them back.
  Status read(std::vector<FluidParticle>& particles) const;
  /// The counts after the last frame (Fluid::stats).
  [[nodiscard]] Result<FluidStats> stats() const;
  /// What the scene's fluid holds (SceneFluidInfo).
  [[nodiscard]] Result<SceneFluidInfo> info() const;
  /// As Fluid::set_emitter and set_sink; an emitter's check against the
  /// boundary (a source inside a collider) sees the boundary as it was made.
  ///@{
  Status set_emitter(std::size_t index, const FluidEmitter& emitter);
  Status set_sink(std::size_t index, const FluidSink& sink);
  ///@}
  /// The last frame's impulses, summed (reads 16 bytes per boundary particle).
  [[nodiscard]] Result<FluidImpulses> last_impulses() const;

  struct State;  ///< the runtime's (src/runtime/scene_fluid.h)
  explicit SceneFluid(State* state) : state_(state) {}

 private:
  State* state_ = nullptr;
};

}  // namespace sinew
