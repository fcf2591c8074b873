// sinew/haptics/tool_bridge.h — the physics thread's side of the haptic
// loop: publishes the tool's state after each frame, and drives the tool
// with the coupling force the haptic loop produced.
//
//   HapticToolBridge bridge(0, snapshots, feedback, clock);   // tool 0
//   loop:  bridge.apply_feedback(sim);   // apply_tool_force(-mean device force over the last frame)
//          sim.step();
//          bridge.publish(sim);          // a HapticSnapshot into the channel
//
// Sign convention: the feedback's force is what the coupling applies to the
// device; the tool gets the opposite, -(mean over the interval since the
// previous apply_feedback), i.e. (I_b - I_a) / (t_b - t_a) from the impulse
// integral of two readings (snapshot_channel.h). A tool driven this way
// should have gravity off (the hand carries the instrument's weight).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "sinew/haptics/clock.h"
#include "sinew/haptics/local_contact_builder.h"
#include "sinew/haptics/snapshot_channel.h"
#include "sinew/result.h"
#include "sinew/simulation.h"

namespace sinew::haptics {

/// The physics thread's side of the haptic hand-off: publish() puts a
/// tool's state into the snapshot channel after each step, and
/// apply_feedback() applies the device's coupling force to the tool before
/// the next (docs/haptics.md).
class HapticToolBridge {
 public:
  /// [in] tool: index of the tool in the scene; channels and clock must outlive the bridge.
  HapticToolBridge(std::size_t tool, SnapshotChannel& snapshots, FeedbackChannel& feedback, Clock& clock)
      : tool_(tool), snapshots_(snapshots), feedback_(feedback), clock_(clock) {}

  /// Damping of the simulated tool's own motion, added by apply_feedback as
  /// -linear v_tool and -angular w_tool from the tool's current state
  /// [in] linear [N s/m], angular [N m s/rad], both >= 0 (default 0). It is
  /// not rendered to the device. Why: the tool -> snapshot -> coupling ->
  /// feedback -> tool loop holds about 1.5 physics frames of delay
  /// (interpolation plus averaging), and a spring K seen through a delay tau
  /// acts as a negative damper of about K tau, eating the coupling's own
  /// damping (500 N/m x 6 ms = 3 N s/m at 250 Hz frames); a coupled tool
  /// then rings at sqrt(K / M). Damping applied here has no such delay.
  /// Explicit: keep linear x time_step / tool mass well below 2. Errors name the parameter.
  Status set_damping(double linear, double angular);

  /// Before Simulation::step(): reads the newest feedback and applies minus
  /// its mean device force and torque since the previous call to the tool.
  /// No new tick since then (the haptic loop stopped or has not started):
  /// nothing is applied (counted in frames_without_feedback()). The first
  /// reading, and the first from a loop other than the previous reading's
  /// (CouplingFeedback::loop: a HapticLoop recreated on the same channel),
  /// apply minus that tick's force and torque.
  Status apply_feedback(Simulation& sim);
  /// After Simulation::step(): publishes the tool's state as a HapticSnapshot
  /// stamped with the clock's now, with the local contact model when one
  /// is set (set_local_contacts; it reads the positions back).
  Status publish(const Simulation& sim);

  /// From now on publish() adds the contacts near the tool as a local
  /// contact model (local_contact_builder.h), for a loop that renders them
  /// (HapticLoopSettings::local_contacts). [in] builder: made for this
  /// bridge's tool (an error otherwise).
  Status set_local_contacts(LocalContactBuilder builder);
  /// The model published last (count 0 when none).
  [[nodiscard]] const LocalContactModel& last_local_contacts() const { return last_model_; }

  /// Minus the mean device force (and torque) last applied to the tool
  /// [N, N m], without the damping of set_damping.
  [[nodiscard]] const Vec3& last_tool_force() const { return force_; }
  [[nodiscard]] const Vec3& last_tool_torque() const { return torque_; }
  [[nodiscard]] const CouplingFeedback& last_feedback() const { return prev_; }
  [[nodiscard]] std::uint64_t frames_without_feedback() const { return missing_; }
  [[nodiscard]] std::uint64_t published() const { return sequence_; }

 private:
  std::size_t tool_;
  SnapshotChannel& snapshots_;
  FeedbackChannel& feedback_;
  Clock& clock_;
  CouplingFeedback prev_{};
  bool have_prev_ = false;
  Vec3 force_{}, torque_{};
  double damping_ = 0.0, angular_damping_ = 0.0;
  std::uint64_t missing_ = 0;
  std::uint64_t sequence_ = 0;
  std::optional<LocalContactBuilder> builder_;
  std::vector<float> positions_;  // publish()'s read-back, kept to avoid reallocating
  LocalContactModel last_model_{};
};

}  // namespace sinew::haptics
