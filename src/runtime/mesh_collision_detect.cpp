// mesh_collision_detect.cpp — the frame's detection between the meshes
// (before_frame, see mesh_collision.h): the reach and motion margin from the
// particles' speeds, each body's mean velocity and the solids' outward
// normals, the boxes swept by the motion and the trees refitted to them, the
// candidate pairs, the narrow phase with its filters (facing, across air,
// within the pair's own reach), and the pruning to the nearest few contacts
// per primitive. The contacts with the shapes' faces follow
// (mesh_collision_shapes.cpp), then colouring and upload
// (mesh_collision_schedule.cpp).
#include "runtime/mesh_collision.h"
#include "runtime/suture_exemption.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>


#include "collision/parallel_pairs.h"
#include "hooks/hooks_internal.h"

namespace sinew {
namespace {

using collision::Contact;

// Vertex-triangle contacts kept per triangle and other body (see prune).
constexpr std::size_t kPerTriangle = 3;
// Edge-edge contacts kept per edge and other body (see prune).
constexpr std::size_t kPerEdge = 4;
// The most candidate pairs one query may hand the narrow phase (see check_pairs).
constexpr std::size_t kMaxPairs = std::size_t{1} << 23;
// Boxes are swept along their vertices' last velocity over 2 dt and grown
// by kTurn dt |v| in every direction besides: room for the motion to turn
// within the frame (half the speed, reversed) without missing a pair.
constexpr double kTurn = 1.0;

}  // namespace

Status MeshCollision::before_frame(Device& device, const XpbdBuffers& scene_buffers,
                                   std::span<const PosedShape> colliders, std::span<const PosedShape> tool_starts,
                                   std::span<const PosedShape> tool_ends, bool& grew) {
  grew = false;
  // The positions and velocities the last frame ended with (after_frame);
  // read here only before the first frame.
  if (!fresh_)
    if (Status s = read_back(device, scene_buffers); !s) return s;
  fresh_ = false;

  // How close two primitives must be at the frame's start to become a
  // contact (mesh_collision.h): the thickness, the user's margin and
  // gravity's share |g| dt^2 / 2 for every pair (a body that starts to
  // fall in this frame, beside one that rests), plus 2 dt |v_rel| with v_rel
  // the relative velocity of the closest points over the last frame (twice
  // the distance they closed in it, for the acceleration within this one).
  // The boxes grow by each primitive's share: half the common part and its
  // path over 2 dt (swept, below), so every pair that may need a contact
  // overlaps; the narrow phase then keeps the contacts within their
  // pair's own reach, and a body moving as a whole makes no self-contacts.
  float fastest = 0.0f;
  if (Status s = measure_speeds(fastest); !s) return s;
  const double dt = time_step_;
  const double common = desc_.thickness + desc_.margin + 0.5 * gravity_ * dt * dt;
  margin_ = desc_.margin + 0.5 * gravity_ * dt * dt + 4.0 * dt * fastest;
  const auto reach = static_cast<float>(desc_.thickness + margin_);
  mean_velocities();
  if (desc_.self_collision && solid_bodies_ > 0) outward_normals();
  all_.clear();
  if (Status s = detect_contacts(common, reach, fastest); !s) return s;

  prune();
  shape_faces(colliders, {}, common);
  if (desc_.tool_faces) shape_faces(tool_starts, tool_ends, common);
  return schedule_contacts(device, grew);
}

// Each collidable particle's speed (speed_) and the fastest of them.
Status MeshCollision::measure_speeds(float& fastest) {
  speed_.assign(movable_.size(), 0.0f);
  fastest = 0.0f;
  for (std::uint32_t p : collidable_) {
    const float* v = &velocities_[std::size_t{p} * 4];
    speed_[p] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!std::isfinite(speed_[p]))
      return Error(ErrorCode::bad_parameter, "mesh collision: particle " + std::to_string(p) +
                                                 " (device order) has a non-finite velocity");
    fastest = std::max(fastest, speed_[p]);
  }
  return {};
}

