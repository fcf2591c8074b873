// mesh_collision.h — contacts between the bodies' meshes in the solver
// (issue 12, part 3; SceneDesc::mesh_collision): before every frame the
// host reads the particles back, finds the frame's contacts (BVH broad
// phase and narrow phase of src/collision), keeps the nearest few of each
// vertex's, triangle's and edge's contacts against each other body, adds
// the triangles' and segments' contacts with the colliders' and tools'
// shapes, colours them and writes them to the device, where
// xpbd_solve_mesh_contacts solves them in every sweep
// (kernels/shared/mesh_contact_params.h). After the frame it reads back the
// multipliers of the contacts with tools: their reaction on the tools.
//
// Why per frame, inflated by the motion: one detection serves all the
// substeps and sweeps, and contacts found within thickness + margin hold
// the surfaces apart wherever they come closer during the frame. Why
// coloured Gauss-Seidel: contacts are solved like the bodies' own
// constraints, each seeing its neighbours' corrections at once (the README
// compares it with a Jacobi pass, "Mesh collision").
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "collision/bvh.h"
#include "collision/leaf_vertices.h"
#include "collision/narrow_phase.h"
#include "collision/normal_cones.h"
#include "collision/rest_close.h"
#include "compiler/scene_compiler.h"
#include "program/xpbd_program.h"
#include "runtime/positions_mirror.h"
#include "runtime/tool_contacts.h"
#include "sinew/scene.h"

namespace sinew {

class MeshCollision {
 public:
  /// The collidable primitives of `scene` (device particle indices) and
  /// the contact buffers on `device`, sized for a first guess.
  static Result<std::unique_ptr<MeshCollision>> create(const SceneDesc& scene, const CompiledScene& compiled,
                                                       Device& device);

  /// Finds this frame's contacts from the positions and velocities now on
  /// the device and uploads them. [out] grew: the buffers or the colours
  /// outgrew the frame program, which must be rebuilt with buffers().
  /// Errors: a non-finite position or a collapsed triangle, named.
  /// [in] colliders: the scene's colliders at their poses at the end of
  /// the frame; the triangles and segments meet them face-on
  /// (shape_faces()). [in] tool_starts, tool_ends: the rigid tools'
  /// capsules at their poses at the start and the end of the frame (tool t
  /// at index t): a tool can move more than its radius in a frame, so its
  /// faces' contacts are found where it starts, on the side the face is
  /// then, and hold the face beyond the plane that touches the tool where
  /// it ends; their reaction comes back through add_tool_reactions.
  Status before_frame(Device& device, const XpbdBuffers& scene_buffers, std::span<const PosedShape> colliders,
                      std::span<const PosedShape> tool_starts, std::span<const PosedShape> tool_ends, bool& grew);

  /// Adds contacts for the rest of the frame, after the frame's own
  /// (continuous collision detection's touches, continuous_collision.h):
  /// they and the frame's earlier additions are coloured greedily into the
  /// colours the program has beyond the frame's (MeshCollisionDesc::
  /// continuous reserves some, at most 32), laid out after the frame's
  /// contacts, and uploaded with the earlier additions' multipliers carried
  /// over and the new ones' at 0. [in] contacts: vertex_triangle, edge_edge
  /// or shape_face (with its offset, motion and tool,
  /// mesh_contact_params.h), with their weights and normal; a tool's
  /// reaction comes back through add_tool_reactions. Returns how many were
  /// added: those that found no colour or slot left are not (the next
  /// frame keeps more room; the caller's next round finds their touches
  /// again, or its fail-safe acts on them).
  Result<std::uint32_t> append_contacts(Device& device, std::span<const collision::Contact> contacts);

  /// Destroys its device buffers (before a MeshCollision made for the
  /// scene's new topology replaces it).
  Status release(Device& device);

