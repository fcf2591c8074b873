// sinew/simulation.h — running a scene on a backend.
//
//   sinew::SceneDesc scene = ...;
//   auto sim = sinew::Simulation::create(scene, {.backend = "auto"});
//   if (!sim) { std::cerr << sim.error().message(); return 1; }
//   for (int f = 0; f < 100; ++f) if (auto s = sim->step(); !s) ...;
//   std::vector<float> x; sim->read_positions(x);
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sinew/device.h"
#include "sinew/divergence.h"
#include "sinew/scene.h"
#include "sinew/graspers.h"
#include "sinew/ids.h"
#include "sinew/needles.h"
#include "sinew/saved_state.h"
#include "sinew/scene_fluid.h"
#include "sinew/tools.h"
#include "sinew/topology.h"
#include "sinew/warnings.h"

namespace sinew {


/// What a compiled scene holds; fixed for the life of a Simulation.
struct SceneInfo {
  std::uint32_t particles = 0;             ///< particles of every body (tet, tri and line bodies' vertices)
  std::uint32_t distance_constraints = 0;  ///< edge (and thread segment) distance constraints
  std::uint32_t volume_constraints = 0;    ///< tet volume constraints
  std::uint32_t distance_colors = 0;  ///< colours of the distance constraints
  std::uint32_t volume_colors = 0;    ///< colours of the volume constraints
  std::uint32_t other_constraints = 0;  ///< every other kind (FEM tets, thin bodies, contacts, attachments)
  std::uint32_t colors = 0;           ///< dependent sweeps per iteration (sum of the above)
  std::uint32_t dispatches_per_frame = 0;  ///< kernel dispatches in one frame's program
  std::uint32_t barriers_per_frame = 0;    ///< barriers between dependent dispatches in one frame's program
  std::vector<std::uint32_t> tet_body_first_particle;   ///< body i's vertex 0 is this particle
  std::vector<std::uint32_t> tri_body_first_particle;   ///< as tet_body_first_particle, for tri bodies
  std::vector<std::uint32_t> line_body_first_particle;  ///< as tet_body_first_particle, for line bodies
  /// Mesh self-collision: pairs of a body's triangles closer than the
  /// thickness in the starting shape, which never make contacts with each
  /// other (MeshCollisionDesc::self_collision).
  std::uint32_t rest_close_triangle_pairs = 0;
  /// All constraints of the bodies: distance + volume + other.
  [[nodiscard]] std::uint32_t constraints() const {
    return distance_constraints + volume_constraints + other_constraints;
  }
};

/// How the last frame's sweeps ended (SolverSettings::residual_tolerance).
enum class SolveStop {
  fixed,          ///< fixed mode: `iterations` sweeps per substep
  converged,      ///< residual mode: every substep's residual reached the tolerance
  iteration_cap,  ///< residual mode: a substep ran max_iterations sweeps without converging
  time_budget,    ///< residual mode: a substep stopped at its share of time_budget_ms
};

/// Timing and error of the last frame. The errors are measured when
/// SolverSettings::measure_errors is set (the default), else left at 0.
/// They are reduced on the device at the end of the frame's program, in a
/// fixed order and about 48-bit precision, so every backend reports the
/// same numbers and only a few words come back (read_back_bytes).
/// One stage of the frame (a feature of the runtime: "colliders and tools",
/// "mesh collision", "continuous collision", "sutures", "solve",
/// "statistics", "tearing", ...; only those the scene uses).
struct StageProfile {
  std::string name;  ///< the stage's name, e.g. "mesh collision"
  double ms = 0.0;  ///< wall time of the stage's work in the last step() [ms]
  /// The stage's own figures of the last step(), by name (the units in the
  /// name: "margin_m"); FrameStats::counter reads one. A counter
  /// "X_capacity" is the capacity of counter "X" (warned near it:
  /// sinew/warnings.h). Mesh collision: contacts, colors, pairs,
  /// pairs_capacity, margin_m, violation_m (FrameStats::contact_violation),
  /// self_violation_m and tool_violation_m (the same over a body's contacts
  /// with itself, and over faces' and segments' contacts with the rigid
  /// tools); continuous collision: hits,
  /// repairs, reverted, carried, forced; sutures: host_ms; fluid:
  /// particles, particles_capacity, steps.
  struct Counter {
    std::string name;    ///< e.g. "contacts", "margin_m"
    double value = 0.0;  ///< its value in the last step()
  };
  std::vector<Counter> counters;  ///< the stage's counters, in the order they were first set
  /// Sets counter `name` (added the first time).
  void set(std::string_view counter, double value);
};

/// What the last frame did and cost: its time, the solver's errors (residuals,
/// energy, volume change), contacts, continuous collision, device times and
/// the profile of each stage (Simulation::last_frame).
struct FrameStats {
  std::uint64_t frame = 0;  ///< frames done
  double time = 0.0;        ///< simulated time [s]
  double wall_ms = 0.0;     ///< wall time of the last step() [ms]: the frame program (solve and the
                            ///< reductions of the statistics) run and waited for, and measure_ms
  double measure_ms = 0.0;  ///< of which reading back and combining the statistics [ms]
  /// Read-backs of all particles' positions by the frame's stages (mesh
  /// collision, sutures, tearing share one, read at most once between two
  /// changes of the positions; 0 in a frame that needs none). Continuous
  /// collision's reads inside the solve are not among them (read_back_bytes
  /// counts them).
  std::uint32_t position_reads = 0;
  /// Bytes the host read from the device in the last step(), as the device
  /// counted them (every backend alike): the statistics' few words; with
  /// mesh collision, needles or tearing, the positions once (16 per
  /// particle, position_reads); 32 per contact when a tool has face
  /// contacts; 96 per suture row; with continuous collision, 32 per
  /// particle per substep and 16 per particle per repair round more. Each
  /// stage's share is its profile's counter "read_bytes".
  std::uint64_t read_back_bytes = 0;
  std::uint32_t host_reads = 0;  ///< read-backs (round trips) in the last step()
  /// Times the last step() blocked on the device: every read-back, and
  /// every wait for a submitted program (each stage's share: its counter
  /// "host_waits"). A frame that runs wholly on the device waits once: its
  /// statistics come back with the program's end.
  std::uint32_t host_waits = 0;
  /// RMS over all constraints of |C + alpha~ lambda| at the start of the
  /// frame's last sweep, each normalised by its rest value (rest length,
  /// rest volume, ...): 0 when the xPBD system is solved exactly. Contact
  /// and attachment residuals have no rest value and count in metres.
  double residual_rms = 0.0;
  double max_residual = 0.0;     ///< the largest of those normalised residuals
  double kinetic_energy = 0.0;   ///< sum of m |v|^2 / 2 over movable particles [J]
  /// Total tet volume / rest total - 1 (0 without tet bodies), measured
  /// inside the bodies' boundary surfaces; after topology changes
  /// (remove_tets, cuts, tears, cautery) the live tets' boundaries and rest
  /// volume.
  double volume_change = 0.0;
  /// Tets whose signed volume is negative at the frame's end (turned inside
  /// out), over the tet bodies' live tets; reduced on the device with the
  /// errors (0 with measure_errors off).
  std::uint32_t inverted_tets = 0;
  /// Gauss-Seidel sweeps (iterations) run in the last frame, over all its substeps.
  std::uint64_t sweeps = 0;
  /// How the sweeps ended; in residual mode the worst substep's reason
  /// (time_budget over iteration_cap over converged).
  SolveStop stop = SolveStop::fixed;
  /// Residual mode: RMS normalised residual at the last check of the
  /// frame's last substep (what the tolerance was compared with; the same
  /// measure as residual_rms, also when measure_errors is off). 0 in fixed mode.
  double checked_residual = 0.0;
  std::uint32_t residual_checks = 0;  ///< residual mode: checks in the last frame (a program each, its residuals brought back by its wait)
  /// Residual mode with SolverSettings::warm_start: substeps of the last
  /// frame whose lambdas were not carried into the next substep (or
  /// frame), because the substep ended at max_iterations with a residual no
  /// lower than at its first check (not converging: carried on, such
  /// lambdas diverged) — the time budget's stops are not counted.
  std::uint32_t dropped_warm_starts = 0;
  /// Whether the last frame's solve converged: every substep's residual
  /// reached SolverSettings::residual_tolerance. Always false in fixed mode
  /// (no residual is checked there; residual_rms says how far it was).
  [[nodiscard]] bool converged() const { return stop == SolveStop::converged; }