// Swept, not swollen: each box grows along its vertices' motion over 2 dt
// (to where linear motion takes them), plus kTurn dt |v| all round, so a
// body sliding along another pairs with a strip of its triangles, not a
// disc. Any two primitives that come within the common reach under linear
// motion within 2 dt overlap: both boxes hold their primitive's whole
// path. Measured on the kidney dropped onto the liver's patch (it slides
// off at 0.4 m/s): detection 0.1-0.3 s per frame instead of 1.5-14 s with
// a swelling by 2 dt |v| in every direction, the same contacts held.
// Self-pairs are found in each body's own frame of motion: with `drift`
// the boxes are swept by each vertex's velocity less its body's mean
// surface velocity (distances within one body do not change under a
// common motion), so a body carried along as a whole pairs only what moves
// relative to the rest of it (measured: the organ example with
// self-collision, the kidney pushed down by the probe, detection at frame
// 6 took 2.2 s instead of 4.7, before the narrow phase's filter).
// Against other bodies the velocities themselves sweep the boxes.
// [in] corners: `arity` per primitive into `velocities` (xyzw); mean: the
// velocity the sweep is relative to (a body's mean, or zero).
void MeshCollision::sweep(std::span<const std::uint32_t> corners, int arity, std::span<const float> velocities,
                          const double mean[3], std::vector<collision::Aabb>& boxes) const {
  const double dt = time_step_;
  const auto velocity = [&](std::size_t i, int k, int a) {
    return double(velocities[4 * std::size_t{corners[i * arity + k]} + a]) - mean[a];
  };
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    double speed = 0.0;
    for (int k = 0; k < arity; ++k)
      speed = std::max(speed, std::sqrt(velocity(i, k, 0) * velocity(i, k, 0) + velocity(i, k, 1) * velocity(i, k, 1) +
                                        velocity(i, k, 2) * velocity(i, k, 2)));
    const auto turn = static_cast<float>(kTurn * dt * speed);
    for (int a = 0; a < 3; ++a) {
      float lo = 0.0f, hi = 0.0f;
      for (int k = 0; k < arity; ++k) {
        const auto d = static_cast<float>(2.0 * dt * velocity(i, k, a));
        lo = std::min(lo, d), hi = std::max(hi, d);
      }
      boxes[i].lo[a] += lo - turn, boxes[i].hi[a] += hi + turn;
    }
  }
}

// Each body's mean surface velocity (over its primitives' corners).
void MeshCollision::mean_velocities() {
  mean_velocity_.assign(3 * std::size_t{body_count_}, 0.0);
  std::vector<double> weight(body_count_, 0.0);
  const auto add = [&](std::span<const std::uint32_t> indices, int arity, std::span<const std::uint32_t> body_of) {
    for (std::size_t i = 0; i < body_of.size(); ++i)
      for (int k = 0; k < arity; ++k) {
        weight[body_of[i]] += 1.0;
        for (int a = 0; a < 3; ++a)
          mean_velocity_[3 * std::size_t{body_of[i]} + a] += velocities_[4 * std::size_t{indices[i * arity + k]} + a];
      }
  };
  add(triangles_, 3, triangle_body_);
  add(segments_, 2, segment_body_);
  for (std::uint32_t b = 0; b < body_count_; ++b)
    for (int a = 0; a < 3; ++a) mean_velocity_[3 * std::size_t{b} + a] /= std::max(weight[b], 1.0);
}

// Only facing contacts (collision::facing) are kept. The others are a
// vertex beside a triangle or two edges that meet end-on, whose normal
// from the closest points is the way round the corner: a plane along it,
// fixed for the frame, would push a vertex that falls past a convex edge
// sideways off it (measured: a block resting across another's edge slid
// off at 0.15 m/s). Those meetings are covered by the facing contacts of
// the neighbouring primitives.
// A solid's surface against itself: the two sides must face each other
// across air (each one's outward normal towards the other), not across the
// body's material (a thin part's two sides; a fold under a probe). A
// vertex's outward direction is its faces' area-weighted normal, an
// edge's the sum of its two faces' unit normals, a triangle's its own.
bool MeshCollision::across_air(const Contact& c) const {
  const std::uint32_t body = body_of_[c.v[0]];
  if (body >= solid_bodies_ || body_of_[c.v[3]] != body) return true;
  const auto along = [&](const float* d) { return c.normal[0] * d[0] + c.normal[1] * d[1] + c.normal[2] * d[2]; };
  float first = 0.0f, second = 0.0f;  // the outward directions along the normal (second towards first)
  if (c.kind == Contact::Kind::vertex_triangle) {
    const std::uint32_t face = solid_face(c.v[1], c.v[2], c.v[3]);
    if (face == UINT32_MAX) return true;
    first = along(&vertex_out_[3 * std::size_t{c.v[0]}]);
    second = along(&face_out_[3 * std::size_t{face}]);
  } else {
    float e[2][3];
    for (int side = 0; side < 2; ++side) {
      if (!solid_edge(c.v[2 * side], c.v[2 * side + 1], e[side])) return true;
    }
    first = along(e[0]);
    second = along(e[1]);
  }
  return first < 0.0f && second > 0.0f;
}