  /// After a topology change (issue 16): brings the collidable primitives
  /// to what create() would make of the scene now, in place and in the
  /// same order, touching only the bodies that changed. A tet body's
  /// boundary is updated from the tets that died since the last call (its
  /// faces that were on the boundary leave, its faces shared with a live
  /// tet join, wound outward from that tet); a tri or line body whose
  /// triangles or segments differ is replaced whole. A changed body's
  /// rest-close pairs are those of create() (the old pairs carried over,
  /// the new triangles' found at the starting positions), its trees are
  /// built anew in the next before_frame; other bodies keep theirs, and
  /// the device buffers are kept (grown where the Jacobi schedule needs
  /// room for more particles). Why: a remake costs 20 ms on a 50,400-tet
  /// block (the boundary of every tet, every triangle's rest-close pairs),
  /// against the 2 ms a cut may add to its frame.
  /// [in] tet_alive: per tet body, per tet of the mesh create() was given
  /// (all alive then), whether it is alive now; tets never come back.
  /// [in] scene: its tri bodies' triangles and line bodies' segments are
  /// the live ones; its tet bodies' meshes are not read. [out] changed:
  /// whether any primitive changed (continuous collision, made from
  /// segments() and triangles(), is then to be made again). Errors
  /// (bad_parameter): a MeshCollision not made with
  /// SceneDesc::topology_changes, masks of the wrong size, or a tet alive
  /// again; nothing is changed then.
  Status update_topology(Device& device, const SceneDesc& scene,
                         std::span<const std::vector<std::uint8_t>* const> tet_alive, bool& changed);

  /// [in] mask: per particle, what sutures exempt (suture_exemption.h);
  /// outlives this, read every frame.
  void set_suture_exemption(const std::vector<std::uint8_t>* mask) { exempt_ = mask; }
  /// The host state that carries from one frame to the next (a saved
  /// state's, sinew/saved_state.h): the velocities the next frame's reach
  /// and swept boxes are measured from, each particle's mean over the last
  /// frame (device order, xyzw [m/s]). [out] out: empty before the first
  /// frame (it reads the device's velocities then).
  void save_velocities(std::vector<float>& out) const;
  /// Simulation::restore_state: the device's positions changed outside the
  /// frames; the next frame reads them again and measures its reach from
  /// `velocities` (what save_velocities gave; empty: from the device's, as
  /// the first frame does), not from the motion between the positions the
  /// last after_frame read and the restored ones. Errors (bad_parameter): a
  /// size that is not 4 floats per particle.
  Status restore_velocities(std::vector<float> velocities);
  /// Reads the positions through the frame's shared mirror (null: on its own).
  void set_positions_mirror(PositionsMirror* mirror) { mirror_ = mirror; }
  /// Particles of the scene (device order).
  [[nodiscard]] std::size_t particles() const { return movable_.size(); }
  /// The collidable primitives (device particles): every line body's
  /// segments (2 each) and every surface's triangles (3 each: the tet
  /// bodies' boundaries, then the tri bodies).
  [[nodiscard]] const std::vector<std::uint32_t>& segments() const { return segments_; }
  [[nodiscard]] const std::vector<std::uint32_t>& triangles() const { return triangles_; }

  /// Reads the positions and velocities the frame ended with (the next
  /// frame's detection starts from them) and measures violation(); with
  /// face contacts on tools, reads their multipliers back too.
  Status after_frame(Device& device, const XpbdBuffers& scene_buffers);

  /// Adds to each tool's reaction (rigid_tool.h: contact_force and torque,
  /// the frame's average; coupling_force and torque, its last substep's;
  /// the touching mass and inertia) what the meshes' faces and segments
  /// gave it in the last frame: per contact, -(sum + lambda) / h over the
  /// frame and -lambda / h over its last substep [N s], as vectors
  /// lambda_n n + lambda_t (mesh_contact_params.h), at the contact's point
  /// on the triangle or segment at the frame's end (the moments of the
  /// earlier substeps are taken there too: exact for the last substep,
  /// which the coupling uses). A touching face's particles count with
  /// their weights c_k in the touching mass and inertia (a particle that
  /// also touches the tool itself counts twice). [in] frame, h: the frame
  /// and substep lengths [s].
  void add_tool_reactions(std::vector<ToolBody>& tools, double frame, double h) const;
  /// How far the last frame's contacts ended inside their thickness [m]:
  /// the largest thickness - gap over them, 0 when none is inside.
  [[nodiscard]] double violation() const { return violation_; }
  /// violation() over the contacts of a body with itself [m].
  [[nodiscard]] double self_violation() const { return self_violation_; }
  /// violation() over the contacts of faces and segments with the tools [m].
  [[nodiscard]] double tool_violation() const { return tool_violation_; }