  // ---- Per-feature figures, kept for one release: each is also a counter
  // of its stage (StageProfile::counters, FrameStats::counter), where new
  // figures go.
  /// Mesh collision (SceneDesc::mesh_collision), 0 without: the frame's
  /// contacts, their colours (dispatches per sweep), the motion margin they
  /// were found within [m], and the wall time [ms] of reading the
  /// particles back, finding, colouring and uploading them (part of wall_ms).
  std::uint32_t mesh_contacts = 0;
  /// Colours the contacts took: with ContactSchedule::device_colored the
  /// device's colours below the cap that hold contacts (counted on the
  /// device, brought back by the frame's wait), the overflow set not
  /// included; 0 with ContactSchedule::jacobi.
  std::uint32_t mesh_contact_colors = 0;
  /// ContactSchedule::device_colored: the contacts of the overflow set
  /// (solved one after another after the colours); 0 otherwise.
  std::uint32_t mesh_contact_overflow = 0;
  double collision_margin = 0.0;  ///< the motion margin the mesh contacts were found within [m]
  double collision_ms = 0.0;      ///< reading back, finding, colouring and uploading the mesh contacts [ms]
  /// The deepest any of the frame's mesh contacts ended inside the
  /// thickness [m], max(thickness - gap) at the frame's end (0 when none
  /// touches): how well the sweeps converged on the contacts.
  double contact_violation = 0.0;
  /// Continuous collision detection (MeshCollisionDesc::continuous), 0
  /// without: pairs of primitives found touching in the frame's substeps
  /// (each round's touches counted), the repair rounds run, the particles
  /// the fail-safe stopped at their substep's start, and the wall time
  /// [ms] of the tests (read-back, broad phase, queries; part of wall_ms).
  std::uint32_t ccd_hits = 0;      ///< touching pairs found in the frame's substeps
  std::uint32_t ccd_repairs = 0;   ///< repair rounds run
  std::uint32_t ccd_reverted = 0;  ///< particles the fail-safe stopped at their substep's start
  /// The particles the fail-safe moved with a tool or capsule collider
  /// (rigidly, over their substep) so its axis could not cross them.
  std::uint32_t ccd_carried = 0;
  /// Touching pairs the fail-safe could not act on, let through: a tool
  /// or capsule collider forcing tissue it carries, or pinned tissue,
  /// through other tissue (it is kinematic within the frame). 0 but for such
  /// scenes.
  std::uint32_t ccd_forced = 0;
  double ccd_ms = 0.0;  ///< wall time of the continuous collision tests [ms] (part of wall_ms)
  /// Needles (SceneDesc::needles), 0 without: the wall time [ms] of their
  /// host side, before the frame (reading the positions back, testing the
  /// tips' paths against the surfaces, uploading the rows) and after it
  /// (reading the rows back, making and ending punctures); part of wall_ms.
  double suture_ms = 0.0;
  /// Device time of the frame's program per kernel (stage) and in all, from
  /// GPU timestamps; timed = false on backends that record none (see DeviceTimes).
  DeviceTimes device;
  /// The divergence checks' verdict on the last frame and what the policy
  /// did (sinew/divergence.h; Simulation::set_divergence_settings).
  DivergenceReport divergence;
  /// The frame's stages in the order they run, each with its wall time in
  /// the last step() (their sum is within wall_ms).
  std::vector<StageProfile> stages;
  /// The wall time [ms] of stage `name` in the last step() (0 when the scene has no such stage).
  [[nodiscard]] double stage_ms(std::string_view name) const;
  /// Counter `counter` of stage `stage` in the last step() (StageProfile::
  /// counters; 0 when there is no such stage or counter).
  [[nodiscard]] double counter(std::string_view stage, std::string_view counter) const;
};

/// A scene compiled onto a device: created from a SceneDesc, stepped frame by
/// frame, read back, and reached through the feature handles (tools(),
/// graspers(), needles(), topology(), fluid()). Movable, not copyable; a
/// handle is valid while its Simulation is neither destroyed nor moved.
class Simulation {
 public:
  /// Checks and compiles the scene and prepares it on a device. Errors name
  /// the bad parameter, or say why the backend is not available.
  static Result<Simulation> create(const SceneDesc& scene, const DeviceOptions& device = {});