// Each solid surface vertex's area-weighted outward normal (vertex_out_) and
// each solid surface triangle's unit normal (face_out_): across_air's
// outward directions (self-collision only).
void MeshCollision::outward_normals() {
  vertex_out_.assign(3 * positions_.size() / 4, 0.0f);
  face_out_.assign(3 * solid_triangles_, 0.0f);
  for (std::size_t t = 0; t < solid_triangles_; ++t) {
    const std::uint32_t* v = &triangles_[3 * t];
    const auto x = [&](int k, int a) { return positions_[4 * std::size_t{v[k]} + a]; };
    const float u[3] = {x(1, 0) - x(0, 0), x(1, 1) - x(0, 1), x(1, 2) - x(0, 2)};
    const float w[3] = {x(2, 0) - x(0, 0), x(2, 1) - x(0, 1), x(2, 2) - x(0, 2)};
    const float n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int a = 0; a < 3; ++a) {
      face_out_[3 * t + a] = length > 0.0f ? n[a] / length : 0.0f;
      for (int k = 0; k < 3; ++k) vertex_out_[3 * std::size_t{v[k]} + a] += n[a];
    }
  }
}

// The contacts kept: facing, across air, within their pair's own reach
// (given to the narrow phase, which drops the rest as it finds them).
bool MeshCollision::wanted_contact(const Contact& c, double common) const {
  const double dt = time_step_;
  if (suture_exempt(exempt_, c.v)) return false;  // a thread where it runs through a puncture
  if (!collision::facing(c, positions_) || !across_air(c)) return false;
  const bool vertex_triangle = c.kind == Contact::Kind::vertex_triangle;
  const float coefficient[4] = {c.w[0], vertex_triangle ? -c.w[1] : c.w[1], -c.w[2], -c.w[3]};
  double rel[3] = {0.0, 0.0, 0.0};
  for (int k = 0; k < 4; ++k)
    for (int a = 0; a < 3; ++a) rel[a] += double(coefficient[k]) * velocities_[std::size_t{c.v[k]} * 4 + a];
  const double closing = 2.0 * dt * std::sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]);
  return double(c.distance) < common + closing;
}

// Boxes swollen by fast motion can pair most of two surfaces, and every
// pair may make up to 15 contacts: past kMaxPairs the frame stops with an
// error that says why, rather than exhausting memory.
std::size_t MeshCollision::pair_capacity() { return kMaxPairs; }

Status MeshCollision::check_pairs(float reach, float fastest) const {
  if (pairs_.size() <= kMaxPairs) return {};
  return Error(ErrorCode::capacity_exceeded,
               "mesh collision: " + std::to_string(pairs_.size()) + " candidate pairs (at most " +
                   std::to_string(kMaxPairs) + ") within the frame's reach of " + std::to_string(1e3 * reach) +
                   " mm: the fastest collidable particle moves " + std::to_string(fastest) +
                   " m/s; smaller time steps or slower bodies keep the reach short");
}

