// frame_stage.h — the frame as a list of stages. Each feature of the
// runtime (external forces, tools, mesh collision, continuous collision,
// needles and sutures, the solve, the statistics, tearing) is one stage;
// Simulation::step() runs the stages' hooks phase by phase, each phase in
// the order the stages were registered, and times every stage.
//
// The shape follows Box2D v3's step context (b2StepContext: what one step
// shares, passed to each stage of the solver) and Jolt's step listeners
// (PhysicsStepListener: a feature joins the update by registering one
// object): a new feature is one stage file and one registration line
// (Simulation::create in simulation.cpp).
//
// The phases of a frame, in order:
//   before_frame  upload what moved, find contacts (tools, mesh collision, sutures, CCD's frame capsules)
//   solve         the frame's device programs (only the solve stage)
//   after_solve   read back what the solve produced, then the statistics
//   after_frame   act on the statistics (tools' reactions, errors), tear
// and, between frames or when tearing removes elements inside one:
//   topology_changed  follow a removal (collision surfaces, grasps, the
//                     measured volume); the core then rebuilds the program
//
// The host's exchanges with the device are counted by the Device itself
// (HostTransfers, backends/backend.h); step() attributes them to the stage
// whose hook made them (its profile's "read_bytes" and "host_waits") and
// sums them in FrameStats (read_back_bytes, host_reads, host_waits).
#pragma once

#include <chrono>
#include <cstdint>
#include <string_view>

#include "backends/backend.h"
#include "sinew/simulation.h"

namespace sinew {

/// What the stages of one frame share. The device and the scene's buffers
/// stay the Simulation's; the statistics are the frame's being made.
struct FrameContext {
  Device& device;
  FrameStats& stats;
  /// An error that leaves the frame whole (a fluid's emitter past its
  /// capacity made what fit): the other stages run, the frame completes,
  /// and step() returns it at the end.
  Status deferred;
};

/// What a topology change did, handed to every stage in registration order.
struct TopologyChange {
  const TopologyEvent& event;  ///< the elements removed and the particles freed
  /// Set by the mesh collision stage when the collision surface changed
  /// (continuous collision, registered after it, remakes its primitives).
  bool collision_surface_changed = false;
};

class FrameStage {
 public:
  virtual ~FrameStage() = default;
  /// The stage's name in FrameStats::stages ("mesh collision", ...).
  [[nodiscard]] virtual std::string_view name() const = 0;
  virtual Status before_frame(FrameContext&) { return {}; }
  virtual Status solve(FrameContext&) { return {}; }
  virtual Status after_solve(FrameContext&) { return {}; }
  virtual Status after_frame(FrameContext&) { return {}; }
  /// Elements were removed (Topology's calls, or tearing after a frame):
  /// the stage follows before the core rebuilds the frame's program.
  virtual Status topology_changed(Device&, TopologyChange&) { return {}; }
  /// After the frame: the stage's own figures into its profile (StageProfile::set).
  virtual void report(StageProfile&) const {}
};

/// Milliseconds since `start` (a stage's own figures in FrameStats).
inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace sinew