  /// Moves the scene and its device; handles of the moved-from Simulation become invalid.
  ///@{
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;
  ///@}
  ~Simulation();

  /// Advances one frame (SolverSettings::time_step), then checks it for
  /// divergence (sinew/divergence.h): with OnDivergence::stop a diverged
  /// frame returns ErrorCode::diverged, with roll_back the scene goes back
  /// to the last good frame.
  Status step();

  /// [in] settings: the divergence checks' bounds and policy, from the next
  /// step() on. With OnDivergence::roll_back the current state is saved at
  /// once (the first frame to roll back to). Errors (bad_parameter, nothing
  /// changed): energy_growth not > 1, floor_speed < 0, max_volume_change
  /// not > 0 or checkpoint_every 0 (each named); a device error saving the first checkpoint.
  Status set_divergence_settings(const DivergenceSettings& settings);
  [[nodiscard]] const DivergenceSettings& divergence_settings() const;
  /// [in] settings: the per-frame warnings' thresholds (sinew/warnings.h),
  /// from the next step() on. Errors (bad_parameter, nothing changed):
  /// frame_budget_ms < 0, repeat_seconds not > 0, capacity_fraction outside
  /// (0, 1], or a non-finite value, each named.
  Status set_warning_settings(const WarningSettings& settings);
  [[nodiscard]] const WarningSettings& warning_settings() const;