// The frame's contacts between the meshes, in all_: the triangles'
// (vertex-triangle and edge-edge), then the segments' against segments and
// against triangles, each from its trees refitted to the frame's boxes.
Status MeshCollision::detect_contacts(double common, float reach, float fastest) {
  const collision::ContactFilter wanted = [&](const Contact& c) { return wanted_contact(c, common); };
  const auto keep = [&] { all_.insert(all_.end(), found_.begin(), found_.end()); };
  const auto half = static_cast<float>(0.5 * common);
  if (!triangles_.empty()) {
    if (Status s = refit_triangle_trees(half); !s) return s;
    candidate_pairs<3>(triangle_trees_, triangles_, triangle_trees_, pairs_);
    if (Status s = check_pairs(reach, fastest); !s) return s;
    if (Status s = collision::triangle_contacts(positions_, triangles_, ownership_, pairs_, reach, found_, wanted);
        !s)
      return s;
    keep();
  }
  if (!segments_.empty()) {
    if (Status s = refit_segment_trees(half); !s) return s;
    candidate_pairs<2>(segment_trees_, segments_, segment_trees_, pairs_);
    if (Status s = check_pairs(reach, fastest); !s) return s;
    if (Status s = collision::segment_contacts(positions_, segments_, pairs_, reach, found_, wanted); !s)
      return s;
    keep();
    if (!triangles_.empty()) {
      candidate_pairs<2>(segment_trees_, segments_, triangle_trees_, pairs_);
      if (Status s = check_pairs(reach, fastest); !s) return s;
      if (Status s = collision::segment_triangle_contacts(positions_, segments_, triangles_, pairs_, reach, found_,
                                                              wanted);
          !s)
        return s;
      keep();
    }
  }
  return {};
}

// The primitives' boxes, swept, and each body's trees refitted to them:
// tree with the velocities themselves (only when there is another body
// to pair with), self_tree in the body's own frame of motion
// (self-collision only). A self tree's boxes are computed in its leaf
// order from its vertices gathered there (leaf_vertices.h: the liver's
// surface in bench_broad_phase, boxes + refit 1.9 -> 1.5 ms and the
// cones 2.6 -> 1.7, min of 8); the same floats as in the primitives'
// order, so the same boxes and the same tree.
// [in] half: each primitive's box grows by it all round before the sweep.
Status MeshCollision::fit(std::span<const std::uint32_t> indices, int arity, std::span<const std::uint32_t> body_of,
                          std::vector<BodyTree>& trees, float half) {
  const bool cross = body_count_ > 1;
  const double still[3] = {0.0, 0.0, 0.0};
  if (desc_.self_collision)
    for (std::size_t b = 0; b < trees.size(); ++b) {
      BodyTree& body = trees[b];
      const double* mean = &mean_velocity_[3 * std::size_t{body_of[body.first]}];
      if (body.self_tree.empty()) {  // the first frame: built over the boxes in the primitives' order
        const auto mine = indices.subspan(std::size_t{body.first} * arity, std::size_t{body.count} * arity);
        if (Status s = collision::primitive_boxes(positions_, mine, arity, half, self_boxes_); !s) return s;
        sweep(mine, arity, velocities_, mean, self_boxes_);
        body.self_tree.build(self_boxes_);
        continue;
      }
      body.leaf.boxes(half, self_boxes_);
      body.leaf.gather(velocities_, leaf_velocities_);
      sweep(body.leaf.corners(), arity, leaf_velocities_, mean, self_boxes_);
      if (Status s = body.self_tree.refit_leaves(self_boxes_); !s) return s;
    }
  if (!cross) return {};
  if (Status s = collision::primitive_boxes(positions_, indices, arity, half, boxes_); !s) return s;
  sweep(indices, arity, velocities_, still, boxes_);
  refit(trees, boxes_);
  return {};
}

// Gathers each body's vertices for its self tree (built before this frame).
Status MeshCollision::gather_body(BodyTree& body, std::span<const std::uint32_t> indices, int arity) {
  if (Status s = body.leaf.index(body.self_tree,
                                 indices.subspan(std::size_t{body.first} * arity, std::size_t{body.count} * arity),
                                 arity);
      !s)
    return s;
  return body.leaf.gather(positions_);
}

Status MeshCollision::gather(std::span<const std::uint32_t> indices, int arity, std::vector<BodyTree>& trees) {
  if (!desc_.self_collision) return {};
  for (BodyTree& body : trees)
    if (!body.self_tree.empty())
      if (Status s = gather_body(body, indices, arity); !s) return s;
  return {};
}

