// simulation_impl.h — the state behind sinew::Simulation, shared by the
// files that implement it: simulation.cpp (create, step, read-back, error
// statistics) and simulation_contacts.cpp (colliders, targets, tools).
#pragma once

#include <array>
#include <chrono>
#include <memory>
#include <optional>
#include <vector>

#include "compiler/scene_compiler.h"
#include "program/stats_program.h"
#include "program/xpbd_program.h"
#include "program/vbd_program.h"
#include "runtime/contact_state.h"
#include "runtime/frame_stage.h"
#include "runtime/positions_mirror.h"
#include "runtime/tool_contacts.h"
#include "runtime/continuous_collision.h"
#include "runtime/mesh_collision.h"
#include "runtime/solve_stepper.h"
#include "runtime/graspers.h"
#include "runtime/sutures.h"
#include "runtime/topology_editor.h"
#include "runtime/topology_log.h"
#include "runtime/scene_fluid.h"
#include "sinew/divergence.h"
#include "runtime/frame_warnings.h"
#include "sinew/saved_state.h"
#include "sinew/simulation.h"

namespace sinew {

struct Simulation::Impl {
  std::unique_ptr<Device> device;
  /// This Simulation's number, unique in the process: the `scene` of its ids (sinew/ids.h).
  std::uint32_t serial = 0;
  // The frame's stages in the order they run (runtime/frame_stage.h,
  // registered in Simulation::create); stats.stages holds their profiles
  // in the same order.
  std::vector<std::unique_ptr<FrameStage>> stages;
  std::vector<HostTransfers> stage_transfers;  // this frame's, per stage (step())
  void add_stage(std::unique_ptr<FrameStage> stage);
  // The positions as read back for the stages that need them on the host
  // (runtime/positions_mirror.h): at most once between two changes.
  PositionsMirror positions_mirror;
  XpbdBuffers buffers;
  FrameProgram program;
  ProgramHandle prepared;
  // Residual-driven mode or the accelerator (SolverSettings): the frame as
  // several programs the host sequences; null in the fixed mode.
  std::unique_ptr<SolveStepper> stepper;
  // SolverSettings::method = vbd: Vertex Block Descent's buffers (the
  // vertex colours and incidences); its frame program replaces xPBD's.
  std::optional<VbdBuffers> vbd;
  SceneInfo info;
  FrameStats stats;
  double time_step = 0.0;
  bool measure_errors = true;
  int substeps = 1, iterations = 1;  // SolverSettings (FrameStats::sweeps in the fixed mode)
  double rest_volume = 0.0;  // every tet body's total rest volume [m^3]
  // Device slot of each user particle (compiler/particle_order.h); reads
  // gather through it into the user's order.
  ParticleOrder order;
  mutable std::vector<float> device_order_scratch;
  Status read_in_user_order(BufferHandle buffer, std::vector<float>& xyzw) const;
  /// The positions in the user's order, through the mirror (the stages' read of this frame).
  Status positions_in_user_order(std::vector<float>& xyzw);
  // The errors and the tools' reaction, reduced on the device at the end of
  // each frame (stats_program.h) and read back as a few words.
  StatsPlan stats_plan;
  std::vector<std::uint32_t> stats_tet_first;  ///< per tet body, its first tet in stats_plan.tet_list
  DeviceStats device_stats;

  void measure(FrameStats& stats) const;

  // SceneDesc::external_forces: forces staged in device order (sized once,
  // so a call allocates nothing); whether a call set the coming frame's,
  // and whether the device buffer holds a call's (nonzero) forces.
  std::vector<kernels::float4> force_scratch;
  // ... and each particle's float inverse mass (device order), to check
  // the impulse h f / m a force makes in float (set_particle_forces).
  std::vector<float> force_inverse_mass;
  bool forces_for_next_frame = false;
  bool forces_on_device = false;
  bool host_forces_this_frame = false;  ///< the frame being run has a call's forces (the fluid adds to them)
  /// Before a frame's program: the forces of the last frame's call, if no
  /// call since set the coming frame's, are reset to zero.
  Status begin_frame_forces();

  // SceneDesc::fluid (scene_fluid.h; null without): destroyed before the device.
  std::unique_ptr<SceneFluid::State> fluid;

