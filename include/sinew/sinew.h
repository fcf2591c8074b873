/* sinew/sinew.h — the C API: sinew from C, and from engines (Unity, Unreal,
 * Godot) through their native-plugin interfaces (docs/c_api.md).
 *
 * C99, usable from C and C++. Everything is behind an opaque handle
 * (sinew_simulation*); every call returns a sinew_status and never lets a
 * C++ exception out (the library's errors, and running out of memory,
 * become codes); the last failing call's message on the calling thread is
 * sinew_last_error(). Nothing in this header is inline: every behaviour
 * lives in the library, so a newer libsinew serves a program built against
 * an older header of the same ABI (docs/c_api.md, "ABI rules").
 *
 *   sinew_simulation* sim = NULL;
 *   if (sinew_create_from_file("scenes/tissue_sag.json", "cpu", 0, &sim) != SINEW_OK) {
 *     fprintf(stderr, "%s\n", sinew_last_error());
 *     return 1;
 *   }
 *   for (int f = 0; f < 60; ++f) sinew_step(sim);    (plays the file's script, then steps)
 *   size_t n = 0;
 *   sinew_read_positions(sim, NULL, 0, &n);          (how many particles)
 *   float* xyzw = malloc(16 * n);
 *   sinew_read_positions(sim, xyzw, n, &n);
 *   sinew_destroy(sim);
 *
 * Units are SI (metres, kilograms, seconds, newtons); rotations are unit
 * quaternions (w, x, y, z); vectors are arrays of 3 doubles.
 */
#ifndef SINEW_SINEW_H
#define SINEW_SINEW_H

#include <stddef.h>
#include <stdint.h>

#include "sinew/version.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Exported names: the library is built with default visibility; the macro
 * is here so that a Windows build can give it __declspec later without
 * changing the header's users. */
#ifndef SINEW_C_API
#define SINEW_C_API
#endif

/** What a call did. The values are fixed; new codes are only appended.
 *  SINEW_BAD_PARAMETER .. SINEW_DIVERGED mirror sinew::ErrorCode (result.h). */
typedef enum sinew_status {
  SINEW_OK = 0,                   /**< success */
  SINEW_BAD_PARAMETER = 1,        /**< a value out of its range, non-finite or inconsistent (an index past the scene's objects) */
  SINEW_BAD_INPUT_FILE = 2,       /**< a file could not be read or is malformed (a scene file, a bad JSON string) */
  SINEW_BACKEND_UNAVAILABLE = 3,  /**< the backend is not built, or has no device or driver here */
  SINEW_DEVICE_LOST = 4,          /**< the device stopped working */
  SINEW_OUT_OF_MEMORY = 5,        /**< host or device memory ran out */
  SINEW_CAPACITY_EXCEEDED = 6,    /**< data-dependent work outgrew a declared capacity (e.g. a grasper's) */
  SINEW_INTERNAL = 7,             /**< a bug in sinew, or a device failure with no better description */
  SINEW_DIVERGED = 8,             /**< a frame diverged and the divergence policy is stop */
  SINEW_NULL_ARGUMENT = 100,      /**< a null handle, or a null pointer where one is required */
  SINEW_BUFFER_TOO_SMALL = 101,   /**< a caller's buffer is too small; the needed count was written to *count */
  SINEW_STATUS_MAX_ENUM = 0x7fffffff  /**< (keeps the enum 32 bits wide on every compiler) */
} sinew_status;

/** The kind of a body (sinew::BodyKind). */
typedef enum sinew_body_kind {
  SINEW_BODY_TET = 0,   /**< a volume of tets */
  SINEW_BODY_TRI = 1,   /**< a sheet of triangles (thin tissue) */
  SINEW_BODY_LINE = 2,  /**< a thread of segments */
  SINEW_BODY_KIND_MAX_ENUM = 0x7fffffff
} sinew_body_kind;

/** A scene compiled onto a device, with its script (opaque). */
typedef struct sinew_simulation sinew_simulation;

/* ------------------------------------------------------------ version, errors */

/** The library's version, SINEW_VERSION's number (MAJOR * 10000 + MINOR * 100
 *  + PATCH) as the library was built: compare it with the header's
 *  SINEW_VERSION to detect a program run against another libsinew. */
SINEW_C_API uint32_t sinew_version(void);
/** The library's version as "MAJOR.MINOR.PATCH" (static storage). */
SINEW_C_API const char* sinew_version_string(void);

/** The message of the last call on this thread that did not return SINEW_OK,
 *  e.g. "scene.json: /tet_bodies/0/density: must be finite and > 0 (got -1)";
 *  "" when none has failed. Valid until the next failing call on this thread
 *  (copy it to keep it). Successful calls leave it as it is. */