  [[nodiscard]] const MeshContactBuffers& buffers() const { return buffers_; }
  [[nodiscard]] std::uint32_t contacts() const { return contact_count_; }  ///< this frame's
  /// This frame's colours (ContactSchedule::device_colored: the device's
  /// colours below the cap holding contacts, known once take_counters had
  /// the frame's counters; the overflow set not included).
  [[nodiscard]] std::uint32_t colors() const { return color_count_; }
  /// ContactSchedule::device_colored: this frame's contacts in the overflow set (after take_counters).
  [[nodiscard]] std::uint32_t overflow() const { return overflow_count_; }
  /// ContactSchedule::device_colored: takes the colours and the overflow
  /// set from the counters of the frame program that just ran (its first
  /// counters are the colouring's, DeviceColoringCounters), brought back
  /// by its wait: no transfer of its own. Other schedules: nothing.
  /// Errors (internal): fewer counters than the colouring declares.
  Status take_counters(std::span<const std::uint32_t> counters);
  /// The last detection's candidate pairs of primitives (within the reach), at most pair_capacity().
  [[nodiscard]] std::size_t candidate_pairs() const { return pairs_.size(); }
  /// The most candidate pairs a detection may find; past it the frame fails with capacity_exceeded.
  [[nodiscard]] static std::size_t pair_capacity();
  /// This frame's largest motion margin [m]: the reach of the fastest pair beyond the thickness.
  [[nodiscard]] double margin() const { return margin_; }
  /// Pairs of triangles closer than the thickness at the scene's start,
  /// summed over the bodies (SceneInfo::rest_close_triangle_pairs).
  [[nodiscard]] std::uint32_t rest_close_pairs() const;