  /// [out] out: the state after the last frame (sinew/saved_state.h), its
  /// bytes replaced (their capacity reused: saving every frame allocates
  /// nothing after the first). Reads the particles' buffers and multipliers
  /// back from the device (and a fluid's particles and grid, and the level
  /// sets a cut can change). Errors: a device error.
  Status save_state(SavedState& out);
  /// [in] state: from save_state of this scene (this Simulation, or one made
  /// from the same SceneDesc); the next step() continues from it bitwise as
  /// the run it was saved from, across topology changes and level-set cuts
  /// made before or after the save: the state's changes this Simulation has
  /// not made are replayed, and a Simulation that has made others (or more)
  /// is made again from its SceneDesc first (a new device; its ids and
  /// handles stay valid, references returned before by info(),
  /// last_frame(), last_tears() and the settings' getters do not;
  /// sinew/saved_state.h). Errors, leaving the
  /// Simulation unchanged: bad_input_file for a damaged or foreign state,
  /// bad_parameter for another scene's state (naming what differs), a state
  /// of format version 3 or older saved after a topology change, or one
  /// that needs the Simulation made again when it was made on a device
  /// given to it; the errors of Simulation::create when it is made again.
  Status restore_state(const SavedState& state);
  /// save_state to a file [in] path (replaced). Errors as save_state's and SavedState::write_file's.
  Status save_state(const std::string& path);
  /// restore_state from a file [in] path. Errors as restore_state's and SavedState::read_file's.
  Status restore_state(const std::string& path);

