// sinew/haptics/scripted_hands.h — scripted hands on a virtual clock: each
// hand a device following a KeyframePath, its HapticLoop ticked at its rate
// between the physics frames (as a device SDK's servo scheduler would call
// it), and a HapticToolBridge driving one tool. The deterministic form of a
// haptic scene: the same forces, the same tool path and the same tissue on
// every run and every machine (bit for bit on one backend), which a loop
// paced to the wall clock cannot give. Scene files' "haptics" section runs
// through it (sinew run), and the haptic examples' `--clock virtual`.
//
//   auto hands = sinew::haptics::ScriptedHands::create(descs, sim, scene.solver.time_step);  // publishes frame 0
//   for (int f = 1; f <= frames; ++f) {
//     hands->before_step(sim);   // ticks each loop up to the end of frame f, applies its force to the tool
//     sim.step();
//     hands->after_step(sim);    // publishes the tools' new state to the loops
//   }
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "sinew/haptics/clock.h"
#include "sinew/haptics/haptic_loop.h"
#include "sinew/haptics/keyframe_path.h"
#include "sinew/haptics/tool_bridge.h"
#include "sinew/result.h"

namespace sinew {
class Simulation;
}

namespace sinew::haptics {

/// One scripted hand.
struct ScriptedHandDesc {
  std::uint32_t tool = 0;  ///< the tool it drives (SceneDesc::tools index); one hand per tool
  KeyframePath path;       ///< the device's pose over time [s] from the run's start
  /// The loop: rate_hz, coupling and the rest (realtime, cpu and
  /// zero_cpu_latency are unused: the loop is ticked on the caller's thread).
  HapticLoopSettings loop;
  double tool_damping = 0.0;          ///< HapticToolBridge::set_damping linear [N s/m], >= 0
  double tool_angular_damping = 0.0;  ///< HapticToolBridge::set_damping angular [N m s/rad], >= 0
};

/// The hands of one Simulation (not copyable: the loops hold their channels).
class ScriptedHands {
 public:
  /// Makes the devices, loops and bridges and publishes the tools' state at
  /// the clock's zero. [in] hands: at most one per tool; [in] sim: the
  /// running scene, at its start; [in] frame_seconds: its frame length
  /// (SolverSettings::time_step) [s], finite and > 0. Errors name the hand
  /// ("hands[1].tool: ..."): a tool the scene lacks, a tool driven twice,
  /// bad loop settings or damping.
  static Result<std::unique_ptr<ScriptedHands>> create(std::vector<ScriptedHandDesc> hands, Simulation& sim,
                                                       double frame_seconds);

  /// Before Simulation::step() makes frame f (f = the frames it has done +
  /// 1): moves the virtual clock to frame f's end, f x frame_seconds,
  /// ticking every loop at each of its periods up to it (tick k at
  /// round(k 1e9 / rate_hz) ns; after frames stepped without the hands,
  /// their ticks too), then applies each loop's mean force over the
  /// interval to its tool.
  Status before_step(Simulation& sim);
  /// After Simulation::step(): publishes each tool's state to its loop.
  Status after_step(const Simulation& sim);

  [[nodiscard]] std::size_t count() const { return hands_.size(); }
  /// Hand i's loop: counters, telemetry (HapticLoop::copy_telemetry).
  [[nodiscard]] const HapticLoop& loop(std::size_t i) const { return *hands_[i]->loop; }
  /// Hand i's device: the forces commanded to it.
  [[nodiscard]] const ScriptedDevice& device(std::size_t i) const { return *hands_[i]->device; }
  /// Hand i's bridge: the force applied to its tool last frame.
  [[nodiscard]] const HapticToolBridge& bridge(std::size_t i) const { return *hands_[i]->bridge; }

 private:
  struct Hand {
    std::unique_ptr<ScriptedDevice> device;
    SnapshotChannel snapshots;
    FeedbackChannel feedback;
    std::unique_ptr<HapticLoop> loop;
    std::unique_ptr<HapticToolBridge> bridge;
    std::int64_t ticks = 0;  ///< ticks run
    double rate_hz = 1000.0;
  };
  ScriptedHands() = default;
  VirtualClock clock_{0};
  std::vector<std::unique_ptr<Hand>> hands_;
  double frame_s_ = 0.0;
};

}  // namespace sinew::haptics