 private:
  MeshCollisionDesc desc_;
  double time_step_ = 0.0;
  double gravity_ = 0.0;  // |g| [m/s^2]
  std::vector<std::uint32_t> triangles_, triangle_body_;  // device particles, 3 per triangle; body per triangle
  collision::TriangleOwnership ownership_;                // of triangles_: each vertex and edge tested once
  std::vector<std::uint32_t> segments_, segment_body_;    // 2 per segment
  const std::vector<std::uint8_t>* exempt_ = nullptr;     // sutures' exemption mask (or none)
  std::vector<std::uint32_t> collidable_;                 // particles of any primitive
  // A BVH per body over its primitives [first, first + count).
  struct BodyTree {
    std::uint32_t first = 0, count = 0;
    collision::Bvh tree;       // boxes swept by the vertices' velocities: against other bodies
    collision::Bvh self_tree;  // swept relative to the body's mean velocity: against itself (self-collision only)
    collision::LeafVertices leaf;  // self_tree's vertices in its leaf order (self-collision only)
    collision::NormalCones cones;  // of self_tree; triangle trees with self-culling only
    // Triangle trees with self-collision: the pairs (local indices)
    // closer than the thickness in the starting shape, never in contact.
    collision::PairSet rest_close;
  };
  std::vector<BodyTree> triangle_trees_, segment_trees_;
  std::vector<collision::Pair> local_;
  std::vector<std::uint32_t> body_of_;  // per particle: the collidable body it belongs to
  // A contact ranked among those of one primitive (a vertex, an edge's two
  // vertices, a triangle's three, sorted) against one other body, nearest first.
  template <class Primitive>
  struct RankKey {
    Primitive primitive;
    std::uint32_t body;  // the other side's body (edges: | 2^31)
    float distance;
    std::uint32_t contact;
    bool operator<(const RankKey& o) const {
      if (primitive != o.primitive) return primitive < o.primitive;
      if (body != o.body) return body < o.body;
      if (distance != o.distance) return distance < o.distance;
      return contact < o.contact;
    }
  };
  std::vector<RankKey<std::uint64_t>> keys_;
  using TriangleKey = RankKey<std::array<std::uint32_t, 3>>;
  std::vector<TriangleKey> triangle_keys_;
  std::vector<std::uint8_t> chosen_;
  void prune();
  // Contacts of the triangles and segments against the colliders' or the
  // tools' shapes, where a primitive's deepest point is inside it or on an
  // edge (a corner is the vertex's own collider contact): a sharp or thin
  // shape pressed between a coarse mesh's or thread's vertices. Not for
  // planes (a primitive's deepest point against a plane is always a
  // corner). Colliders (`ends` empty) are met at their end pose. Tools:
  // shape i is tool i (Contact::shape), met at its start pose `shapes[i]`
  // within the reach widened by its motion, the plane of the contact moved
  // to touch its end pose `ends[i]` (a capsule) along the start's normal.
  void shape_faces(std::span<const PosedShape> shapes, std::span<const PosedShape> ends, double common);
  // The uploaded contacts with a tool's capsule: (slot, tool), and after
  // the frame their multipliers (lambda, then the earlier substeps' sum).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> tool_slots_;
  std::vector<float> tool_lambda_, tool_lambda_sum_;
  std::vector<float> upload_motion_;  // per contact slot (Contact::motion)
  // Refits each body's tree (against other bodies) to its primitives'
  // `boxes` (builds it when empty). Rebuilt, when degraded past
  // kMaxDegradation, after the cones' update beside it (before_frame).
  static void refit(std::vector<BodyTree>& trees, std::span<const collision::Aabb> boxes);
  static constexpr double kMaxDegradation = 2.0;
  // Fills each triangle tree's rest_close from the starting positions
  // (device order, xyzw).
  Status find_rest_close(std::span<const float> start);
  template <int Arity>
  void candidate_pairs(std::vector<BodyTree>& a, std::span<const std::uint32_t> indices,
                       const std::vector<BodyTree>& b, std::vector<collision::Pair>& pairs);
  MeshContactBuffers buffers_;
  std::uint32_t contact_count_ = 0, color_count_ = 0, overflow_count_ = 0;
  // ContactSchedule::device_colored: (re)makes buffers_.coloring for buffers_.capacity contacts.
  Status make_device_coloring(Device& device);
  // Continuous collision's contacts (append_contacts): the colours and
  // slots kept free beyond the frame's, the frame's additions and their
  // slots, the colours they take, and whether the last frame needed more.
  std::uint32_t reserve_colors_ = 0, reserve_slots_ = 0;
  std::vector<collision::Contact> appended_;
  std::vector<std::uint32_t> appended_slots_;
  std::uint32_t appended_colors_ = 0;
  bool want_colors_ = false, want_slots_ = false;
  std::vector<std::uint32_t> color_mask_;  // per particle: the appended colours it is in (bit k)
  double margin_ = 0.0;
  double violation_ = 0.0, self_violation_ = 0.0, tool_violation_ = 0.0;
  std::vector<std::uint8_t> tool_slot_;  // per contact slot: a tool's (after_frame's scratch)
  bool fresh_ = false;  // positions_ and velocities_ hold the device's current state
  bool restored_ = false;  // velocities_ were restored: the next read_back reads the positions only
  PositionsMirror* mirror_ = nullptr;
  Status read_back(Device& device, const XpbdBuffers& scene_buffers);
  // Per-frame scratch, kept to avoid reallocating.
  std::vector<float> positions_, start_positions_, velocities_, speed_;
  std::uint32_t solid_bodies_ = 0;  // bodies 0 .. solid_bodies_ - 1 are tet bodies (closed, outward surfaces)
  std::uint32_t body_count_ = 0;      // collidable bodies: tet, then tri, then line bodies
  std::vector<double> mean_velocity_;  // per body: its surface vertices' mean velocity (xyz) [m/s]
  std::vector<collision::Aabb> self_boxes_;  // one body's self tree's, in its leaf order
  std::vector<float> leaf_velocities_;       // one body's velocities gathered in its self tree's leaf order
  std::size_t solid_triangles_ = 0;  // triangles_ [0, solid_triangles_) are the solids' surfaces
  std::vector<float> vertex_out_;  // per particle of a solid's surface: its area-weighted normal (xyz)
  std::vector<float> face_out_;    // per solid surface triangle: its unit normal (xyz)
  void index_solid_edges();
  // Calls visit(face) for each solid surface triangle with edge (a, b), ascending.
  template <class Visit>
  void faces_on(std::uint32_t a, std::uint32_t b, Visit visit) const;
  // The solid surface triangle (a, b, c), or UINT32_MAX.
  std::uint32_t solid_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) const;
  // [out] out: the sum of the unit normals of the faces on edge (a, b);
  // false if it is no solid's surface edge.
  bool solid_edge(std::uint32_t a, std::uint32_t b, float out[3]) const;
  // The solid surface triangles around each particle (compressed rows,
  // ascending): faces_on, solid_face and solid_edge look an edge up there.
  std::vector<std::uint32_t> solid_first_, solid_around_;
  // ---- Topology changes (SceneDesc::topology_changes; update_topology).
  // A tet body's faces: face slot 4 t + f is face f of tet t, wound as
  // extract_boundary_surface winds it (outward from t).
  struct TetFaces {
    std::uint32_t first_particle = 0;                // the body's first particle (scene order)
    std::vector<std::array<std::uint32_t, 4>> tets;  // the body's tets (body vertex indices)
    std::vector<std::uint8_t> alive;                 // per tet, as of the last update
    // Per face slot: the next slot with the same three vertices, a ring
    // (the slot itself when no other tet has that face).
    std::vector<std::uint32_t> twin;
    std::vector<std::uint32_t> boundary;  // the boundary's face slots, ascending (extract_boundary_surface's order)
    std::vector<std::uint8_t> on_boundary;  // per face slot
    // The tets' boxes at the starting positions grown by half the
    // thickness (self-collision only): where a new boundary face finds
    // the faces it is rest-close to.
    collision::Bvh rest_tree;
  };
  std::vector<TetFaces> tet_faces_;  // per tet body; empty without topology changes
  std::vector<float> rest_positions_;  // the starting positions (device order, xyzw; w = 0): rest-close pairs
  std::vector<std::uint32_t> device_of_;  // scene particle -> device particle
  std::vector<std::uint32_t> tri_first_, line_first_;  // per tri / line body: its first particle (scene order)
  // update_topology's scratch for the ownership it carries over (kept: a
  // fresh 120 kB of rows paid its page faults at every cut).
  std::vector<std::array<std::uint32_t, 6>> owner_scratch_;
  std::vector<std::uint8_t> dirty_;  // per particle, 0 between calls
  // Builds tet_faces_ (and rest_positions_, device_of_) from the scene create() was given.
  void index_tet_faces(const SceneDesc& scene, const CompiledScene& compiled);
  // The triangles (device particles, 3 each) of tet body `body`'s boundary slots.
  void boundary_triangles(const TetFaces& faces, std::vector<std::uint32_t>& out) const;
  // The derived indices after triangles_ or segments_ changed: the trees'
  // ranges, body_of_, ownership_ (unless `ownership` is false: the caller
  // brought it up to date), the solid faces, collidable_.
  void index_primitives(bool ownership = true);
  // The rest-close pairs of a changed triangle body: `old` (local indices
  // before the change) carried over through `remap` (old -> new local
  // index, UINT32_MAX: gone), and those of the triangles `added` (new local
  // indices) found against the body's tet faces (tet bodies) or all its
  // triangles (tri bodies) at the starting positions.
  Status update_rest_close(std::uint32_t body, BodyTree& tree, const collision::PairSet& old,
                           std::span<const std::uint32_t> remap, std::span<const std::uint32_t> added);
  std::vector<collision::Aabb> boxes_;
  std::vector<collision::Pair> pairs_;
  std::vector<collision::Contact> found_, all_;
  std::vector<std::uint8_t> movable_;  // per particle (device order): inverse mass > 0
  std::vector<std::uint8_t> face_hit_;  // per triangle: its triangle-shape contacts in found_ (at most kManifold)
  static constexpr std::size_t kManifold = 3;  // a face's contacts with one shape: its deepest point, its span's ends
  std::vector<std::uint32_t> kept_, contact_particles_, table_, upload_particles_;
  std::vector<float> upload_coefficients_, upload_normals_;
  std::vector<std::uint32_t> upload_offsets_, upload_touched_, upload_slots_, compact_offsets_;  // Jacobi
  // The runs of `body_of` (one body's primitives are contiguous): per body
  // of `bodies`, its (first, count); count 0 for a body with none.
  static std::vector<std::pair<std::uint32_t, std::uint32_t>> body_ranges(const std::vector<std::uint32_t>& body_of,
                                                                          std::uint32_t bodies);
  // ---- The frame's detection (before_frame; mesh_collision_detect.cpp).
  // speed_ per collidable particle; [out] fastest. Errors: a non-finite velocity.
  Status measure_speeds(float& fastest);
  void mean_velocities();   // mean_velocity_
  void outward_normals();   // vertex_out_, face_out_ (self-collision with solids)
  // Grows each primitive's box along its corners' velocities (less `mean`) over 2 dt.
  void sweep(std::span<const std::uint32_t> corners, int arity, std::span<const float> velocities,
             const double mean[3], std::vector<collision::Aabb>& boxes) const;
  // The trees refitted to the frame's boxes (grown by `half`), degraded ones rebuilt.
  Status refit_triangle_trees(float half);
  Status refit_segment_trees(float half);
  Status fit(std::span<const std::uint32_t> indices, int arity, std::span<const std::uint32_t> body_of,
             std::vector<BodyTree>& trees, float half);
  Status gather_body(BodyTree& body, std::span<const std::uint32_t> indices, int arity);
  Status gather(std::span<const std::uint32_t> indices, int arity, std::vector<BodyTree>& trees);
  void rebuild_degraded(std::vector<BodyTree>& trees);
  // The narrow phase's filters: a solid's two sides facing across air, and
  // every condition a contact of the frame meets (within `common` plus its
  // closing speed's share).
  bool across_air(const collision::Contact& c) const;
  bool wanted_contact(const collision::Contact& c, double common) const;
  Status check_pairs(float reach, float fastest) const;  // pairs_ within kMaxPairs
  // The frame's contacts between the meshes into all_ (before prune).
  Status detect_contacts(double common, float reach, float fastest);
  // ---- Scheduling and upload (mesh_collision_schedule.cpp).
  Status schedule_contacts(Device& device, bool& grew);
  std::uint32_t keep_movable();  // kept_, contact_particles_, contact_count_
  Status make_room(Device& device, std::uint32_t count, bool& grew);
  Status assign_slots(Device& device, std::uint32_t count, std::vector<std::uint32_t>& slot_of, bool& grew);
  void fill_upload(std::uint32_t count, std::span<const std::uint32_t> slot_of);
  Status upload_jacobi(Device& device);
  Status upload_contacts(Device& device, std::uint32_t count);
  // ---- update_topology's steps (mesh_collision_topology.cpp).
  struct TopologyChange {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> old_triangles, old_segments;  // body_ranges before
    std::vector<std::uint8_t> body_changed;  // per body
    // Per triangle body that changed: old local index -> new (remap) and the
    // new triangles (added, new local indices); per changed body, its new
    // primitives (replaced, device particles).
    std::vector<std::vector<std::uint32_t>> remap, added, replaced;
  };
  Status tets_died(std::span<const std::vector<std::uint8_t>* const> tet_alive,
                   std::vector<std::vector<std::uint32_t>>& died) const;
  void update_tet_boundaries(const std::vector<std::vector<std::uint32_t>>& died, TopologyChange& change);
  void compare_tri_bodies(const SceneDesc& scene, TopologyChange& change);
  void compare_line_bodies(const SceneDesc& scene, TopologyChange& change);
  Status retree(const std::vector<std::uint32_t>& body_of, const std::vector<std::uint32_t>& old_body_of,
                std::vector<BodyTree>& trees, bool triangles_of, const TopologyChange& change);
  void carry_ownership(const TopologyChange& change, const std::vector<std::uint32_t>& triangles,
                       std::uint32_t triangle_bodies);
};

}  // namespace sinew