SINEW_C_API const char* sinew_last_error(void);
/** The code's name, e.g. "bad_input_file" (static storage; "unknown" for a value not listed). */
SINEW_C_API const char* sinew_status_name(sinew_status status);

/* ------------------------------------------------------------ create, destroy */

/** Reads scene file [in] path (docs/scene_files.md; meshes relative to its
 *  folder) and compiles it on [in] backend: "auto", "cpu", "opencl" or
 *  "vulkan"; NULL or "" takes the file's run.backend. [in] threads: the cpu
 *  backend's worker threads (0: all hardware threads; >= 0). [out] out: the
 *  new simulation, NULL on error. Errors: SINEW_BAD_INPUT_FILE and
 *  SINEW_BAD_PARAMETER naming the JSON path, SINEW_BACKEND_UNAVAILABLE. */
SINEW_C_API sinew_status sinew_create_from_file(const char* path, const char* backend, int threads,
                                                sinew_simulation** out);
/** As sinew_create_from_file, from [in] json (the file's text, NUL-terminated);
 *  [in] base_dir resolves relative mesh paths in it (NULL or "": the current
 *  directory). */
SINEW_C_API sinew_status sinew_create_from_json(const char* json, const char* base_dir, const char* backend,
                                                int threads, sinew_simulation** out);
/** Destroys [in] sim and everything it holds (NULL: nothing happens). Always SINEW_OK for a valid handle. */
SINEW_C_API sinew_status sinew_destroy(sinew_simulation* sim);

/** What a simulation holds; fixed for its life. */
typedef struct sinew_scene_info {
  uint32_t struct_size;  /**< [in] sizeof(sinew_scene_info), set by the caller */
  uint32_t particles;    /**< particles of every body (the arrays of sinew_read_positions) */
  uint32_t tet_bodies, tri_bodies, line_bodies;  /**< bodies of each kind */
  uint32_t tools, colliders, targets, graspers, needles;  /**< the scene's objects of each kind */
  uint32_t constraints;  /**< constraints of the bodies */
  uint32_t script_frames;  /**< the file's run.frames (what `sinew run` would run) */
} sinew_scene_info;
/** [out] info (its struct_size set by the caller: the library fills the
 *  fields that fit). Errors: SINEW_NULL_ARGUMENT, SINEW_BAD_PARAMETER for a
 *  struct_size smaller than the first version's struct. */
SINEW_C_API sinew_status sinew_get_scene_info(const sinew_simulation* sim, sinew_scene_info* info);

/** [out] name: the backend running the scene ("cpu", "opencl", "vulkan"),
 *  NUL-terminated, at most [in] capacity bytes with the NUL; a longer name
 *  is SINEW_BUFFER_TOO_SMALL with the bytes needed (NUL included) in *count
 *  (count may be NULL otherwise). */
SINEW_C_API sinew_status sinew_get_backend_name(const sinew_simulation* sim, char* name, size_t capacity,
                                                size_t* count);

/** One body: where its particles and surface triangles are. */
typedef struct sinew_body_info {
  uint32_t struct_size;     /**< [in] sizeof(sinew_body_info), set by the caller */
  uint32_t kind;            /**< sinew_body_kind */
  uint32_t index;           /**< among the scene's bodies of that kind */
  uint32_t first_particle;  /**< its vertex 0 is this particle */
  uint32_t particle_count;  /**< its vertices */
  uint32_t first_triangle;  /**< its surface triangles start here in sinew_read_surface_triangles (now) */
  uint32_t triangle_count;  /**< its surface triangles now (0 for a thread) */
} sinew_body_info;
/** [out] info of body [in] body, numbered over every body: the tet bodies,
 *  then the tri bodies, then the line bodies (sinew_scene_info's counts).
 *  Errors: SINEW_BAD_PARAMETER for a body past them. */
SINEW_C_API sinew_status sinew_get_body_info(sinew_simulation* sim, uint32_t body, sinew_body_info* info);

/* ------------------------------------------------------------ stepping */

/** Advances one frame: first the frame's part of the scene's script, if it
 *  has one and it is playing (sinew_set_script_playing; its poses, forces
 *  and actions of frame f = frames done + 1, as `sinew run` plays them),
 *  then one step. So N calls give, bitwise, the positions `sinew run FILE
 *  --frames N` ends with on the same backend. Errors: the script's or the
 *  step's (SINEW_DIVERGED with the stop policy). */
