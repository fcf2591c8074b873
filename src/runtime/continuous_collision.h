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
// The broad phase: one tree over the segments' swept boxes (the box of
// their ends at the substep's start and end holds the whole linear motion)
// and one over the triangles', refitted every substep and rebuilt when
// degraded (collision/bvh.h). The queries run in double on the float
// positions (exact in double) with min_separation 0: a touch means a true
// crossing or contact, not a near miss within the thickness, which the
// frame's contacts and the CCD contacts' thickness keep.
//
// Contact normal (Bridson, Fedkiw, Anderson, "Robust Treatment of
// Collisions, Contact and Friction for Cloth Animation", SIGGRAPH 2002,
// section 7): the plane the primitives meet in at the time of the touch —
// the two edges' cross product, or the triangle's normal — turned towards
// the side the first primitive came from; when the motion lies in that
// plane (parallel or coplanar primitives), the direction between the two
// touching points at the substep's start.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "collision/bvh.h"
#include "collision/narrow_phase.h"
#include "runtime/mesh_collision.h"
#include "runtime/solve_stepper.h"
#include "sinew/result.h"

namespace sinew {

/// The search itself, on positions in host memory (device particle order).
class ContinuousSearch {
 public:
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
  /// Errors (bad_parameter): a non-finite position, naming the particle.
  Status find(std::span<const float> start, std::span<const float> end, std::vector<collision::Contact>& hits);

  /// Queries run by the last find().
  [[nodiscard]] std::uint64_t queries() const { return queries_; }

 private:
  std::vector<std::uint32_t> segments_, triangles_;
  collision::Bvh segment_tree_, triangle_tree_;
  std::vector<collision::Aabb> boxes_;
  std::vector<collision::Pair> pairs_;
  std::uint64_t queries_ = 0;
  void fit(std::span<const float> start, std::span<const float> end, std::span<const std::uint32_t> indices,
           int arity, collision::Bvh& tree);
};

/// The search wired into the solver: reads the substep's motion from the
/// device, hands the touches to the mesh collision as contacts, runs the
/// fail-safe. A SubstepHook for SolveStepper.
class ContinuousCollision final : public SubstepHook {
 public:
  /// [in] mesh_collision, buffers: outlive this. repairs: rounds per
  /// substep before the fail-safe (MeshCollisionDesc::continuous_repairs).
  ContinuousCollision(std::vector<std::uint32_t> segments, std::vector<std::uint32_t> triangles,
                      MeshCollision& mesh_collision, const XpbdBuffers& buffers, int repairs);

  Status after_sweeps(Device& device, int substep, int round, bool& repair) override;

  /// Zeroes the frame's counters (before each frame).
  void begin_frame();
  // The frame's counters (FrameStats::ccd_*).
  [[nodiscard]] std::uint32_t hits() const { return hits_; }
  [[nodiscard]] std::uint32_t repairs() const { return repair_rounds_; }
  [[nodiscard]] std::uint32_t reverted() const { return reverted_; }
  [[nodiscard]] double wall_ms() const { return wall_ms_; }

 private:
  ContinuousSearch search_;
  MeshCollision& mesh_collision_;
  const XpbdBuffers& buffers_;
  int repairs_ = 0;
  std::vector<float> start_, end_;
  std::vector<collision::Contact> hits_found_;
  std::uint32_t hits_ = 0, repair_rounds_ = 0, reverted_ = 0;
  double wall_ms_ = 0.0;
  // Stops the movable particles of `hits_found_` at their start positions,
  // then searches again, until no moving pair touches; writes the positions.
  Status stop_touching(Device& device);
};

}  // namespace sinew
