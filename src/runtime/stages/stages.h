// stages.h — the stages of the frame (runtime/frame_stage.h), one file
// each, registered in Simulation::create in this order:
//   forces, fluid, tool cuts, tools, mesh collision, sutures, continuous collision,
//   solve, statistics, tearing.
// A stage a scene does not use is not registered.
#pragma once

#include <memory>
#include <vector>

#include "runtime/frame_stage.h"
#include "runtime/simulation_impl.h"

namespace sinew {

/// SceneDesc::external_forces: zeroes a past frame's forces no call renewed.
std::unique_ptr<FrameStage> make_forces_stage(Simulation::Impl& sim);
/// SceneDesc::fluid: the fluid's frame on the scene's device, coupled with the tissue.
std::unique_ptr<FrameStage> make_fluid_stage(Simulation::Impl& sim);
/// ToolDesc::cuts: the cutting tools' poses before the frame (registered
/// before the tools stage), their collider cut along their motion after
/// it; nullptr when no tool cuts.
std::unique_ptr<FrameStage> make_tool_cuts_stage(Simulation::Impl& sim, const std::vector<ToolDesc>& tools);
/// Colliders, targets and rigid tools: integrated and uploaded before the
/// frame, settled (and the tools' reactions taken) after its statistics.
std::unique_ptr<FrameStage> make_tools_stage(Simulation::Impl& sim);
/// Contacts between meshes, found before the frame, checked after the solve.
std::unique_ptr<FrameStage> make_mesh_collision_stage(Simulation::Impl& sim);
/// Needles and their punctures, before the frame and after the solve.
std::unique_ptr<FrameStage> make_sutures_stage(Simulation::Impl& sim);
/// Continuous collision: the frame's capsules before it; its tests run
/// inside the solve (a SubstepHook) and are reported after it.
std::unique_ptr<FrameStage> make_continuous_stage(Simulation::Impl& sim);
/// The frame's device programs: the fixed program, or the stepper's.
std::unique_ptr<FrameStage> make_solve_stage(Simulation::Impl& sim);
/// The device's reductions read back after the solve, the errors after the tools.
std::unique_ptr<FrameStage> make_statistics_stage(Simulation::Impl& sim);
/// Elements stretched past their tear strain, removed after the frame.
std::unique_ptr<FrameStage> make_tearing_stage(Simulation::Impl& sim);

}  // namespace sinew