  /// [out] xyzw per particle: position [m] and inverse mass [1/kg] in w.
  Status read_positions(std::vector<float>& xyzw) const;
  /// [out] xyz0 per particle: velocity [m/s], w unused.
  Status read_velocities(std::vector<float>& xyzw) const;

  /// Forces [N] on the scene's particles (3 floats x, y, z per particle, in
  /// the particle order of read_positions), acting during the next frame
  /// (every substep), then reset to zero; calls before one step replace the
  /// previous call's forces. Each substep adds the impulse h f / m to a
  /// particle's velocity before predicting its position, so the impulse
  /// passes through the substep's velocity damping (the bodies'
  /// velocity_damping k: a factor exp(-k h)) like any velocity, unlike
  /// gravity's; pinned and kinematic particles (mass 0) ignore their force.
  /// Costs an upload of 16 bytes per particle per call, and one more in the
  /// first frame without a call after one (resetting them).
  /// Needs SceneDesc::external_forces (else an error naming it). Errors
  /// (bad_parameter): a span whose size is not 3 x particles, a non-finite
  /// value, or one whose velocity over a frame (time_step f / m) or move
  /// (time_step^2 f / m) is not finite in float32, the device's precision
  /// (naming the particle); the forces set before stay then.
  Status set_particle_forces(std::span<const float> xyz);

  // ---- Features, each behind its own handle and header (a view of this
  // Simulation: valid while it is neither destroyed nor moved), with typed
  // ids (sinew/ids.h).

  /// Tools, colliders and kinematic targets (sinew/tools.h).
  [[nodiscard]] Tools tools();
  /// Graspers (sinew/graspers.h).
  [[nodiscard]] Graspers graspers();
  /// Needles and sutures (sinew/needles.h).
  [[nodiscard]] Needles needles();
  /// Topology changes: removals, cuts, cautery, tears (sinew/topology.h).
  [[nodiscard]] Topology topology();

  /// The scene's fluid (SceneDesc::fluid; sinew/scene_fluid.h): its
  /// particles, counts, emitters and sinks. Calls on it are errors when
  /// the scene has none.
  [[nodiscard]] SceneFluid fluid();

  /// What the compiled scene holds (fixed for the Simulation's life).
  [[nodiscard]] const SceneInfo& info() const;
  /// The last step()'s figures (default values before the first step()).
  [[nodiscard]] const FrameStats& last_frame() const;
  /// The backend running the scene: "cpu", "opencl" or "vulkan".
  [[nodiscard]] std::string backend_name() const;
  /// Its device, e.g. "CPU reference (2 threads, AVX2)" or "Vulkan: NVIDIA H100 (discrete GPU, ...)".
  [[nodiscard]] std::string device_name() const;

