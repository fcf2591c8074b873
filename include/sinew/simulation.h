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
#include <vector>

#include "sinew/device.h"
#include "sinew/scene.h"

namespace sinew {


/// What a compiled scene holds; fixed for the life of a Simulation.
struct SceneInfo {
  std::uint32_t particles = 0;
  std::uint32_t distance_constraints = 0;
  std::uint32_t volume_constraints = 0;
  std::uint32_t distance_colors = 0;  ///< colours of the distance constraints
  std::uint32_t volume_colors = 0;    ///< colours of the volume constraints
  std::uint32_t other_constraints = 0;  ///< every other kind (FEM tets, thin bodies, contacts, attachments)
  std::uint32_t colors = 0;           ///< dependent sweeps per iteration (sum of the above)
  std::uint32_t dispatches_per_frame = 0;
  std::uint32_t barriers_per_frame = 0;
  std::vector<std::uint32_t> tet_body_first_particle;   ///< body i's vertex 0 is this particle
  std::vector<std::uint32_t> tri_body_first_particle;
  std::vector<std::uint32_t> line_body_first_particle;
  /// Mesh self-collision: pairs of a body's triangles closer than the
  /// thickness in the starting shape, which never make contacts with each
  /// other (MeshCollisionDesc::self_collision).
  std::uint32_t rest_close_triangle_pairs = 0;
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
  std::string name;
  double ms = 0.0;  ///< wall time of the stage's work in the last step() [ms]
};

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
  std::uint64_t read_back_bytes = 0;  ///< bytes the host read from the device in the last step():
                                      ///< the statistics' few words; with mesh collision, needles or
                                      ///< tearing, the positions once (16 per particle, position_reads);
                                      ///< 32 per contact when a tool has face contacts; 96 per suture
                                      ///< row; with continuous collision, 32 per particle per substep
                                      ///< and 16 per particle per repair round more
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
  /// Gauss-Seidel sweeps (iterations) run in the last frame, over all its substeps.
  std::uint64_t sweeps = 0;
  /// How the sweeps ended; in residual mode the worst substep's reason
  /// (time_budget over iteration_cap over converged).
  SolveStop stop = SolveStop::fixed;
  /// Residual mode: RMS normalised residual at the last check of the
  /// frame's last substep (what the tolerance was compared with; the same
  /// measure as residual_rms, also when measure_errors is off). 0 in fixed mode.
  double checked_residual = 0.0;
  std::uint32_t residual_checks = 0;  ///< residual mode: checks (round trips) in the last frame
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
  /// Mesh collision (SceneDesc::mesh_collision), 0 without: the frame's
  /// contacts, their colours (dispatches per sweep), the motion margin they
  /// were found within [m], and the wall time [ms] of reading the
  /// particles back, finding, colouring and uploading them (part of wall_ms).
  std::uint32_t mesh_contacts = 0;
  std::uint32_t mesh_contact_colors = 0;  ///< 0 with ContactSchedule::jacobi
  double collision_margin = 0.0;
  double collision_ms = 0.0;
  /// The deepest any of the frame's mesh contacts ended inside the
  /// thickness [m], max(thickness - gap) at the frame's end (0 when none
  /// touches): how well the sweeps converged on the contacts.
  double contact_violation = 0.0;
  /// Continuous collision detection (MeshCollisionDesc::continuous), 0
  /// without: pairs of primitives found touching in the frame's substeps
  /// (each round's touches counted), the repair rounds run, the particles
  /// the fail-safe stopped at their substep's start, and the wall time
  /// [ms] of the tests (read-back, broad phase, queries; part of wall_ms).
  std::uint32_t ccd_hits = 0;
  std::uint32_t ccd_repairs = 0;
  std::uint32_t ccd_reverted = 0;
  /// The particles the fail-safe moved with a tool or capsule collider
  /// (rigidly, over their substep) so its axis could not cross them.
  std::uint32_t ccd_carried = 0;
  /// Touching pairs the fail-safe could not act on, let through: a tool
  /// or capsule collider forcing tissue it carries, or pinned tissue,
  /// through other tissue (it is kinematic within the frame). 0 but for such
  /// scenes.
  std::uint32_t ccd_forced = 0;
  double ccd_ms = 0.0;
  /// Needles (SceneDesc::needles), 0 without: the wall time [ms] of their
  /// host side, before the frame (reading the positions back, testing the
  /// tips' paths against the surfaces, uploading the rows) and after it
  /// (reading the rows back, making and ending punctures); part of wall_ms.
  double suture_ms = 0.0;
  /// Device time of the frame's program per kernel (stage) and in all, from
  /// GPU timestamps; timed = false on backends that record none (see DeviceTimes).
  DeviceTimes device;
  /// The frame's stages in the order they run, each with its wall time in
  /// the last step() (their sum is within wall_ms).
  std::vector<StageProfile> stages;
};

