// continuous_collision.h — continuous collision detection in the solver
// (issue 13, part 3; MeshCollisionDesc::continuous): after each substep's
// sweeps the host tests the motion the threads' segments made in it, from
// the substep's start (the device's previous positions) to its end, against
// each other and against the surfaces' triangles, with the CCD queries of
// sinew/ccd.h. A touch becomes a contact for the rest of the frame
// (MeshCollision::append_contacts) and the substep's sweeps run again; after
// MeshCollisionDesc::continuous_repairs rounds the fail-safe stops the
// particles of the pairs that still touch where the substep started.
//
// Why a thread can then never pass through anything it is tested against:
// a crossing within a substep is a touch of the linear motion (CCD never
// misses one), and a substep ends only when no pair with a moving particle
// touches. The fail-safe ends: each of its rounds stops at least one more
// particle (a touching pair has a moving particle), and a pair whose
// particles are all still cannot cross. It relies on the substep's start
// being free of crossings, which holds by induction from a scene that
// starts with none.
//
// The broad phase: a tree over the segments' swept boxes (the box of their
// ends at the substep's start and end holds the whole linear motion),
// refitted every substep, and one over the triangles' boxes at a reference
// (the frame's start: refitted once per frame, rebuilt when degraded,
// collision/bvh.h). A triangle's swept box lies within its reference box
// grown by the drift, the farthest any triangle vertex is from its
// reference at the substep's start or end (along an axis), so the threads'
// and capsules' boxes grown by the drift meet every triangle theirs could.
// Why: refitting the triangles' tree every substep cost 3.1 ms of every
// substep on the organ example (124,000 triangles), measuring the drift
// 0.1 ms. The queries run in double on the float
// positions (exact in double) with min_separation 0: a touch means a true
// crossing or contact, not a near miss within the thickness, which the
// frame's contacts and the CCD contacts' thickness keep.
//
// Contact normal (Bridson, Fedkiw, Anderson, "Robust Treatment of
// Collisions, Contact and Friction for Cloth Animation", SIGGRAPH 2002,
// section 7): the plane the primitives meet in at the time of the touch —
// the two edges' cross product, or the triangle's normal — turned towards
// the side the first primitive came from: the side its touching point
// starts on, or, when it starts within 1 nm of the plane (touching at the
// substep's start), the side its motion relative to the second leaves;
// when neither tells (motion within that plane: parallel or coplanar
// primitives), the direction between the two touching points at the
// substep's start.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "collision/bvh.h"
#include "collision/narrow_phase.h"
#include "runtime/mesh_collision.h"
#include "runtime/solve_stepper.h"
#include "runtime/tool_contacts.h"
#include "sinew/result.h"

namespace sinew {

/// The search itself, on positions in host memory (device particle order).
class ContinuousSearch {
 public:
  using Motion = std::array<std::array<double, 3>, 2>;  ///< a point at the substep's start and end [m]
  /// A tool's or capsule collider's axis over the substep: its two ends'
  /// motion, linearised, and how far their true path (a rotation) can
  /// stray from it [m], used as the queries' minimum separation.
  struct Capsule {
    std::array<Motion, 2> ends{};
    double stray = 0.0;
  };

  /// [in] segments: 2 particles per segment (every line body's); triangles:
  /// 3 per triangle (the surfaces a thread meets).
  ContinuousSearch(std::vector<std::uint32_t> segments, std::vector<std::uint32_t> triangles);

  /// Every pair touching in the linear motion from `start` to `end` (xyzw
  /// per particle): segment-segment pairs that share no vertex (edge-edge
  /// queries), and each segment against each triangle (its ends against
  /// the face, the segment against the triangle's edges). Pairs whose
  /// particles all end where they started are skipped (they cannot cross).
  /// [out] hits: one contact per touch (kind vertex_triangle or edge_edge,
  /// the touch's parameters as weights, the normal described above,
  /// distance 0), sorted and unique (sort_unique_contacts).
  /// [in] capsules: axes the segments and triangles must not cross either
  /// (the segments' and triangles' edges against the axis, the triangles
  /// against its ends); their touches come as kind shape_face on the
  /// tissue's particles ((a, a, b, c) or (a, a, b, b), mesh_contact_params.h)
  /// with `shape` the capsule's index and the normal from the axis towards
  /// the side the tissue came from. carried: per particle (or empty), the
  /// index of the capsule it moves with this substep (the fail-safe), or
  /// kNotCarried: a capsule's pairs whose tissue particles it carries all
  /// are skipped.
  /// Errors (bad_parameter): a non-finite position, naming the particle.
  Status find(std::span<const float> start, std::span<const float> end, std::vector<collision::Contact>& hits,
              std::span<const Capsule> capsules = {}, std::span<const std::uint32_t> carried = {});
  static constexpr std::uint32_t kNotCarried = UINT32_MAX;

  /// Refits the triangles' tree to their boxes at `positions` (xyzw per
  /// particle), the reference later searches measure the drift from (the
  /// frame's start). A find() with no reference takes its start.
  void set_reference(std::span<const float> positions);

  /// Queries run by the last find().
  [[nodiscard]] std::uint64_t queries() const { return queries_; }

  /// [in] mask: per particle, what sutures exempt (suture_exemption.h):
  /// segment-triangle pairs joining a thread and a hole are not tested.
  void set_suture_exemption(const std::vector<std::uint8_t>* mask) { exempt_ = mask; }