SINEW_C_API sinew_status sinew_step(sinew_simulation* sim);
/** [in] playing: nonzero (the default) plays the script in sinew_step; 0
 *  leaves every pose, force and action to the caller. Turning it back on
 *  plays on from the frame the simulation has reached (actions of the
 *  frames skipped are not run). */
SINEW_C_API sinew_status sinew_set_script_playing(sinew_simulation* sim, int playing);

/** How the last frame's sweeps ended (sinew::SolveStop). */
typedef enum sinew_solve_stop {
  SINEW_SOLVE_FIXED = 0, SINEW_SOLVE_CONVERGED = 1, SINEW_SOLVE_ITERATION_CAP = 2, SINEW_SOLVE_TIME_BUDGET = 3,
  SINEW_SOLVE_STOP_MAX_ENUM = 0x7fffffff
} sinew_solve_stop;

/** What the last frame did and cost (sinew::FrameStats; simulation.h
 *  documents each figure). All zero before the first step. */
typedef struct sinew_frame_stats {
  uint32_t struct_size;      /**< [in] sizeof(sinew_frame_stats), set by the caller */
  uint32_t stop;             /**< sinew_solve_stop */
  uint64_t frame;            /**< frames done */
  double time;               /**< simulated time [s] */
  double wall_ms;            /**< wall time of the last step [ms] */
  double measure_ms;         /**< of which reading back the statistics [ms] */
  double residual_rms;       /**< RMS normalised constraint residual at the last sweep */
  double max_residual;       /**< the largest normalised residual */
  double kinetic_energy;     /**< [J] */
  double volume_change;      /**< total tet volume / rest - 1 */
  double checked_residual;   /**< residual mode: the residual compared with the tolerance */
  uint64_t sweeps;           /**< Gauss-Seidel sweeps over the frame's substeps */
  uint64_t read_back_bytes;  /**< bytes read back from the device in the step */
  uint32_t inverted_tets;    /**< tets turned inside out at the frame's end */
  uint32_t position_reads;   /**< read-backs of all positions by the frame's stages */
  uint32_t host_reads;       /**< read-backs (round trips) */
  uint32_t host_waits;       /**< times the step blocked on the device */
  uint32_t residual_checks;  /**< residual mode: checks in the frame */
  uint32_t contacts;         /**< mesh collision contacts */
  uint32_t contact_colors;   /**< their colours */
  uint32_t ccd_hits;         /**< continuous collision: touching pairs found */
  uint32_t ccd_repairs;      /**< repair rounds */
  uint32_t ccd_reverted;     /**< particles the fail-safe stopped */
  uint32_t ccd_carried;      /**< particles the fail-safe moved with a tool */
  uint32_t ccd_forced;       /**< touching pairs let through */
  double collision_margin;   /**< [m] */
  double collision_ms;       /**< [ms] */
  double contact_violation;  /**< [m] */
  double ccd_ms;             /**< [ms] */
  double suture_ms;          /**< [ms] */
  double device_ms;          /**< device time of the frame's program [ms] (0 where not timed) */
  uint32_t device_timed;     /**< 1 when the backend recorded timestamps */
  uint32_t divergence;       /**< sinew::Divergence of the frame (0: none) */
  uint64_t diverged_frames;  /**< frames found diverged since creation */
} sinew_frame_stats;
/** [out] stats of the last frame (struct_size set by the caller: the fields that fit are filled). */
SINEW_C_API sinew_status sinew_get_frame_stats(const sinew_simulation* sim, sinew_frame_stats* stats);
/** [out] ms: the wall time of stage [in] stage ("solve", "mesh collision", ...;
 *  docs/frame_stages.md) in the last step, 0 when the scene has no such stage. */
SINEW_C_API sinew_status sinew_get_stage_ms(const sinew_simulation* sim, const char* stage, double* ms);
/** [out] value: counter [in] counter of stage [in] stage in the last step (0 when there is none). */
SINEW_C_API sinew_status sinew_get_stage_counter(const sinew_simulation* sim, const char* stage,
                                                 const char* counter, double* value);

/* ------------------------------------------------------------ reading the bodies
 *
 * Every read takes the caller's buffer, its capacity in records, and
 * [out] count: the records there are. A NULL buffer with capacity 0 asks
 * for the count only (SINEW_OK); a capacity below the count is
 * SINEW_BUFFER_TOO_SMALL with the count written and nothing else. The
 * library never keeps the caller's pointers. */

/** [out] xyzw: 4 floats per particle, the position [m] and the inverse
 *  mass [1/kg] (0: pinned or kinematic), in the order of sinew_body_info's
 *  particles. [in] capacity: particles xyzw holds. */
