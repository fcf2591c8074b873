// retraction_scene.h — the reference scene "S1 retraction", shared by
// examples/retraction.cpp, benchmarks/retraction.cpp and its ctest: kidney_57k
// (corotational FEM, pinned along its back, its own mesh self-collision
// on) grasped at its upper pole by a grasper and pulled up while a capsule
// probe presses its front, both tools driven by scripted haptic devices
// through the haptic tool bridge (sinew/haptics/tool_bridge.h), 60 Hz frames.
//
// The grasper as a haptic tool. The bridge drives a rigid tool (ToolDesc), and
// a grasper (GrasperDesc) is moved by pose; so the grasper's jaws ride on a
// rigid capsule tool (its shaft, above the jaws): before each frame the jaws
// move to the shaft's pose, and the holds' pull on the jaws goes back to the
// shaft as a force. The holds are compliant (GrasperDesc::compliance c per
// held vertex), so that pull is what the springs carry:
// F = sum_k (x_k - target_k) / c, read from the positions after each frame and
// applied to the shaft during the next (explicit, one frame late, as every
// tool's reaction is). The hand then feels, through the virtual coupling, the
// tissue it pulls on.
//
// The haptic loops. Two ways to tick them (RetractionSettings::realtime_haptics):
//  - virtual (default): this thread ticks both loops at 1 kHz of simulated
//    time on a VirtualClock before each frame, as a device SDK's scheduler
//    calls HapticLoop::tick(); runs are repeatable, whatever the frame costs;
//  - real time: each loop runs on its own thread at 1 kHz of wall time
//    (SCHED_FIFO when granted) while the frames run as fast as they can.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sinew/haptics/clock.h"
#include "sinew/haptics/haptic_loop.h"
#include "sinew/haptics/scripted_device.h"
#include "sinew/haptics/tool_bridge.h"
#include "sinew/result.h"
#include "sinew/scene.h"
#include "sinew/simulation.h"

namespace sinew::examples {

/// How the retraction scene is built and run.
struct RetractionSettings {
  std::string mesh;                ///< the kidney's tet mesh (millimetres, scaled to metres), e.g. kidney_57k.node
  std::string backend = "cpu";     ///< cpu, opencl, vulkan or auto
  int threads = 0;                 ///< cpu backend worker threads (0: all)
  double young = 10e3;             ///< Young's modulus [Pa] of the corotational FEM
  double poisson = 0.45;           ///< Poisson ratio
  int substeps = 16;               ///< per 1/60 s frame (fewer invert the mesh's small tets: docs/benchmarks.md)
  int iterations = 1;              ///< per substep
  bool self_collision = true;      ///< the kidney's mesh self-collision (MeshCollisionDesc)
  bool measure_errors = false;     ///< SolverSettings::measure_errors
  bool realtime_haptics = false;   ///< loops on their own threads at wall-clock 1 kHz (above)
  bool realtime_priority = true;   ///< real time: ask for SCHED_FIFO for the loops' threads
  double script_speed = 1.0;       ///< the hands' script runs this many times faster (> 0; the ctest's short run)
  /// The probe's loop renders the local contact model (HapticLoopSettings::local_contacts)
  /// that its bridge publishes (LocalContactBuilder, default settings).
  bool local_contacts = false;
  /// Real time: pin the grasper's and the probe's loop threads to these CPUs (-1: not pinned).
  std::array<int, 2> haptic_cpus{-1, -1};
  /// > 0: the probe presses with this force [N] along -z, ramped in as the
  /// script's press is (kPressStart, kPressEnd) and then held, instead of
  /// following its hand's coupling; a spring-damper (kProbeHold) keeps it on
  /// its axis and its orientation. 0: the hand's coupling (the scene S1).
  double probe_force = 0.0;
  int contact_sweeps = 0;  ///< SolverSettings::contact_sweeps
};

/// The scene in a few lines, for the programs' --help.
inline constexpr const char* kRetractionAbout =
    "The reference scene S1: kidney_57k (corotational FEM, 10 kPa, nu 0.45), pinned along its back (low z),\n"
    "grasped at its upper pole and pulled 15 mm up while a capsule probe presses its front 10 mm; mesh\n"
    "self-collision on; both tools driven by scripted haptic devices through the haptic tool bridge; 60 Hz\n"
    "frames.\n";

/// The scene's script [s]: the grasper lifts the pole by kPull [m] over
/// [kPullStart, kPullEnd]; the probe presses kPress [m] over [kPressStart, kPressEnd]; then both hold.
inline constexpr double kPull = 0.015, kPullStart = 0.2, kPullEnd = 1.4;
inline constexpr double kPress = 0.010, kPressStart = 0.1, kPressEnd = 0.9;
/// The gap [m] between the probe's tip and the kidney (and the grasper's jaws and shaft) at the start.
inline constexpr double kToolGap = 0.002;
/// When the probe's device reaches the kidney [s of script time]: the
/// press ramp 0.5 - 0.5 cos(pi u) has covered kToolGap.
double probe_contact_time();

/// RetractionSettings::probe_force: the spring-damper that holds the probe
/// on its axis (across it) and in its orientation: stiffness [N/m] and
/// damping [N s/m] across the axis (damping along it too), and angular
/// stiffness [N m/rad] and damping [N m s/rad]; all explicit, inside
/// their bounds at 60 Hz for the tool's 0.3 kg and 1e-4 kg m^2
/// (k dt^2 / M = 0.46, b dt / M = 1.1; 1.4 and 0.67 for the rotation).
struct ProbeHold {
  static constexpr double stiffness = 500.0, damping = 20.0;
  static constexpr double angular_stiffness = 0.5, angular_damping = 0.004;
};

/// What one frame's physics checks measure (RetractionScene::check).
struct RetractionCheck {
  double max_slip = 0.0;           ///< the held vertex furthest from where the jaws hold it [m]
  double contact_violation = 0.0;  ///< FrameStats::contact_violation [m]
  double self_violation = 0.0;     ///< the same over the kidney's contacts with itself [m]
  double tool_violation = 0.0;     ///< the same over its faces' contacts with the tools [m]
  /// The deepest kidney vertex inside the probe's capsule [m] (0: none inside).
  double probe_penetration = 0.0;
  double probe_force = 0.0;        ///< the tissue's push on the probe along +z, the frame's average [N]
  double probe_depth = 0.0;        ///< how far the probe's tip moved along -z since the start [m]
  std::size_t inverted_tets = 0;   ///< tets whose signed volume changed sign from the rest shape
  std::array<double, 3> grasp_force{};   ///< the tissue's pull on the jaws [N]
  std::array<double, 3> device_force{};  ///< last force commanded to the grasper's device [N]
  double pole_lift = 0.0;          ///< the held vertices' mean rise since the grasp [m]
};

/// The scene, its two scripted devices, loops and bridges. Not movable (the
/// loops hold references to the devices, channels and clock).
class RetractionScene {
 public:
  /// Reads the mesh, builds the scene and the haptic side, closes the
  /// grasper on the pole. Errors: the mesh's, the scene's, the loops'.
  static Result<std::unique_ptr<RetractionScene>> create(const RetractionSettings& settings);
  ~RetractionScene();
  RetractionScene(const RetractionScene&) = delete;
  RetractionScene& operator=(const RetractionScene&) = delete;