 private:
  std::vector<std::uint32_t> segments_, triangles_;
  std::vector<std::uint32_t> triangle_vertices_;  // sorted, unique
  std::vector<float> reference_;                  // positions the triangle tree was fitted at
  collision::Bvh segment_tree_, triangle_tree_, capsule_tree_;
  // The segments' and capsules' boxes grown by the drift, against the triangles.
  collision::Bvh segment_reach_tree_, capsule_reach_tree_;
  std::vector<collision::Aabb> boxes_, segment_boxes_, capsule_boxes_;
  // The farthest (along an axis) any triangle vertex is from its reference at `start` or `end` [m].
  double drift(std::span<const float> start, std::span<const float> end) const;
  std::vector<collision::Pair> pairs_;
  std::uint64_t queries_ = 0;
  // find()'s steps: the positions checked, then the threads against each
  // other, the threads against the surfaces, the capsules against both.
  Status check_finite(std::span<const float> start, std::span<const float> end) const;
  Status test_primitives(std::span<const float> start, std::span<const float> end, std::array<std::uint32_t, 4> p,
                         collision::Contact::Kind kind, std::vector<collision::Contact>& hits);
  Status thread_against_thread(std::span<const float> start, std::span<const float> end,
                               std::vector<collision::Contact>& hits);
  Status thread_against_surfaces(std::span<const float> start, std::span<const float> end,
                                 std::vector<collision::Contact>& hits);
  Status capsules_against_tissue(std::span<const float> start, std::span<const float> end,
                                 std::vector<collision::Contact>& hits, std::span<const Capsule> capsules,
                                 std::span<const std::uint32_t> carried, bool surfaces, double reach);
  Status capsule_against(std::span<const float> start, std::span<const float> end,
                         std::vector<collision::Contact>& hits, std::span<const Capsule> capsules,
                         std::span<const std::uint32_t> carried, const collision::Bvh& tree,
                         const collision::Bvh& capsule_tree, const std::vector<std::uint32_t>& indices, int arity);
  const std::vector<std::uint8_t>* exempt_ = nullptr;
  void fit(std::span<const float> start, std::span<const float> end, std::span<const std::uint32_t> indices,
           int arity, collision::Bvh& tree);
};

/// A capsule the threads and surfaces must not pass through, at its poses
/// at the frame's start and end: a rigid tool (`tool` its index) or a
/// capsule collider (`tool` = collision::Contact::kNoShape).
struct FrameCapsule {
  PosedShape start, end;
  std::uint32_t tool = collision::Contact::kNoShape;
};

/// The search wired into the solver: reads the substep's motion from the
/// device, hands the touches to the mesh collision as contacts, runs the
/// fail-safe. A SubstepHook for SolveStepper.
class ContinuousCollision final : public SubstepHook {
 public:
  /// [in] mesh_collision, buffers: outlive this. desc: the scene's
  /// (thickness, continuous_repairs: rounds per substep before the
  /// fail-safe); substeps: per frame.
  ContinuousCollision(std::vector<std::uint32_t> segments, std::vector<std::uint32_t> triangles,
                      MeshCollision& mesh_collision, const XpbdBuffers& buffers, const MeshCollisionDesc& desc,
                      int substeps);

  Status after_sweeps(Device& device, int substep, int round, bool& repair) override;

  /// See ContinuousSearch::set_suture_exemption.
  void set_suture_exemption(const std::vector<std::uint8_t>* mask) { search_.set_suture_exemption(mask); }

  /// Before each frame: zeroes the frame's counters; [in] capsules: the
  /// tools and capsule colliders over the frame (interpolated per substep
  /// like the kernels do: position linearly, rotation by normalised lerp).
  void begin_frame(std::vector<FrameCapsule> capsules);
  // The frame's counters (FrameStats::ccd_*).
  [[nodiscard]] std::uint32_t hits() const { return hits_; }
  [[nodiscard]] std::uint32_t repairs() const { return repair_rounds_; }
  [[nodiscard]] std::uint32_t reverted() const { return reverted_; }
  [[nodiscard]] std::uint32_t carried() const { return carried_count_; }
  [[nodiscard]] std::uint32_t forced() const { return forced_; }
  [[nodiscard]] double wall_ms() const { return wall_ms_; }

 private:
  ContinuousSearch search_;
  MeshCollision& mesh_collision_;
  const XpbdBuffers& buffers_;
  double thickness_ = 0.0;
  int repairs_ = 0, substeps_ = 1;
  std::vector<FrameCapsule> frame_capsules_;
  std::vector<ContinuousSearch::Capsule> capsules_;  // this substep's
  // This substep's rigid motion of each capsule: start and end poses.
  std::vector<std::array<PosedShape, 2>> substep_poses_;
  // Per particle, this substep: the capsule the fail-safe moves it with, or kNotCarried.
  std::vector<std::uint32_t> carried_;
  static constexpr std::uint32_t kNotCarried = ContinuousSearch::kNotCarried;
  std::vector<float> start_, end_;
  std::vector<collision::Contact> hits_found_, contacts_;
  std::uint32_t hits_ = 0, repair_rounds_ = 0, reverted_ = 0, carried_count_ = 0, forced_ = 0;
  double wall_ms_ = 0.0;
  void substep_capsules(int substep);
  // The contact of a capsule touch (hit.shape: the capsule's index): the
  // plane that touches the capsule along the normal, moving with it over
  // the frame, as the mesh collision's tool faces (mesh_contact_params.h).
  collision::Contact capsule_contact(const collision::Contact& hit) const;
  // The fail-safe: stops the moving particles of each pair that still
  // touches where the substep started, or, against a capsule, moves them
  // with it; searches again until no pair it can act on touches; writes
  // the positions.
  Status fail_safe(Device& device);
};

}  // namespace sinew