class Simulation {
 public:
  /// Checks and compiles the scene and prepares it on a device. Errors name
  /// the bad parameter, or say why the backend is not available.
  static Result<Simulation> create(const SceneDesc& scene, const DeviceOptions& device = {});

  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;
  ~Simulation();

  /// Advances one frame (SolverSettings::time_step).
  Status step();

  /// [out] xyzw per particle: position [m] and inverse mass [1/kg] in w.
  Status read_positions(std::vector<float>& xyzw) const;
  /// [out] xyz0 per particle: velocity [m/s], w unused.
  Status read_velocities(std::vector<float>& xyzw) const;

  /// Moves collider `index` to this pose [m, unit quaternion (w, x, y, z)]
  /// by the end of the next frame; its substeps interpolate the motion.
  Status set_collider_pose(std::size_t index, const std::array<double, 3>& position,
                           const std::array<double, 4>& rotation);
  /// Moves kinematic target `index` to `position` [m] by the end of the next frame.
  Status set_target(std::size_t index, const std::array<double, 3>& position);
  /// Force [N] and torque [N m] (world frame, about the tool's centre)
  /// acting on tool `index` during the next frame (then reset to zero);
  /// calls before one step add up.
  Status apply_tool_force(std::size_t index, const std::array<double, 3>& force, const std::array<double, 3>& torque);

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
  /// value (naming the particle); the forces set before stay then.
  Status set_particle_forces(std::span<const float> xyz);

  /// Cuts level-set collider `index` (ColliderShape::level_set, built with
  /// its whole inside stored): LevelSet::cut with the tool's poses in the
  /// collider's frame. The collider's grid changes (and every LevelSet
  /// sharing it), and so does the device's copy, by the changed leaves,
  /// before this returns: the next step collides with the cut shape.
  /// Errors: not a level-set collider; LevelSet::cut's.
  Result<CutReport> cut_collider(std::size_t index, const CutterShape& shape, const Pose& from, const Pose& to);

  // ---- Topology changes (SceneDesc::topology_changes; runtime/topology_editor.h)
  //
  // Elements (a tet body's tets, a tri body's triangles) are removed, never
  // split: what is left is whole original elements, so no sliver is ever
  // made (the smallest element keeps its rest volume or area). A removed
  // element's own constraints go (volume and FEM; area), and so do the
  // distance constraints of edges no remaining element has and, on a tri
  // body, the dihedral (bending) constraints of the hinges it was part of;
  // an edge that keeps some of its elements is made softer by the share it
  // lost (alpha_e = c_d L^2 / V_e, TetBodyDesc; c_d L^2 / (A_e t),
  // TriBodyDesc). Each removed constraint's colour gives its last
  // constraint the slot, so every colour stays valid and only the changed
  // slots are uploaded; the frame program is rebuilt with the new counts.
  // A vertex left with no element is fixed (inverse mass 0) and its mass
  // handed to the movable vertices it shared a removed element with, or
  // else to the nearest live movable vertex of its body; cuts and tears
  // conserve the total mass unless nothing movable is left to take it
  // (then it is mass_removed). Cautery burns its elements' mass away.
  // Events are returned, for a renderer to update its meshes
  // (current_tets, current_triangles). Errors in the arguments change
  // nothing; a device error during a change leaves the Simulation unusable.

