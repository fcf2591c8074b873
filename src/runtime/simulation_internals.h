// simulation_internals.h — what the library's tests and benchmarks may see
// of a Simulation beyond the public API: its device and its frame program
// (both internal types; users describe scenes, not dispatches).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "backends/backend.h"
#include "runtime/frame_stage.h"
#include "sinew/simulation.h"

namespace sinew {

struct CompiledScene;

struct SimulationInternals {
  /// A Simulation of `scene` on a device the caller made (a test's device
  /// wrapper that injects faults: tests/faulty_device.h).
  static Result<Simulation> create(const SceneDesc& scene, std::unique_ptr<Device> device);
  /// Simulation::create's work once the scene is compiled and the device made.
  static Result<Simulation> assemble(const SceneDesc& scene, CompiledScene& compiled, std::unique_ptr<Device> device);
  static const Device& device(const Simulation& sim);
  static const FrameProgram& program(const Simulation& sim);
  static double frame_length(const Simulation& sim);  ///< SolverSettings::time_step [s]
  /// Collider `index`'s pose as last set (where it is at the end of the
  /// next frame; after a step and before a new pose, where it is now), in
  /// the device's float32. [pre] index < the scene's colliders.
  static Pose collider_pose(const Simulation& sim, std::size_t index);
  /// Appends a stage to the frame: in every phase it runs after the
  /// scene's own, and FrameStats::stages gains its profile.
  static void add_stage(Simulation& sim, std::unique_ptr<FrameStage> stage);
  /// The particles' velocity buffer (float4 per particle, device order): a
  /// test stage breaks a frame through it (the divergence tests).
  static BufferHandle velocity_buffer(const Simulation& sim);
  /// The colouring checker (scenes with topology_changes): every block's
  /// colours in use, read back from the device, and the particles they
  /// share. conflicts: movable particles (inverse mass > 0 on the device)
  /// met a second time in one colour (0 when every colour is valid).
  struct ColorCheck {
    std::uint32_t colors = 0;
    std::uint64_t constraints = 0;  ///< in use
    std::uint64_t conflicts = 0;
    double total_mass = 0.0;  ///< sum of 1 / w over the device's movable particles [kg]
    /// Every constraint in use: its kernel and its particles (user order,
    /// sorted), the list sorted; what a test compares with the topology.
    std::vector<std::pair<Kernel, std::vector<std::uint32_t>>> in_use;
  };
  static Result<ColorCheck> check_colors(const Simulation& sim);
  /// Every block's constraint slots as the device holds them (each slot's
  /// particles and data words, in slot order) and each colour's count in
  /// use: what replaying a topology log must give bit for bit.
  static Result<std::vector<std::uint32_t>> constraint_words(const Simulation& sim);
  /// Simulation::restore_state's work: restores `state` into `sim`, or,
  /// when the state's topology changes do not continue the Simulation's
  /// (it has made others, or more), into a Simulation made again from its
  /// SceneDesc and device options that then takes its place (its ids stay
  /// valid; stages added by add_stage are not). `what` names the state in
  /// errors; on an error `sim` is as it was.
  static Status restore(Simulation& sim, const SavedState& state, const std::string& what);
};

}  // namespace sinew