  /// Real time only: starts both loops' threads (the script's clock starts now).
  Status start_haptics();
  /// Real time only: stops them (idempotent).
  void stop_haptics();

  /// One 1/60 s frame: [virtual] the loops' ticks up to the frame's end;
  /// the tools' feedback and the grasp's pull; the jaws to the shaft; step();
  /// the tools' snapshots; the grasp's pull for the next frame.
  Status frame();
  /// The frame's physics checks (reads the positions back).
  Result<RetractionCheck> check();

  [[nodiscard]] Simulation& sim() { return *sim_; }
  [[nodiscard]] const SceneDesc& scene() const { return scene_; }
  [[nodiscard]] haptics::HapticLoop& grasper_loop() { return *loops_[0]; }
  [[nodiscard]] haptics::HapticLoop& probe_loop() { return *loops_[1]; }
  [[nodiscard]] const std::vector<std::uint32_t>& held() const { return held_; }
  [[nodiscard]] const Pose& jaws() const { return jaws_; }
  [[nodiscard]] const std::array<double, 3>& jaw_half_extents() const { return jaw_half_; }
  [[nodiscard]] double frame_time() const { return scene_.solver.time_step; }

 private:
  RetractionScene() = default;
  Status grasp();
  Status measure_pull();  // pull_ from the positions after a frame
  Status press_probe();   // RetractionSettings::probe_force: the probe's force for the coming frame

  RetractionSettings settings_;
  SceneDesc scene_;
  std::vector<std::array<std::uint32_t, 4>> tets_;
  std::vector<double> rest_sign_;
  std::optional<Simulation> sim_;
  haptics::VirtualClock virtual_clock_;
  haptics::MonotonicClock wall_clock_;
  haptics::Clock* clock_ = nullptr;
  std::array<haptics::SnapshotChannel, 2> snapshots_;
  std::array<haptics::FeedbackChannel, 2> feedback_;
  std::vector<std::unique_ptr<haptics::ScriptedDevice>> devices_;
  std::vector<std::unique_ptr<haptics::HapticLoop>> loops_;
  std::vector<std::unique_ptr<haptics::HapticToolBridge>> bridges_;
  std::array<double, 3> jaw_offset_{};  // the jaws' centre from the shaft's centre, shaft frame [m]
  std::array<double, 3> jaw_half_{};
  Pose jaws_;                           // where the jaws were last sent
  std::vector<std::uint32_t> held_;
  std::vector<std::array<double, 3>> held_local_;  // each held vertex in the jaws' frame [m]
  std::array<double, 3> grasp_centre_{};           // the held vertices' mean at the grasp [m]
  double hold_compliance_ = 0.0;                   // [m/N] per held vertex
  std::array<double, 3> pull_{};                   // the tissue's pull on the jaws after the last frame [N]
  std::vector<float> x_;
  std::int64_t t0_ = 0;
  std::uint64_t frames_ = 0;
  bool running_ = false;
};

}  // namespace sinew::examples