  /// What one change did to body `body` (a tet body, a tri body, or a line
  /// body whose segments broke: body_kind).
  struct TopologyEvent {
    BodyKind body_kind = BodyKind::tet;
    std::size_t body = 0;
    std::vector<std::uint32_t> tets_removed;      ///< a tet body's: indices into its mesh.tets
    std::vector<std::uint32_t> triangles_removed; ///< a tri body's: indices into its mesh.triangles
    std::vector<std::uint32_t> segments_removed;  ///< a line body's: indices into its segments
    std::vector<std::uint32_t> vertices_removed;  ///< movable vertices left with no element (now fixed and massless)
    std::uint32_t constraints_removed = 0;  ///< volume, FEM, area, distance and bending constraints taken out
    std::uint32_t edges_softened = 0;       ///< distance constraints whose compliance grew
    double mass_moved = 0.0;    ///< [kg] handed from removed vertices to their neighbours
    double mass_removed = 0.0;  ///< [kg] that left the scene (burned, or no neighbour left)
    double wall_ms = 0.0;       ///< host and device time of the change, the program rebuilt included
    double rebuild_ms = 0.0;    ///< of which rebuilding the frame program
  };
  /// Removes tets of tet body `body` (indices into its mesh.tets, each
  /// alive, no repeats). Errors: topology changes not enabled, a bad body
  /// or tet (named); on an error nothing changed.
  Result<TopologyEvent> remove_tets(std::size_t body, std::span<const std::uint32_t> tets);
  /// Removes triangles of tri body `body` (indices into its mesh.triangles,
  /// each alive, no repeats). Errors as remove_tets'.
  Result<TopologyEvent> remove_triangles(std::size_t body, std::span<const std::uint32_t> triangles);
  /// A blade: the segment from `a` to `b` [m].
  struct Blade {
    std::array<double, 3> a{}, b{};
  };
  /// Cuts body `body` of `kind` (tet or tri) with a blade swept from `from`
  /// to `to` (the quad they span, two triangles): every live tet or
  /// triangle the swept quad touches at the body's current positions is
  /// removed (mass as above). A sheet cut in its own plane loses the
  /// triangles the quad overlaps. The query sees the tissue where it is
  /// now: tissue moving across the blade's path between strokes can slip
  /// past uncut, so strokes along a line should overlap
  /// (examples/cholecystectomy.cpp).
  Result<TopologyEvent> cut_body(BodyKind kind, std::size_t body, const Blade& from, const Blade& to);
  /// cut_body(BodyKind::tet, body, from, to).
  Result<TopologyEvent> cut_body(std::size_t body, const Blade& from, const Blade& to);
  /// A heated tip (a ball of `radius` [m] at `centre` [m]) touching body
  /// `body` of `kind` (tet or tri) for `seconds` [s] (> 0): a live element
  /// whose current centroid lies in the ball accumulates that time, and is
  /// burned (removed with its mass) once it has been touched for
  /// dwell_time [s] (> 0) in all. The rate: the ball's volume inside a tet
  /// body (its disc's area across a sheet) goes every dwell_time.
  Result<TopologyEvent> cauterize(BodyKind kind, std::size_t body, const std::array<double, 3>& centre, double radius,
                                  double seconds, double dwell_time);
  /// cauterize(BodyKind::tet, body, ...).
  Result<TopologyEvent> cauterize(std::size_t body, const std::array<double, 3>& centre, double radius,
                                  double seconds, double dwell_time);
  /// Breaks segments of line body `body` (indices into its segments, each
  /// whole, no repeats): their distance constraints go, with the bending
  /// constraints across them (a thread cut with scissors). Errors as
  /// remove_tets'.
  Result<TopologyEvent> remove_segments(std::size_t body, std::span<const std::uint32_t> segments);
  /// What tore in the last step() (TetBodyDesc::tear_strain,
  /// TriBodyDesc::tear_strain, LineBodyDesc::tear_strain), one event per
  /// body that tore.
  [[nodiscard]] const std::vector<TopologyEvent>& last_tears() const;
  /// The live tets of tet body `body` (indices into its mesh.tets, as
  /// tets; the vertices are the mesh's): its current topology, for
  /// extract_boundary_surface. Errors: a bad body.
  Result<std::vector<std::array<std::uint32_t, 4>>> current_tets(std::size_t body) const;
  /// The live triangles of tri body `body` (as triangles of its mesh's
  /// vertices): its current surface, for a renderer. Errors: a bad body.
  Result<std::vector<std::array<std::uint32_t, 3>>> current_triangles(std::size_t body) const;