// Trees that refitting degraded are rebuilt after it (Bvh::update's rule).
void MeshCollision::rebuild_degraded(std::vector<BodyTree>& trees) {
  const bool cross = body_count_ > 1;
  for (BodyTree& body : trees) {
    if (desc_.self_collision && body.self_tree.degradation() > kMaxDegradation) body.self_tree.rebuild();
    if (cross && body.tree.degradation() > kMaxDegradation) body.tree.rebuild();
  }
}

// The triangle trees refitted (and the degraded ones rebuilt), with their
// normal cones.
Status MeshCollision::refit_triangle_trees(float half) {
  // The normal cones (self-culling) need the positions and the self
  // trees' shapes only, not their boxes: they are updated on a second
  // thread while the boxes are computed and refitted (the liver's
  // surface, bench_broad_phase: 6.72 -> 6.12 ms per frame on 2 cores; the
  // organ example: no measurable change). A tree built or rebuilt
  // meanwhile has a new shape: its cones are redone.
  const bool cull = desc_.self_collision && desc_.self_culling;
  std::vector<std::uint64_t> shape(triangle_trees_.size());
  for (std::size_t b = 0; b < triangle_trees_.size(); ++b) shape[b] = triangle_trees_[b].self_tree.build_id();
  const auto cones_of = [&](BodyTree& body) {
    body.cones.update(body.self_tree,
                      std::span<const std::uint32_t>(triangles_).subspan(std::size_t{body.first} * 3,
                                                                         std::size_t{body.count} * 3),
                      body.leaf);
  };
  if (Status s = gather(triangles_, 3, triangle_trees_); !s) return s;
  // Only trees built before this frame: a first build happens inside fit,
  // beside the cones (shape[b] == 0 until then; build ids start at 1).
  Status fitted;
  hooks::parallel_invoke({[&] { fitted = fit(triangles_, 3, triangle_body_, triangle_trees_, half); },
                          [&] {
                            if (!cull) return;
                            for (std::size_t b = 0; b < triangle_trees_.size(); ++b)
                              if (shape[b] != 0) cones_of(triangle_trees_[b]);
                          }});
  if (!fitted) return fitted;
  rebuild_degraded(triangle_trees_);
  if (cull)
    for (std::size_t b = 0; b < triangle_trees_.size(); ++b)
      if (triangle_trees_[b].self_tree.build_id() != shape[b]) {
        // A new shape: the vertices gathered anew in its leaf order.
        if (Status s = gather_body(triangle_trees_[b], triangles_, 3); !s) return s;
        cones_of(triangle_trees_[b]);
      }
  return {};
}

// The segment trees refitted (and the degraded ones rebuilt).
Status MeshCollision::refit_segment_trees(float half) {
  if (Status s = gather(segments_, 2, segment_trees_); !s) return s;
  if (Status s = fit(segments_, 2, segment_body_, segment_trees_, half); !s) return s;
  rebuild_degraded(segment_trees_);
  return {};
}

// Candidate pairs (global primitive indices) between the bodies of `a`
// (primitives of `Arity` vertices in `indices`) and those of `b`: when a
// and b are the same set, every body against every later one, and each
// against itself when self-collision is on (skipping primitives that share
// a vertex); otherwise every body of a against every body of b. A body's
// own pairs are never visited when self-collision is off, so a scene pays
// nothing for the self-pairs it does not want.
// Triangle surfaces skip their flat patches' self-pairs (normal_cones.h)
// unless desc_.self_culling is off.
template <int Arity>
void MeshCollision::candidate_pairs(std::vector<BodyTree>& a, std::span<const std::uint32_t> indices,
                                    const std::vector<BodyTree>& b, std::vector<collision::Pair>& pairs) {
  pairs.clear();
  const bool same = &a == &b;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (same && desc_.self_collision) {
      const auto mine = indices.subspan(std::size_t{a[i].first} * Arity, std::size_t{a[i].count} * Arity);
      // Skipped: pairs that share a vertex, and those closer than the
      // thickness at rest (triangles only; rest_close.h).
      const collision::SharesVertexOrListed<Arity> skip{{mine}, a[i].rest_close.empty() ? nullptr : &a[i].rest_close};
      const collision::NormalCones* cones = Arity == 3 && desc_.self_culling ? &a[i].cones : nullptr;
      collision::self_overlapping_pairs_parallel(a[i].self_tree, skip, local_, cones);
      for (const auto& [p, q] : local_) pairs.push_back({a[i].first + p, a[i].first + q});
    }
    for (std::size_t j = same ? i + 1 : 0; j < b.size(); ++j) {
      collision::overlapping_pairs(a[i].tree, b[j].tree, local_);
      for (const auto& [p, q] : local_) pairs.push_back({a[i].first + p, b[j].first + q});
    }
  }
}

