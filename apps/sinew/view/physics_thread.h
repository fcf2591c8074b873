// physics_thread.h — the viewer's physics (docs/viewer.md): a Simulation
// stepped on its own thread at the scene's own rate (one time_step of wall
// clock per frame, or as fast as it can), its script played, the picked
// tool driven through the haptic tool bridge by a haptic loop that samples
// the mouse's virtual device, and a ViewSnapshot published after each frame.
// The viewer asks for pause, step, reset and another tool through atomics:
// it never waits for a frame, and the physics never waits for a draw.
#pragma once

#include <atomic>
#include <cstdint>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "sinew/haptics/clock.h"
#include "sinew/haptics/haptic_loop.h"
#include "sinew/haptics/scripted_hands.h"
#include "sinew/haptics/tool_bridge.h"
#include "sinew/scene_file.h"
#include "sinew/simulation.h"
#include "view/mouse_device.h"
#include "view/view_snapshot.h"

namespace sinew::view {

class PhysicsThread {
 public:
  /// [in] file: the scene (with the viewer's probe, if it added one);
  /// [in] device: the backend and device; [in] mouse: the virtual device the
  /// haptic loop samples (outlives this).
  PhysicsThread(SceneFile file, DeviceOptions device, MouseDevice& mouse);
  ~PhysicsThread();  ///< stop()
  PhysicsThread(const PhysicsThread&) = delete;
  PhysicsThread& operator=(const PhysicsThread&) = delete;

  /// Makes the Simulation on the physics thread and starts stepping it, and
  /// the haptic loop when the scene has a tool no scripted hand of the file
  /// drives (the mouse's handle placed at the first such tool; the file's
  /// scripted hands play on theirs, on the frames' clock). Errors: the
  /// Simulation's (a backend not available, ...), the loop's, the hands'.
  Status start();
  /// Stops the haptic loop and the physics thread. Idempotent.
  void stop();

  void set_paused(bool paused) { paused_.store(paused); }
  [[nodiscard]] bool paused() const { return paused_.load(); }
  /// One frame while paused.
  void step_once() { step_requests_.fetch_add(1); }
  /// Remakes the Simulation from the scene (its first frame again).
  void reset() { reset_requested_.store(true); }
  /// Drives tool `tool` with the haptic loop from the next frame (the viewer
  /// places the mouse's handle at it first); a tool a scripted hand drives
  /// stays the hand's (the mouse then drives nothing).
  void drive_tool(int tool) { driven_tool_.store(tool); }
  [[nodiscard]] int driven_tool() const { return driven_tool_.load(); }

  /// The snapshots (the viewer's thread reads front() after update()).
  TripleBuffer<ViewSnapshot>& snapshots() { return snapshots_; }
  /// The haptic loop's feedback: CouplingFeedback::force is the force on the hand [N].
  [[nodiscard]] bool read_feedback(haptics::CouplingFeedback& out) const { return feedback_.try_read(out); }
  /// What the haptic loop runs at ("" without tools).
  [[nodiscard]] const std::string& haptic_description() const { return haptic_description_; }
  /// The Simulation's device name (after start()).
  [[nodiscard]] const std::string& device_name() const { return device_name_; }
  /// The scene as it runs.
  [[nodiscard]] const SceneFile& file() const { return file_; }

 private:
  void run(std::promise<Status> ready);
  Status make_simulation();
  Status step_frame();
  [[nodiscard]] bool scripted(int tool) const;
  void note_change(const TopologyEvent& event);
  void refresh_shapes();
  Status fill_snapshot(ViewSnapshot& out);

  SceneFile file_;
  DeviceOptions device_options_;
  MouseDevice& mouse_;
  haptics::MonotonicClock clock_;
  haptics::SnapshotChannel haptic_snapshots_;
  haptics::FeedbackChannel feedback_;
  std::unique_ptr<haptics::HapticLoop> loop_;
  std::string haptic_description_, device_name_;

  // Physics thread only.
  std::optional<Simulation> sim_;
  std::optional<ScriptPlayer> player_;
  std::optional<haptics::HapticToolBridge> bridge_;
  std::unique_ptr<haptics::ScriptedHands> hands_;  // the file's scripted hands
  int bridged_tool_ = -1;
  std::uint64_t generation_ = 0, frame_ = 0, shape_version_ = 0, surfaces_version_ = UINT64_MAX;
  std::vector<std::vector<std::array<std::uint32_t, 3>>> tet_surfaces_, tri_surfaces_;
  std::vector<std::vector<std::array<std::uint32_t, 2>>> line_segments_;
  std::shared_ptr<const std::vector<TriMesh>> collider_surfaces_;
  std::vector<float> velocities_;
  std::vector<FluidParticle> fluid_;
  std::vector<ScriptEvent> results_;
  double physics_hz_ = 0.0;
  std::string error_;

  TripleBuffer<ViewSnapshot> snapshots_;
  std::atomic<bool> paused_{false}, reset_requested_{false}, stop_{false};
  std::atomic<int> step_requests_{0};
  std::atomic<int> driven_tool_{-1};
  std::thread thread_;
};

}  // namespace sinew::view