  // ---- Graspers (SceneDesc::graspers; runtime/graspers.h)

  /// Closes grasper `index` at `pose` [m, unit quaternion (w, x, y, z)]: every
  /// movable particle (of any body) inside the jaws, the box of
  /// `half_extents` [m] (> 0) centred on the pose in its frame, is held
  /// where it is now, at a point fixed in the grasper's frame. So is every
  /// surface triangle (a tet body's boundary face, a tri body's triangle)
  /// that crosses the box with none of its vertices inside it: at its
  /// point nearest the pose's position, through its barycentric weights
  /// (a coarse mesh grasped between its vertices; held_points lists them).
  /// Of such triangles sharing a vertex only the one whose point is
  /// nearest is held (a point's vertices move with it; two points on one
  /// vertex would fight over it within one colour). Returns the held
  /// particles (the user's order, as read_positions). Errors: a bad index,
  /// pose or box; closed already; more particles than its capacity, or
  /// points than its point_capacity (capacity_exceeded, nothing held).
  Result<std::vector<std::uint32_t>> close_grasper(std::size_t index, const Pose& pose,
                                                   const std::array<double, 3>& half_extents);
  /// A surface point a grasper holds: sum weights[k] x[particles[k]].
  struct HeldPoint {
    std::array<std::uint32_t, 3> particles{};  ///< the triangle's particles (user order)
    std::array<double, 3> weights{};           ///< barycentric, each in [0, 1], summing to 1
  };
  /// The surface points grasper `index` holds (none while open). Errors: a bad index.
  Result<std::vector<HeldPoint>> held_points(std::size_t index) const;
  /// Moves grasper `index` to `pose` by the end of the next frame (its held
  /// particles' targets move across the frame's substeps). Errors: a bad
  /// index or pose.
  Status move_grasper(std::size_t index, const Pose& pose);
  /// Opens grasper `index`: what it held is free from the next frame on.
  /// Returns the released particles. Errors: a bad index.
  Result<std::vector<std::uint32_t>> open_grasper(std::size_t index);

  /// A tool's state at the end of the last frame.
  struct ToolState {
    std::array<double, 3> position{};          ///< [m]
    std::array<double, 4> rotation{1, 0, 0, 0};  ///< unit quaternion (w, x, y, z)
    std::array<double, 3> velocity{};          ///< [m/s]
    std::array<double, 3> angular_velocity{};  ///< world frame [rad/s]
    std::array<double, 3> contact_force{};     ///< what the tissue pushed the tool with, frame average [N]
    std::array<double, 3> contact_torque{};    ///< about the tool's centre [N m]
    /// A level-set tool's penalty from the colliders and the other tools
    /// (or a capsule tool's from level-set tools), at the start of the last
    /// frame, which it drove (ToolDesc) [N], about its centre [N m].
    std::array<double, 3> penalty_force{};
    std::array<double, 3> penalty_torque{};
    std::uint32_t penalty_points = 0;  ///< a level-set tool's surface points inside other shapes then
    double penalty_depth = 0.0;        ///< the deepest one's depth [m]
  };
  Result<ToolState> tool_state(std::size_t index) const;