// Keeps, of the frame's contacts, the nearest few that matter (see
// mesh_collision.h): where a coarse surface lies on a finer one, every
// vertex finds dozens of triangles and every edge dozens of edges within the
// reach, hundreds of contacts per vertex that say the same thing (measured:
// the kidney landing on the liver's surface, 538 contacts on one vertex, as
// many colours). A vertex-triangle contact stays when it is its vertex's
// nearest against that other body and, for an immovable vertex, among its
// triangle's kPerTriangle nearest; an edge-edge contact when it is among the kPerEdge nearest of
// both its edges against the other edge's body. Ties go to
// the earlier contact (the narrow phase's sorted order), so the result is
// deterministic.
void MeshCollision::prune() {
  keys_.clear();
  triangle_keys_.clear();
  const auto edge = [](std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
  };
  for (std::uint32_t k = 0; k < all_.size(); ++k) {
    const Contact& c = all_[k];
    if (c.kind == Contact::Kind::vertex_triangle) {
      keys_.push_back({c.v[0], body_of_[c.v[1]], c.distance, k});
      std::array<std::uint32_t, 3> t{c.v[1], c.v[2], c.v[3]};
      std::sort(t.begin(), t.end());
      triangle_keys_.push_back({t, body_of_[c.v[0]], c.distance, k});
    } else {
      keys_.push_back({edge(c.v[0], c.v[1]), body_of_[c.v[2]] | 0x80000000u, c.distance, k});
      keys_.push_back({edge(c.v[2], c.v[3]), body_of_[c.v[0]] | 0x80000000u, c.distance, k});
    }
  }
  std::sort(keys_.begin(), keys_.end());
  std::sort(triangle_keys_.begin(), triangle_keys_.end());
  // Vertex-triangle: the vertex's nearest. Edge-edge: among the
  // kPerEdge nearest of both of its edges (a coarse edge over a fine
  // surface crosses dozens of fine edges, each of which would keep it).
  chosen_.assign(all_.size(), 1);
  std::size_t rank = 0;
  for (std::size_t i = 0; i < keys_.size(); ++i) {
    const bool same =
        i > 0 && keys_[i].primitive == keys_[i - 1].primitive && keys_[i].body == keys_[i - 1].body;
    rank = same ? rank + 1 : 0;
    const bool edge_key = (keys_[i].body & 0x80000000u) != 0;
    if (rank >= (edge_key ? kPerEdge : 1)) chosen_[keys_[i].contact] = 0;
  }
  // A vertex-triangle contact of an immovable vertex also has to be among
  // its triangle's kPerTriangle nearest against the vertex's body: a coarse
  // triangle over a fine fixed surface otherwise keeps one contact per
  // fine vertex under it, all on the same three particles (a coarse block
  // on a pinned 1 mm grid: 4,562 contacts in 638 colours). A movable vertex
  // keeps its nearest whatever the triangle's count: it is what holds that
  // vertex out (capping those too let the kidney, pressed by the example's
  // probe, into the liver by 0.8 mm).
  rank = 0;
  for (std::size_t i = 0; i < triangle_keys_.size(); ++i) {
    const bool same = i > 0 && triangle_keys_[i].primitive == triangle_keys_[i - 1].primitive &&
                      triangle_keys_[i].body == triangle_keys_[i - 1].body;
    rank = same ? rank + 1 : 0;
    if (rank >= kPerTriangle && !movable_[all_[triangle_keys_[i].contact].v[0]])
      chosen_[triangle_keys_[i].contact] = 0;
  }
  std::size_t kept = 0;
  for (std::size_t k = 0; k < all_.size(); ++k)
    if (chosen_[k]) all_[kept++] = all_[k];
  all_.resize(kept);
}

}  // namespace sinew