  // Contacts between meshes (mesh_collision.h; null when the scene has
  // none). The program is rebuilt when they outgrow it (or the topology
  // changes), from the compiled scene's shape (its blocks without their
  // data) kept here for that.
  std::unique_ptr<MeshCollision> mesh_collision;
  // The threads' continuous collision detection, run by the stepper after
  // every substep's sweeps (null unless MeshCollisionDesc::continuous).
  std::unique_ptr<ContinuousCollision> continuous;
  // The needles and their punctures (sutures.h; null when the scene has none).
  std::unique_ptr<Sutures> sutures;
  /// The stages that end every sweep: the mesh contacts and the sutures.
  [[nodiscard]] SweepExtras sweep_extras() const {
    return {mesh_collision ? &mesh_collision->buffers() : nullptr, sutures ? &sutures->buffers() : nullptr};
  }
  CompiledScene program_shape;
  SolverSettings solver;
  std::array<double, 3> gravity{};
  /// Builds the fixed-mode frame program (solve + statistics) and prepares it on the device.
  Status prepare_program(const CompiledScene& compiled);
  /// Builds the frame's program(s) again from program_shape: after the mesh
  /// contacts outgrew theirs, or a topology change. On an error the
  /// programs are not ready, and the next step() tries again.
  Status rebuild_program();
  Status rebuild_programs();  // rebuild_program's work
  bool program_ready = true;

  // With topology changes and mesh collision: the scene's bodies as the
  // collision sees them (each tet body's live tets), to make the mesh
  // collision again after a change (null otherwise; the mesh collision
  // stage's topology_changed).
  std::unique_ptr<SceneDesc> collision_scene;
  // SceneDesc::graspers (null without).
  std::unique_ptr<GrasperHolds> graspers;
  // SceneDesc::topology_changes: the host copy of the constraints that
  // removals patch (null without), and the last step's tears.
  std::unique_ptr<TopologyEditor> topology;
  std::vector<TopologyEvent> tears;
  /// Every change the editor applied, in order (topology_log.h): a saved
  /// state holds it, a restore replays it.
  TopologyLog topology_log;
  /// With topology changes: the scene and the device options it was made
  /// with, to make it again for a restore whose log does not continue this
  /// Simulation's (SimulationInternals::restore; no options: made on a
  /// device given to it, which cannot be made again).
  std::shared_ptr<const SceneDesc> source_scene;
  std::optional<DeviceOptions> device_options;
  bool replaying = false;  ///< inside a restore's replay: no roll-back checkpoint and no program rebuilt per change
  /// Applies one change (the editor, then finish_change) and logs it.
  Result<TopologyEvent> edit(TopologyRecord record, std::chrono::steady_clock::time_point start);
  /// After a frame: removes the tets, triangles and segments stretched
  /// past their body's tear_strain.
  Status tear();
  /// Removes elements of a tet or tri body (topology_editor.h), rebuilds
  /// the program and times the whole change from `start`.
  Result<TopologyEvent> apply_removal(BodyKind kind, std::size_t body,
                                                  std::span<const std::uint32_t> elements, bool burn,
                                                  std::chrono::steady_clock::time_point start);
  /// After tets were removed (with measure_errors): the statistics' faces
  /// are the tet bodies' live boundaries and rest_volume the live tets',
  /// so FrameStats::volume_change measures what is left.
  Status refresh_volume(const TopologyEvent& event);
  /// After the editor changed something: every stage's topology_changed
  /// (the mesh collision made again, ...), the program rebuilt, the event's
  /// times filled in.
  Result<TopologyEvent> finish_change(Result<TopologyEvent> event, bool changed,
                                                  std::chrono::steady_clock::time_point start);