  /// Moves kinematic needle `index` to this pose [m, unit quaternion (w, x,
  /// y, z)] by the end of the next frame (NeedleDesc); its substeps
  /// interpolate each of its points linearly. Errors: a force-driven needle.
  Status set_needle_pose(std::size_t index, const std::array<double, 3>& position,
                         const std::array<double, 4>& rotation);
  /// Force [N] and torque [N m] (world frame, about the needle's origin, its
  /// centre of mass) acting on force-driven needle `index` during the next
  /// frame (then reset to zero); calls before one step add up. Errors: a
  /// kinematic needle.
  Status apply_needle_force(std::size_t index, const std::array<double, 3>& force,
                            const std::array<double, 3>& torque);

  /// A tissue point held on a needle or its thread (NeedleDesc).
  struct Puncture {
    BodyKind body_kind = BodyKind::tet;  ///< tet (its boundary surface) or tri
    std::uint32_t body = 0;              ///< index among the scene's bodies of that kind
    /// The triangle: of extract_boundary_surface(mesh) for a tet body, of
    /// mesh.triangles for a tri body.
    std::uint32_t triangle = 0;
    std::array<double, 3> weights{};  ///< barycentric weights of the point on it
    bool exit = false;       ///< made leaving a tet body (else entering a surface)
    bool on_thread = false;  ///< the needle has passed it: it holds the thread
    std::uint32_t thread_segment = 0;  ///< on_thread: the thread's segment through it
    double thread_s = 0.0;             ///< on_thread: where along that segment, in [0, 1]
  };
  /// A needle at the end of the last frame.
  struct NeedleState {
    std::array<double, 3> position{};            ///< [m]
    std::array<double, 4> rotation{1, 0, 0, 0};  ///< unit quaternion (w, x, y, z)
    std::array<double, 3> velocity{};            ///< over the last frame [m/s]
    std::array<double, 3> angular_velocity{};    ///< over the last frame, world frame [rad/s]
    /// What the tissue and the thread did to the needle, averaged over the
    /// last frame: the force [N] of its tip's push, its punctures and its
    /// tie to the thread, and their torque about its origin [N m] (world
    /// frame). Kinematic needles report it too: it is the force to render
    /// on a haptic device.
    std::array<double, 3> reaction_force{}, reaction_torque{};
    std::vector<Puncture> punctures;             ///< in the order they were made
    bool pushing = false;    ///< the tip pushes a surface it has not punctured
    double tip_force = 0.0;  ///< that push, along the tip, averaged over the frame [N]
    /// Since the start: surface triangles the tip met that it could not
    /// puncture because they were degenerate (no area) or inverted (their
    /// tet turned inside out), and frames in which the push passed
    /// puncture_force at more than max_puncture_angle.
    std::uint32_t refused_degenerate = 0, refused_inverted = 0, refused_angle = 0;
  };
  Result<NeedleState> needle_state(std::size_t index) const;

  [[nodiscard]] const SceneInfo& info() const;
  [[nodiscard]] const FrameStats& last_frame() const;
  /// The backend running the scene: "cpu", "opencl" or "vulkan".
  [[nodiscard]] std::string backend_name() const;
  /// Its device, e.g. "CPU reference (2 threads, AVX2)" or "Vulkan: NVIDIA H100 (discrete GPU, ...)".
  [[nodiscard]] std::string device_name() const;

  /// The library's own state behind a Simulation (src/runtime/simulation_impl.h; incomplete here, named so
  /// that the frame's stages, src/runtime/stages/, can refer to it).
  struct Impl;

 private:
  friend struct SimulationInternals;  // the library's own access (src/runtime/simulation_internals.h)
  explicit Simulation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sinew