SINEW_C_API sinew_status sinew_read_positions(sinew_simulation* sim, float* xyzw, size_t capacity, size_t* count);
/** [out] xyzw: 4 floats per particle, the velocity [m/s] and 0. As sinew_read_positions. */
SINEW_C_API sinew_status sinew_read_velocities(sinew_simulation* sim, float* xyzw, size_t capacity, size_t* count);
/** [out] indices: 3 particle indices per triangle (indices into
 *  sinew_read_positions' particles), wound counter-clockwise from outside:
 *  every tet body's live boundary surface, then every tri body's live
 *  triangles, body by body (sinew_body_info says where each starts). After
 *  cuts, tears and cautery it is the surface left. [in] capacity: triangles
 *  indices holds. */
SINEW_C_API sinew_status sinew_read_surface_triangles(sinew_simulation* sim, uint32_t* indices, size_t capacity,
                                                      size_t* count);

/* ------------------------------------------------------------ driving the scene */

/** Forces [N] on the particles during the next frame, then reset: [in]
 *  xyz, 3 floats per particle, [in] particles: the scene's particle count.
 *  Needs the scene's external_forces (else SINEW_BAD_PARAMETER naming it). */
SINEW_C_API sinew_status sinew_set_particle_forces(sinew_simulation* sim, const float* xyz, size_t particles);
/** Moves collider [in] collider to [in] position [m] and [in] rotation
 *  (unit quaternion w, x, y, z) by the end of the next frame. */
SINEW_C_API sinew_status sinew_set_collider_pose(sinew_simulation* sim, uint32_t collider, const double position[3],
                                                 const double rotation[4]);
/** Moves kinematic target [in] target to [in] position [m] by the end of the next frame. */
SINEW_C_API sinew_status sinew_set_target_position(sinew_simulation* sim, uint32_t target, const double position[3]);
/** Force [N] and torque [N m] (world frame, about the tool's centre) on
 *  rigid tool [in] tool during the next frame; calls before one step add up. */
SINEW_C_API sinew_status sinew_apply_tool_force(sinew_simulation* sim, uint32_t tool, const double force[3],
                                                const double torque[3]);

/** A rigid tool at the end of the last frame (sinew::ToolState). */
typedef struct sinew_tool_state {
  uint32_t struct_size;       /**< [in] sizeof(sinew_tool_state), set by the caller */
  uint32_t penalty_points;    /**< a level-set tool's surface points inside other shapes */
  double position[3];         /**< [m] */
  double rotation[4];         /**< unit quaternion (w, x, y, z) */
  double velocity[3];         /**< [m/s] */
  double angular_velocity[3]; /**< world frame [rad/s] */
  double contact_force[3];    /**< what the tissue pushed the tool with, frame average [N] */
  double contact_torque[3];   /**< about the tool's centre [N m] */
  double penalty_force[3];    /**< a level-set tool's penalty [N] */
  double penalty_torque[3];   /**< [N m] */
  double penalty_depth;       /**< the deepest penalty point's depth [m] */
} sinew_tool_state;
/** [out] state of rigid tool [in] tool. */
SINEW_C_API sinew_status sinew_get_tool_state(const sinew_simulation* sim, uint32_t tool, sinew_tool_state* state);

/** Closes grasper [in] grasper at [in] position / [in] rotation on what lies
 *  in the box of [in] half_extents [m] around it (sinew::Graspers::close);
 *  [out] held (may be NULL): the particles it holds. A grasp event follows. */
SINEW_C_API sinew_status sinew_close_grasper(sinew_simulation* sim, uint32_t grasper, const double position[3],
                                             const double rotation[4], const double half_extents[3], size_t* held);
/** Moves closed grasper [in] grasper to the pose by the end of the next frame. */
SINEW_C_API sinew_status sinew_move_grasper(sinew_simulation* sim, uint32_t grasper, const double position[3],
                                            const double rotation[4]);
/** Opens grasper [in] grasper; [out] released (may be NULL): the particles it let go. A release event follows. */
SINEW_C_API sinew_status sinew_open_grasper(sinew_simulation* sim, uint32_t grasper, size_t* released);

/** Cuts body [in] body of kind [in] kind (tet or tri) with the blade
 *  swept from (from_a, from_b) to (to_a, to_b) [m] (sinew::Topology::cut;
 *  the scene needs topology_changes). [out] removed (may be NULL): the
 *  elements removed. A cut event follows. */
SINEW_C_API sinew_status sinew_cut(sinew_simulation* sim, sinew_body_kind kind, uint32_t body, const double from_a[3],
                                   const double from_b[3], const double to_a[3], const double to_b[3],
                                   size_t* removed);

