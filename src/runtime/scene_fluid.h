// scene_fluid.h — a scene's fluid on the Simulation's device
// (SceneDesc::fluid): the SPH solver, the tissue samples its coupled
// boundary particles sit on, and the two coupling programs
// (kernels/shared/fluid_coupling_params.h). The fluid stage
// (stages/fluid_stage.cpp) runs one frame of it before the tissue's.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "backends/backend.h"
#include "compiler/scene_compiler.h"
#include "fluid/sph_solver.h"
#include "program/xpbd_program.h"
#include "sinew/scene.h"
#include "sinew/scene_fluid.h"

namespace sinew {

struct SceneFluid::State {
  /// The fluid of `scene.fluid` (checked) on `device`, its surfaces on the
  /// compiled scene's particles (device slots). [in] frame: the scene's
  /// time step [s].
  static Result<std::unique_ptr<State>> create(const SceneDesc& scene, const CompiledScene& compiled,
                                               Device& device, const XpbdBuffers& buffers);
  ~State();
  State(const State&) = delete;
  State& operator=(const State&) = delete;

  /// The fluid's frame: the boundary follows the tissue, the fluid's
  /// steps, its forces on the tissue (added to the host's when
  /// `add_to_host_forces`). An emitter past the capacity finishes the
  /// steps; its capacity_exceeded is kept in `pending` for the frame's end.
  Status run_frame(bool add_to_host_forces);

  Device& device;
  std::unique_ptr<SphSolver> solver;
  SceneFluidInfo info;
  Status pending;  ///< a capacity error of this frame's steps, returned by step() when the frame is done

 private:
  explicit State(Device& d) : device(d) {}
  Status make_coupling(const SceneDesc& scene, const CompiledScene& compiled, const XpbdBuffers& buffers,
                       std::vector<SurfaceSamples>& samples);
  std::vector<BufferHandle> owned_;  // the coupling's buffers
  ProgramHandle follow_{}, forces_{}, forces_added_{};
  bool coupled_ = false;
};

}  // namespace sinew