  /// Deprecated: the calls by raw index, kept for one release. Each does
  /// what its replacement, named in its deprecation message, does (the
  /// feature headers document them).
  ///@{
  using TopologyEvent = sinew::TopologyEvent;
  using Blade = sinew::Blade;
  using HeldPoint = sinew::HeldPoint;
  using ToolState = sinew::ToolState;
  using Puncture = sinew::Puncture;
  using NeedleState = sinew::NeedleState;
  [[deprecated("use tools().set_pose(ColliderId, ...)")]] Status set_collider_pose(std::size_t index, const std::array<double, 3>& position,
                                                               const std::array<double, 4>& rotation);
  [[deprecated("use tools().set_position(TargetId, ...)")]] Status set_target(std::size_t index, const std::array<double, 3>& position);
  [[deprecated("use tools().apply_force(ToolId, ...)")]] Status apply_tool_force(std::size_t index, const std::array<double, 3>& force,
                                                             const std::array<double, 3>& torque);
  [[deprecated("use tools().state(ToolId)")]] Result<ToolState> tool_state(std::size_t index) const;
  [[deprecated("use tools().cut(ColliderId, ...)")]] Result<CutReport> cut_collider(std::size_t index, const CutterShape& shape,
                                                                const Pose& from, const Pose& to);
  [[deprecated("use topology().remove_tets(TetBodyId, ...)")]] Result<TopologyEvent> remove_tets(std::size_t body,
                                                                              std::span<const std::uint32_t> tets);
  [[deprecated("use topology().remove_triangles(TriBodyId, ...)")]] Result<TopologyEvent> remove_triangles(
      std::size_t body, std::span<const std::uint32_t> triangles);
  [[deprecated("use topology().cut(TetBodyId or TriBodyId, ...)")]] Result<TopologyEvent> cut_body(BodyKind kind, std::size_t body,
                                                                                 const Blade& from, const Blade& to);
  [[deprecated("use topology().cut(TetBodyId, ...)")]] Result<TopologyEvent> cut_body(std::size_t body, const Blade& from,
                                                                    const Blade& to);
  [[deprecated("use topology().cauterize(TetBodyId or TriBodyId, ...)")]] Result<TopologyEvent> cauterize(
      BodyKind kind, std::size_t body, const std::array<double, 3>& centre, double radius, double seconds,
      double dwell_time);
  [[deprecated("use topology().cauterize(TetBodyId, ...)")]] Result<TopologyEvent> cauterize(std::size_t body,
                                                                           const std::array<double, 3>& centre,
                                                                           double radius, double seconds,
                                                                           double dwell_time);
  [[deprecated("use topology().remove_segments(LineBodyId, ...)")]] Result<TopologyEvent> remove_segments(
      std::size_t body, std::span<const std::uint32_t> segments);
  [[deprecated("use topology().last_tears()")]] [[nodiscard]] const std::vector<TopologyEvent>& last_tears() const;
  [[deprecated("use topology().current_tets(TetBodyId)")]] Result<std::vector<std::array<std::uint32_t, 4>>> current_tets(
      std::size_t body) const;
  [[deprecated("use topology().current_triangles(TriBodyId)")]] Result<std::vector<std::array<std::uint32_t, 3>>> current_triangles(
      std::size_t body) const;
  [[deprecated("use graspers().close(GrasperId, ...)")]] Result<std::vector<std::uint32_t>> close_grasper(
      std::size_t index, const Pose& pose, const std::array<double, 3>& half_extents);
  [[deprecated("use graspers().held_points(GrasperId)")]] Result<std::vector<HeldPoint>> held_points(std::size_t index) const;
  [[deprecated("use graspers().move(GrasperId, ...)")]] Status move_grasper(std::size_t index, const Pose& pose);
  [[deprecated("use graspers().open(GrasperId)")]] Result<std::vector<std::uint32_t>> open_grasper(std::size_t index);
  [[deprecated("use needles().set_pose(NeedleId, ...)")]] Status set_needle_pose(std::size_t index, const std::array<double, 3>& position,
                                                             const std::array<double, 4>& rotation);
  [[deprecated("use needles().apply_force(NeedleId, ...)")]] Status apply_needle_force(std::size_t index,
                                                                   const std::array<double, 3>& force,
                                                                   const std::array<double, 3>& torque);
  [[deprecated("use needles().state(NeedleId)")]] Result<NeedleState> needle_state(std::size_t index) const;
  ///@}

  /// The library's own state behind a Simulation (src/runtime/simulation_impl.h; incomplete here, named so
  /// that the frame's stages, src/runtime/stages/, can refer to it).
  struct Impl;

 private:
  friend struct SimulationInternals;  // the library's own access (src/runtime/simulation_internals.h)
  friend class Tools;
  friend class Graspers;
  friend class Needles;
  friend class Topology;
  explicit Simulation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sinew