  // simulation_contacts.cpp: host copies of the collider and target
  // buffers (rewritten before each frame) and the tools' rigid state.
  std::vector<float> colliders;
  std::vector<float> targets;
  std::size_t scene_targets = 0;  ///< SceneDesc::targets (the graspers' own targets follow them)
  ContactState contacts;
  Status init_contacts(const SceneDesc& scene, const CompiledScene& compiled);
  Status before_frame();  ///< integrates the tools (rigid_tool.h), uploads what moved
  /// The scene's colliders at their poses at the end of the coming frame
  /// (or at its start: where the last frame left them).
  [[nodiscard]] std::vector<PosedShape> collider_shapes(bool start = false) const;
  /// Each tool's shape (a capsule or a level set) at its pose at the start or the end of the coming
  /// frame (after before_frame, which integrates the tools).
  [[nodiscard]] std::vector<PosedShape> tool_shapes(bool start) const;
  /// The tools and capsule colliders over the coming frame, for the
  /// continuous collision detection (after before_frame).
  [[nodiscard]] std::vector<FrameCapsule> frame_capsules() const;
  Status after_frame();   ///< settles what moved, takes each tool's reaction from device_stats
  /// Cuts level-set collider `index` (Simulation::cut_collider; the tool cuts stage).
  Result<CutReport> cut_collider(std::size_t index, const CutterShape& shape, const Pose& from, const Pose& to);

  // ---- Saved state and divergence (simulation_state.cpp, divergence_check.cpp).
  /// Changes of the scene's shape: topology changes (finish_change) and
  /// level-set cuts (cut_collider), counted (a state saved by format
  /// version 3 or older restores only where none was made).
  std::uint64_t shape_generation = 0;
  /// The device buffers whose contents carry from one frame to the next,
  /// with their sizes (set in create; save_state reads them in this order).
  struct StateBuffer {
    BufferHandle buffer;
    std::size_t bytes = 0;
    const char* name = "";
  };
  std::vector<StateBuffer> state_buffers;
  /// state_buffers and the fluid's (sph_solver.h), in the order a state holds them.
  [[nodiscard]] std::vector<StateBuffer> saved_buffers() const;
  /// Fills state_buffers and the divergence checks' scene figures (history) from the compiled scene.
  void init_state_buffers(const CompiledScene& compiled);
  Status save_state(SavedState& out);
  /// [out] rebuild (may be null): set when the state's topology log does
  /// not continue this Simulation's, so that only a Simulation made again
  /// from its SceneDesc can take it (SimulationInternals::restore); the
  /// error returned then says so, and nothing changed.
  Status restore_state(const SavedState& state, const std::string& what, bool* rebuild = nullptr);

  DivergenceSettings divergence;
  FrameWarnings warnings;  ///< sinew/warnings.h (frame_warnings.cpp)
  /// What the checks keep between frames: the last frame's kinetic energy,
  /// the scene's movable mass and starting extent, the force term of the
  /// energy bound for the coming frame (set_particle_forces) and the frame being run.
  struct DivergenceHistory {
    double last_energy = 0.0;       ///< [J]
    double movable_mass = 0.0;      ///< [kg]
    double extent = 0.0;            ///< the starting positions' bounding-box diagonal [m]
    double next_force_speed = 0.0;  ///< sqrt(sum dt^2 |f|^2 / (2 m)) of the forces set for the coming frame [sqrt(J)]
    double force_speed = 0.0;       ///< the same for the frame being run
  } history;
  SavedState last_good;  ///< OnDivergence::roll_back: the last good frame's state
  bool checkpoint_failed = false;
  bool stepping = false;  ///< inside step()'s stages (a topology change there is a tear)
  /// Saves last_good (OnDivergence::roll_back): after a good frame, and after a topology change between frames.
  void checkpoint();
  /// After a frame: the checks, the log and the policy (divergence_check.cpp).
  Status check_divergence();
  /// A roll-back back before a tear of the diverged frame: only a Simulation
  /// made again can take the checkpoint, which step() does
  /// (SimulationInternals::restore), then reports it as check_divergence would.
  struct PendingRollBack {
    DivergenceReport diverged;
    std::string message;
  };
  std::optional<PendingRollBack> pending_roll_back;
  /// The report and the warning of a roll-back to the frame now restored.
  void report_roll_back(const DivergenceReport& diverged, const std::string& message);
  /// A frame a stage failed (a device error): with OnDivergence::roll_back
  /// the scene goes back to the last good frame; the error is returned either way.
  Status after_failed_frame(const Error& error);
};


}  // namespace sinew