/** Moves kinematic needle [in] needle to the pose by the end of the next frame. */
SINEW_C_API sinew_status sinew_set_needle_pose(sinew_simulation* sim, uint32_t needle, const double position[3],
                                               const double rotation[4]);
/** Force [N] and torque [N m] on force-driven needle [in] needle during the next frame. */
SINEW_C_API sinew_status sinew_apply_needle_force(sinew_simulation* sim, uint32_t needle, const double force[3],
                                                  const double torque[3]);

/** A needle at the end of the last frame (sinew::NeedleState, without its punctures). */
typedef struct sinew_needle_state {
  uint32_t struct_size;       /**< [in] sizeof(sinew_needle_state), set by the caller */
  uint32_t punctures;         /**< punctures it holds now */
  uint32_t pushing;           /**< 1: the tip pushes a surface it has not punctured */
  uint32_t reserved;          /**< 0 */
  double position[3];         /**< [m] */
  double rotation[4];         /**< unit quaternion (w, x, y, z) */
  double velocity[3];         /**< [m/s] */
  double angular_velocity[3]; /**< [rad/s] */
  double reaction_force[3];   /**< the force to render on a haptic device [N] */
  double reaction_torque[3];  /**< about the needle's origin [N m] */
  double tip_force;           /**< the unpunctured push along the tip [N] */
} sinew_needle_state;
/** [out] state of needle [in] needle. */
SINEW_C_API sinew_status sinew_get_needle_state(const sinew_simulation* sim, uint32_t needle, sinew_needle_state* state);

/* ------------------------------------------------------------ events */

/** What an event is. Values are fixed; new kinds are only appended. */
typedef enum sinew_event_kind {
  SINEW_EVENT_GRASP = 1,         /**< a grasper closed: count = particles held */
  SINEW_EVENT_RELEASE = 2,       /**< a grasper opened: count = particles released */
  SINEW_EVENT_CUT = 3,           /**< a blade removed elements of a body */
  SINEW_EVENT_CAUTERY = 4,       /**< a heated tip burned elements */
  SINEW_EVENT_REMOVAL = 5,       /**< elements removed by index */
  SINEW_EVENT_TEAR = 6,          /**< a body tore in the step (its tear_strain) */
  SINEW_EVENT_PUNCTURE = 7,      /**< a needle made a puncture in the step */
  SINEW_EVENT_PUNCTURE_END = 8,  /**< a puncture a needle held ended in the step */
  SINEW_EVENT_COLLIDER_CUT = 9,  /**< a level-set collider was cut: volume_removed */
  SINEW_EVENT_KIND_MAX_ENUM = 0x7fffffff
} sinew_event_kind;

/** One thing the last frame did, 96 bytes, laid out as written (every
 *  field at its natural alignment, no padding). Fields that do not apply
 *  to the kind are 0. */
typedef struct sinew_event {
  uint32_t kind;                 /**< sinew_event_kind */
  uint32_t object;               /**< the grasper, needle or collider; for a topology event the body */
  uint32_t body_kind;            /**< sinew_body_kind of the body changed or punctured */
  uint32_t body;                 /**< its index among the bodies of that kind */
  uint64_t frame;                /**< the frame that made it (the step it came before or in) */
  uint32_t count;                /**< elements removed, or particles held / released */
  uint32_t vertices_removed;     /**< topology: vertices left with no element */
  uint32_t constraints_removed;  /**< topology: constraints taken out */
  uint32_t triangle;             /**< puncture: the surface triangle (as sinew::Puncture) */
  uint32_t exit;                 /**< puncture: 1 when made leaving a tet body */
  uint32_t reserved;             /**< 0 */
  double weights[3];             /**< puncture: barycentric weights of the point on the triangle */
  double mass_moved;             /**< topology [kg]: handed to neighbouring vertices */
  double mass_removed;           /**< topology [kg]: that left the scene */
  double volume_removed;         /**< collider cut [m^3] */
} sinew_event;

/** [out] events of the last frame: those of the calls and script actions
 *  between the frame before and its step (grasps, releases, cuts, cautery,
 *  removals, collider cuts), then those of the step (tears, punctures made
 *  and ended), in that order. [in] capacity: records events holds; [in]
 *  event_size: sizeof(sinew_event) as the caller knows it (records are
 *  written event_size apart, each with the fields that fit, so the record
 *  may grow). Errors as the reads above. */
SINEW_C_API sinew_status sinew_read_events(const sinew_simulation* sim, sinew_event* events, size_t capacity,
                                           size_t event_size, size_t* count);

#ifdef __cplusplus
}  /* extern "C" */
#endif

#endif /* SINEW_SINEW_H */
