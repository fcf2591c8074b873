// mesh_collision.cpp — the host side of the contacts between meshes (see
// mesh_collision.h): once per frame, read the positions back, refit the
// BVHs over boxes inflated by half the reach (thickness + motion margin),
// find the candidate pairs and the contacts closer than the reach, colour
// them (greedy, coloring/greedy_coloring.h) and upload them colour-sorted.
#include "runtime/mesh_collision.h"
#include "runtime/suture_exemption.h"

#include "collision/shape_distance.h"
#include "mesh/tet_faces.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <span>
#include <string>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "coloring/greedy_coloring.h"
#include "collision/parallel_pairs.h"
#include "collision/shape_distance.h"
#include "mesh/tet_faces.h"
#include "sinew/mesh.h"

namespace sinew {
namespace {

using collision::Contact;

constexpr std::uint32_t kFirstColors = 16;
// Colours kept free for continuous collision's contacts at first (doubled,
// up to 32, when a frame needs more: append_contacts).
constexpr std::uint32_t kContinuousColors = 8;
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

// A contact's coefficients c_k (mesh_contact_params.h) from its weights.
void coefficients_of(const collision::Contact& c, float out[4]) {
  const bool vertex_triangle = c.kind == collision::Contact::Kind::vertex_triangle;
  const float sign = c.kind == collision::Contact::Kind::shape_face ? 1.0f : -1.0f;  // both weights on the triangle's side
  out[0] = c.w[0];
  out[1] = vertex_triangle ? -c.w[1] : c.w[1];
  out[2] = sign * c.w[2];
  out[3] = sign * c.w[3];
}

Status make(Device& device, std::size_t bytes, const char* label, BufferHandle& handle) {
  auto made = device.create_buffer(std::max<std::size_t>(bytes, 16), label);
  if (!made) return made.error();
  handle = *made;
  return {};
}

// The runs of `body_of` (one body's primitives are contiguous): per body
// of `bodies`, its (first, count); count 0 for a body with none.
std::vector<std::pair<std::uint32_t, std::uint32_t>> body_ranges(const std::vector<std::uint32_t>& body_of,
                                                                 std::uint32_t bodies) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges(bodies, {0u, 0u});
  for (std::uint32_t k = 0; k < body_of.size(); ++k) {
    auto& r = ranges[body_of[k]];
    if (r.second == 0) r.first = k;
    ++r.second;
  }
  return ranges;
}

}  // namespace

Result<std::unique_ptr<MeshCollision>> MeshCollision::create(const SceneDesc& scene, const CompiledScene& compiled,
                                                             Device& device) {
  auto mc = std::unique_ptr<MeshCollision>(new MeshCollision());
  mc->desc_ = scene.mesh_collision;
  mc->time_step_ = scene.solver.time_step;
  mc->solid_bodies_ = static_cast<std::uint32_t>(scene.tet_bodies.size());
  mc->gravity_ = std::hypot(scene.gravity[0], scene.gravity[1], scene.gravity[2]);
  const auto& device_of = compiled.order.device_of;
  std::uint32_t body = 0;
  mc->body_count_ = static_cast<std::uint32_t>(scene.tet_bodies.size() + scene.tri_bodies.size() + scene.line_bodies.size());
  mc->movable_.resize(compiled.positions.size());
  for (std::size_t p = 0; p < compiled.positions.size(); ++p) mc->movable_[p] = compiled.positions[p].w > 0.0f;
  // With topology changes the boundary comes from the faces' index that
  // update_topology keeps (the same triangles, in the same order).
  if (scene.topology_changes) mc->index_tet_faces(scene, compiled);
  for (std::size_t b = 0; b < scene.tet_bodies.size(); ++b, ++body) {
    if (scene.topology_changes) {
      mc->boundary_triangles(mc->tet_faces_[b], mc->triangles_);
    } else {
      const std::uint32_t first = compiled.tet_body_first_particle[b];
      for (const auto& f : extract_boundary_surface(scene.tet_bodies[b].mesh).triangles)
        for (std::uint32_t v : f) mc->triangles_.push_back(device_of[first + v]);
    }
    mc->triangle_body_.resize(mc->triangles_.size() / 3, body);
  }
  for (std::size_t b = 0; b < scene.tri_bodies.size(); ++b, ++body) {
    const std::uint32_t first = compiled.tri_body_first_particle[b];
    for (const auto& f : scene.tri_bodies[b].mesh.triangles) {
      for (std::uint32_t v : f) mc->triangles_.push_back(device_of[first + v]);
      mc->triangle_body_.push_back(body);
    }
  }
  for (std::size_t b = 0; b < scene.line_bodies.size(); ++b, ++body) {
    const std::uint32_t first = compiled.line_body_first_particle[b];
    for (const auto& s : scene.line_bodies[b].segments) {
      for (std::uint32_t v : s) mc->segments_.push_back(device_of[first + v]);
      mc->segment_body_.push_back(body);
    }
  }
  // One tree per body with primitives: contiguous runs of triangle_body_ / segment_body_.
  const auto trees_of = [&](const std::vector<std::uint32_t>& body_of, std::vector<BodyTree>& trees) {
    for (const auto& [first, count] : body_ranges(body_of, mc->body_count_))
      if (count > 0) {
        trees.emplace_back();
        trees.back().first = first;
        trees.back().count = count;
      }
  };
  trees_of(mc->triangle_body_, mc->triangle_trees_);
  trees_of(mc->segment_body_, mc->segment_trees_);
  mc->index_primitives();
  if (mc->desc_.self_collision) {
    std::vector<float> start(4 * compiled.positions.size());
    for (std::size_t p = 0; p < compiled.positions.size(); ++p) {
      const auto& x = compiled.positions[p];
      start[4 * p] = x.x, start[4 * p + 1] = x.y, start[4 * p + 2] = x.z, start[4 * p + 3] = 0.0f;
    }
    if (Status s = mc->find_rest_close(start); !s) return s.error();
  }

  // A first guess of the room needed (4 contacts per surface vertex, 16
  // colours); before_frame grows both when a frame needs more.
  MeshContactBuffers& b = mc->buffers_;
  b.capacity = std::max<std::uint32_t>(1024, 4 * static_cast<std::uint32_t>(mc->collidable_.size()));
  b.colors = kFirstColors;
  const std::size_t contact_bytes = std::size_t{b.capacity} * 16;
  for (auto [handle, bytes, label] :
       {std::tuple{&b.table, std::size_t{2} * b.colors * 4, "mesh contact table"},
        std::tuple{&b.particles, contact_bytes, "mesh contact particles"},
        std::tuple{&b.coefficients, contact_bytes, "mesh contact coefficients"},
        std::tuple{&b.normals, contact_bytes, "mesh contact normals"},
        std::tuple{&b.lambda, contact_bytes, "mesh contact lambdas"},
        std::tuple{&b.lambda_sum, contact_bytes, "mesh contact lambda sums"},
        std::tuple{&b.motion, contact_bytes / 4, "mesh contact plane motions"}})
    if (Status s = make(device, bytes, label, *handle); !s) return s.error();
  b.jacobi = mc->desc_.schedule == ContactSchedule::jacobi;
  b.touched_capacity = static_cast<std::uint32_t>(mc->collidable_.size());
  for (auto [handle, bytes, label] :
       {std::tuple{&b.delta, b.jacobi ? 4 * contact_bytes : 16, "mesh contact corrections"},
        std::tuple{&b.touched, b.jacobi ? std::size_t{b.touched_capacity} * 4 : 16, "mesh contact particles touched"},
        std::tuple{&b.offsets, b.jacobi ? std::size_t{b.touched_capacity + 1} * 4 : 16, "mesh contact offsets"},
        std::tuple{&b.slots, b.jacobi ? contact_bytes : 16, "mesh contact slots"}})
    if (Status s = make(device, bytes, label, *handle); !s) return s.error();
  if (mc->desc_.continuous) {
    // Room for the touches of continuous collision detection (append_contacts).
    mc->reserve_colors_ = kContinuousColors;
    mc->reserve_slots_ = std::max<std::uint32_t>(256, static_cast<std::uint32_t>(mc->segments_.size()));
  }
  b.params.thickness = static_cast<float>(mc->desc_.thickness);
  b.params.compliance = static_cast<float>(mc->desc_.compliance);
  b.params.static_friction = static_cast<float>(mc->desc_.static_friction);
  b.params.dynamic_friction = static_cast<float>(mc->desc_.dynamic_friction);
  return mc;
}

Status MeshCollision::release(Device& device) {
  MeshContactBuffers& b = buffers_;
  for (BufferHandle* h : {&b.table, &b.particles, &b.coefficients, &b.normals, &b.lambda, &b.lambda_sum, &b.motion,
                          &b.delta, &b.touched, &b.offsets, &b.slots})
    if (h->valid()) {
      if (Status s = device.destroy_buffer(*h); !s) return s;
      *h = {};
    }
  return {};
}

// The broad phase at the start (boxes grown by half the thickness: every
// pair closer than it overlaps), then the exact distance of each candidate.
// A mesh's fissures and sharp creases, closer than the thickness before
// anything moves, would otherwise be pushed apart to it in the first frame:
// the liver_382k surface at 1 mm has 683 facing vertex-triangle contacts at
// rest, the nearest 0.03 mm, and with self-collision on the organ example
// blew up (28 m/s by frame 20, then the pair capacity error).
Status MeshCollision::find_rest_close(std::span<const float> start) {
  std::vector<collision::Pair> pairs;
  for (BodyTree& body : triangle_trees_) {
    const auto mine = std::span<const std::uint32_t>(triangles_).subspan(std::size_t{body.first} * 3,
                                                                         std::size_t{body.count} * 3);
    if (Status s = collision::rest_close_pairs(start, mine, static_cast<float>(desc_.thickness), pairs); !s) return s;
    body.rest_close = collision::PairSet(pairs, body.count);
  }
  return {};
}

// The solid surface triangles around each particle, ascending (a counting
// sort): an edge's faces are among its lower vertex's.
void MeshCollision::index_solid_edges() {
  solid_first_.assign(movable_.size() + 1, 0);
  for (std::size_t k = 0; k < 3 * solid_triangles_; ++k) ++solid_first_[std::size_t{triangles_[k]} + 1];
  for (std::size_t p = 0; p < movable_.size(); ++p) solid_first_[p + 1] += solid_first_[p];
  solid_around_.resize(3 * solid_triangles_);
  std::vector<std::uint32_t> next(solid_first_.begin(), solid_first_.end() - 1);
  for (std::uint32_t t = 0; t < solid_triangles_; ++t)
    for (int k = 0; k < 3; ++k) solid_around_[next[triangles_[3 * std::size_t{t} + k]]++] = t;
}

template <class Visit>
void MeshCollision::faces_on(std::uint32_t a, std::uint32_t b, Visit visit) const {
  const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
  if (std::size_t{lo} + 1 >= solid_first_.size()) return;
  std::uint32_t last = UINT32_MAX;
  for (std::uint32_t k = solid_first_[lo]; k < solid_first_[lo + 1]; ++k) {
    const std::uint32_t t = solid_around_[k];
    if (t == last) continue;  // a triangle listed twice around lo (a degenerate one)
    last = t;
    const std::uint32_t* v = &triangles_[3 * std::size_t{t}];
    for (int e = 0; e < 3; ++e)  // once per edge of t that is {lo, hi}
      if (std::min(v[e], v[(e + 1) % 3]) == lo && std::max(v[e], v[(e + 1) % 3]) == hi) visit(t);
  }
}

std::uint32_t MeshCollision::solid_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
  std::uint32_t found = UINT32_MAX;
  faces_on(a, b, [&](std::uint32_t t) {
    const std::uint32_t* v = &triangles_[3 * std::size_t{t}];
    if (found == UINT32_MAX && (v[0] == c || v[1] == c || v[2] == c)) found = t;
  });
  return found;
}

bool MeshCollision::solid_edge(std::uint32_t a, std::uint32_t b, float out[3]) const {
  bool any = false;
  out[0] = out[1] = out[2] = 0.0f;
  faces_on(a, b, [&](std::uint32_t t) {
    any = true;
    for (int d = 0; d < 3; ++d) out[d] += face_out_[3 * std::size_t{t} + d];
  });
  return any;
}

void MeshCollision::index_primitives(bool ownership) {
  const std::size_t particles = movable_.size();
  body_of_.assign(particles, UINT32_MAX);
  for (std::size_t t = 0; t < triangle_body_.size(); ++t)
    for (int k = 0; k < 3; ++k) body_of_[triangles_[3 * t + k]] = triangle_body_[t];
  for (std::size_t t = 0; t < segment_body_.size(); ++t)
    for (int k = 0; k < 2; ++k) body_of_[segments_[2 * t + k]] = segment_body_[t];
  if (ownership) ownership_ = collision::triangle_ownership(triangles_);
  solid_triangles_ = 0;
  while (solid_triangles_ < triangle_body_.size() && triangle_body_[solid_triangles_] < solid_bodies_) ++solid_triangles_;
  if (desc_.self_collision) index_solid_edges();
  // Every particle of a primitive, ascending.
  std::vector<std::uint8_t> used(particles, 0);
  for (std::uint32_t v : triangles_) used[v] = 1;
  for (std::uint32_t v : segments_) used[v] = 1;
  collidable_.clear();
  for (std::uint32_t p = 0; p < particles; ++p)
    if (used[p]) collidable_.push_back(p);
}

namespace {

// Sorts (key, value) pairs by key, stably: least significant digit first,
// 11 bits a pass, as many passes as `bits` needs.
void radix_sort(std::vector<std::pair<std::uint64_t, std::uint32_t>>& items, int bits) {
  constexpr int kDigit = 11;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> other(items.size());
  std::vector<std::uint32_t> count(std::size_t{1} << kDigit);
  for (int shift = 0; shift < bits; shift += kDigit) {
    std::fill(count.begin(), count.end(), 0u);
    for (const auto& item : items) ++count[(item.first >> shift) & ((1u << kDigit) - 1)];
    std::uint32_t sum = 0;
    for (std::uint32_t& c : count) sum += std::exchange(c, sum);
    for (const auto& item : items) other[count[(item.first >> shift) & ((1u << kDigit) - 1)]++] = item;
    items.swap(other);
  }
}

}  // namespace

// Each tet body's faces grouped by their three vertices (a radix sort of
// the packed sorted triples; a plain sort where they do not fit in 64
// bits), linked into rings; the boundary is the faces alone in theirs, as
// extract_boundary_surface finds it. With self-collision, the tets' rest
// boxes too (update_rest_close).
void MeshCollision::index_tet_faces(const SceneDesc& scene, const CompiledScene& compiled) {
  device_of_ = compiled.order.device_of;
  tri_first_.assign(compiled.tri_body_first_particle.begin(), compiled.tri_body_first_particle.end());
  line_first_.assign(compiled.line_body_first_particle.begin(), compiled.line_body_first_particle.end());
  rest_positions_.assign(4 * compiled.positions.size(), 0.0f);
  for (std::size_t p = 0; p < compiled.positions.size(); ++p) {
    const auto& x = compiled.positions[p];
    rest_positions_[4 * p] = x.x, rest_positions_[4 * p + 1] = x.y, rest_positions_[4 * p + 2] = x.z;
  }
  tet_faces_.resize(scene.tet_bodies.size());
  for (std::size_t b = 0; b < scene.tet_bodies.size(); ++b) {
    TetFaces& f = tet_faces_[b];
    const TetMesh& mesh = scene.tet_bodies[b].mesh;
    f.first_particle = compiled.tet_body_first_particle[b];
    f.tets = mesh.tets;
    f.alive.assign(f.tets.size(), 1);
    const std::size_t slots = 4 * f.tets.size();
    int bits = 1;
    while (bits < 32 && (std::uint64_t{1} << bits) < mesh.vertices.size()) ++bits;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(slots);
    std::vector<std::array<std::uint32_t, 3>> triples(3 * bits > 64 ? slots : 0);
    for (std::uint32_t s = 0; s < slots; ++s) {
      const auto& tet = f.tets[s / 4];
      std::array<std::uint32_t, 3> v{tet[kOutwardFaces[s % 4][0]], tet[kOutwardFaces[s % 4][1]],
                                     tet[kOutwardFaces[s % 4][2]]};
      std::sort(v.begin(), v.end());
      if (3 * bits > 64) triples[s] = v;
      else keys[s] = {(std::uint64_t{v[0]} << (2 * bits)) | (std::uint64_t{v[1]} << bits) | v[2], s};
    }
    if (3 * bits > 64) {  // over 2^21 vertices
      std::vector<std::uint32_t> order(slots);
      std::iota(order.begin(), order.end(), 0u);
      std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return triples[x] < triples[y]; });
      std::uint64_t group = 0;
      for (std::size_t k = 0; k < slots; ++k) {
        if (k > 0 && triples[order[k]] != triples[order[k - 1]]) ++group;
        keys[k] = {group, order[k]};
      }
    } else {
      radix_sort(keys, 3 * bits);
    }
    f.twin.resize(slots);
    f.on_boundary.assign(slots, 0);
    f.boundary.clear();
    for (std::size_t k = 0; k < slots;) {
      std::size_t end = k + 1;
      while (end < slots && keys[end].first == keys[k].first) ++end;
      for (std::size_t j = k; j < end; ++j) f.twin[keys[j].second] = keys[j + 1 < end ? j + 1 : k].second;
      if (end == k + 1) f.on_boundary[keys[k].second] = 1;
      k = end;
    }
    for (std::uint32_t s = 0; s < slots; ++s)
      if (f.on_boundary[s]) f.boundary.push_back(s);
    if (desc_.self_collision) {
      const auto half = static_cast<float>(0.5 * desc_.thickness);
      std::vector<collision::Aabb> boxes(f.tets.size());
      for (std::size_t t = 0; t < f.tets.size(); ++t) {
        collision::Aabb& box = boxes[t];
        box = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
        for (std::uint32_t v : f.tets[t])
          for (int a = 0; a < 3; ++a) {
            const float x = rest_positions_[4 * std::size_t{device_of_[f.first_particle + v]} + a];
            box.lo[a] = std::min(box.lo[a], x - half), box.hi[a] = std::max(box.hi[a], x + half);
          }
      }
      f.rest_tree.build(boxes);
    }
  }
}

void MeshCollision::boundary_triangles(const TetFaces& faces, std::vector<std::uint32_t>& out) const {
  for (std::uint32_t s : faces.boundary) {
    const auto& tet = faces.tets[s / 4];
    for (int k : kOutwardFaces[s % 4]) out.push_back(device_of_[faces.first_particle + tet[std::size_t(k)]]);
  }
}

std::uint32_t MeshCollision::rest_close_pairs() const {
  std::size_t sum = 0;
  for (const BodyTree& body : triangle_trees_) sum += body.rest_close.size();
  return static_cast<std::uint32_t>(sum);
}

void MeshCollision::refit(std::vector<BodyTree>& trees, std::span<const collision::Aabb> boxes) {
  for (BodyTree& t : trees) {
    const auto mine = boxes.subspan(t.first, t.count);
    if (t.tree.empty()) t.tree.build(mine);
    else t.tree.refit(mine);
  }
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

// The velocities that set the reach are the frame's mean ones, (end - start)
// / dt, not the device's, which are the last substep's: after an impact those
// carry the jitter of single corrections (measured: a kidney landing on the
// liver's surface showed 1.4-2.4 m/s after a 0.3 m/s fall), and a reach
// grown from them paired most of both surfaces, frame after frame. Only the
// first frame, with no previous positions, reads the device's velocities.
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

Status MeshCollision::read_back(Device& device, const XpbdBuffers& scene_buffers) {
  const std::size_t particles = movable_.size();
  const bool have_start = positions_.size() == particles * 4;
  if (have_start) start_positions_.swap(positions_);
  positions_.resize(particles * 4);
  velocities_.resize(particles * 4);
  if (mirror_) {
    if (Status s = mirror_->copy_to(device, scene_buffers.position, particles * 4, positions_); !s) return s;
  } else {
    if (Status s = device.read_buffer(scene_buffers.position, 0, positions_.data(), positions_.size() * 4); !s) return s;
    read_back_bytes_ += positions_.size() * 4;
  }
  if (have_start) {
    const auto inv_dt = static_cast<float>(1.0 / time_step_);
    for (std::size_t k = 0; k < positions_.size(); ++k)
      velocities_[k] = inv_dt * (positions_[k] - start_positions_[k]);
  } else if (Status s = device.read_buffer(scene_buffers.velocity, 0, velocities_.data(), velocities_.size() * 4);
             !s) {
    return s;
  } else {
    read_back_bytes_ += velocities_.size() * 4;
  }
  fresh_ = true;
  return {};
}

Status MeshCollision::after_frame(Device& device, const XpbdBuffers& scene_buffers) {
  if (Status s = read_back(device, scene_buffers); !s) return s;
  // The multipliers of the contacts with tools (their reaction): the whole
  // frame's contacts are read, those few picked out in add_tool_reactions.
  if (!tool_slots_.empty()) {
    const std::size_t slots = contact_count_ + appended_.size();  // continuous collision's too
    const std::size_t bytes = slots * 16;
    tool_lambda_.resize(slots * 4);
    tool_lambda_sum_.resize(slots * 4);
    if (Status s = device.read_buffer(buffers_.lambda, 0, tool_lambda_.data(), bytes); !s) return s;
    if (Status s = device.read_buffer(buffers_.lambda_sum, 0, tool_lambda_sum_.data(), bytes); !s) return s;
    read_back_bytes_ += 2 * bytes;
  }
  // How far the frame's contacts ended inside their thickness, from the
  // very positions the next frame's detection starts from.
  double worst = 0.0;
  const auto slots = contact_count_ + static_cast<std::uint32_t>(appended_.size());
  for (std::uint32_t k = 0; k < slots; ++k) {
    double gap = 0.0;
    for (int a = 0; a < 3; ++a) {
      double along = 0.0;
      for (int j = 0; j < 4; ++j)
        along += double(upload_coefficients_[4 * std::size_t{k} + j]) *
                 positions_[4 * std::size_t{upload_particles_[4 * std::size_t{k} + j]} + a];
      gap += along * upload_normals_[4 * std::size_t{k} + a];
    }
    gap += upload_normals_[4 * std::size_t{k} + 3];  // the offset (shape contacts)
    worst = std::max(worst, desc_.thickness - gap);
  }
  violation_ = worst;
  return {};
}

void MeshCollision::add_tool_reactions(std::vector<ToolBody>& tools, double frame, double h) const {
  using V3 = math::Vec3;
  for (const auto& [slot, t] : tool_slots_) {
    if (t >= tools.size()) continue;
    ToolBody& tool = tools[t];
    const std::size_t at = std::size_t{slot} * 4;
    const V3 n{upload_normals_[at], upload_normals_[at + 1], upload_normals_[at + 2]};
    // The multiplier as a vector, lambda_n n + lambda_t [kg m].
    const auto vector_of = [&](const std::vector<float>& l) {
      return math::add(math::mul(n, double(l[at])), V3{l[at + 1], l[at + 2], l[at + 3]});
    };
    const V3 last = vector_of(tool_lambda_);
    const V3 earlier = vector_of(tool_lambda_sum_);
    // The contact's point on the triangle or segment at the frame's end.
    V3 point{0.0, 0.0, 0.0};
    for (int k = 0; k < 4; ++k)
      for (int a = 0; a < 3; ++a)
        point[a] += double(upload_coefficients_[at + k]) * positions_[4 * std::size_t{upload_particles_[at + k]} + a];
    const V3 r = math::sub(point, tool.position);
    // The tissue was pushed by +lambda / h per substep; the tool takes the opposite.
    const V3 frame_impulse = math::mul(math::add(earlier, last), -1.0 / h);
    const V3 last_impulse = math::mul(last, -1.0 / h);
    tool.contact_force = math::add(tool.contact_force, math::mul(frame_impulse, 1.0 / frame));
    tool.contact_torque = math::add(tool.contact_torque, math::mul(math::cross(r, frame_impulse), 1.0 / frame));
    tool.coupling_force = math::add(tool.coupling_force, math::mul(last_impulse, 1.0 / h));
    tool.coupling_torque = math::add(tool.coupling_torque, math::mul(math::cross(r, last_impulse), 1.0 / h));
    if (!(tool_lambda_[at] > 0.0f)) continue;  // not touching at the frame's end
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t p = upload_particles_[at + k];
      const double c = upload_coefficients_[at + k], w = positions_[4 * std::size_t{p} + 3];
      if (!(c > 0.0) || !(w > 0.0)) continue;
      const double m = c / w;
      const V3 rk = math::sub(V3{positions_[4 * std::size_t{p}], positions_[4 * std::size_t{p} + 1],
                                 positions_[4 * std::size_t{p} + 2]},
                              tool.position);
      tool.touching_mass += m;
      const double r2 = math::dot(rk, rk);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          tool.touching_inertia[std::size_t(3 * i + j)] += m * ((i == j ? r2 : 0.0) - rk[i] * rk[j]);
    }
  }
}

namespace {

// A capsule's ends (the segment its radius swells) at a pose.
std::array<math::Vec3, 2> capsule_ends(const PosedShape& s) {
  const math::Vec3 axis = math::rotate(s.rotation, math::Vec3{0.0, s.shape->half_height, 0.0});
  return {math::sub(s.position, axis), math::add(s.position, axis)};
}

// A point of a shape's frame [m] at the shape's pose.
math::Vec3 carried(const PosedShape& s, const math::Vec3& local) {
  return math::add(s.position, math::rotate(s.rotation, local));
}

}  // namespace

void MeshCollision::shape_faces(std::span<const PosedShape> shapes, std::span<const PosedShape> ends, double common) {
  const double dt = time_step_;
  const std::size_t triangles = triangle_body_.size();
  const bool tools = !ends.empty();
  for (std::size_t index = 0; index < shapes.size(); ++index) {
    const PosedShape& shape = shapes[index];
    const std::uint32_t which = tools ? static_cast<std::uint32_t>(index) : Contact::kNoShape;
    // A tool: how far any point of its capsule moves in the frame (its
    // segment's ends move linearly between the poses, and so bound it), and
    // the offset of the plane that touches it where it ends, on the face's
    // side (n points from the tool to the face): thickness - the largest
    // n . p over the capsule.
    // A level-set tool: the bound from its box's corners (a rigid motion's
    // displacement is affine in the point, so its length is convex and
    // largest at a corner), and the plane through the contact's surface
    // point carried along with the tool (its surface there, to first order).
    const bool level_set = tools && shape.shape->shape == ColliderShape::level_set;
    double moved = 0.0;
    std::array<math::Vec3, 2> first{}, last{};
    if (level_set) {
      const std::array<double, 6> box = shape.shape->level_set->bounds();
      for (int corner = 0; corner < 8; ++corner) {
        const math::Vec3 local{box[corner & 1 ? 3 : 0], box[corner & 2 ? 4 : 1], box[corner & 4 ? 5 : 2]};
        moved = std::max(moved, math::norm(math::sub(carried(ends[index], local), carried(shape, local))));
      }
    } else if (tools) {
      first = capsule_ends(shape);
      last = capsule_ends(ends[index]);
      for (int k = 0; k < 2; ++k) moved = std::max(moved, math::norm(math::sub(last[k], first[k])));
    }
    const auto offset_at = [&](const std::array<math::Vec3, 2>& ends_at, const math::Vec3& n) {
      return desc_.thickness - (std::max(math::dot(n, ends_at[0]), math::dot(n, ends_at[1])) + shape.shape->radius);
    };
    // The contact plane's offset at the frame's end and its motion over the
    // frame, for a tool (c.offset, c.motion) given its surface point at the
    // start, or for a collider (at rest over the frame).
    const auto plane = [&](Contact& c, const math::Vec3& normal, const math::Vec3& surface) {
      if (level_set) {
        const math::Vec3 local = math::rotate(math::conj(shape.rotation), math::sub(surface, shape.position));
        c.offset = float(desc_.thickness - math::dot(normal, carried(ends[index], local)));
        c.motion = float(desc_.thickness - math::dot(normal, surface)) - c.offset;
      } else if (tools) {
        c.offset = float(offset_at(last, normal));
        c.motion = float(offset_at(first, normal)) - c.offset;
      } else {
        c.offset = float(desc_.thickness - math::dot(normal, surface));
      }
    };
    if (shape.shape->shape == ColliderShape::plane) continue;
    // Triangles in parallel (one evaluation each for most), joined in
    // triangle order so the contacts do not depend on the threads.
    found_.assign(triangles, Contact{});
    face_hit_.assign(triangles, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, triangles, 256), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t t = r.begin(); t < r.end(); ++t) {
        const std::uint32_t* v = &triangles_[3 * t];
        if (!movable_[v[0]] && !movable_[v[1]] && !movable_[v[2]]) continue;
        math::Vec3 corner[3];
        float speed = 0.0f;
        for (int k = 0; k < 3; ++k) {
          for (int a = 0; a < 3; ++a) corner[k][a] = positions_[4 * std::size_t{v[k]} + a];
          speed = std::max(speed, speed_[v[k]]);
        }
        collision::TriangleContact hit;
        if (!collision::triangle_against(*shape.shape, shape.position, shape.rotation, corner[0], corner[1],
                                         corner[2], common + 2.0 * dt * speed + moved, hit))
          continue;
        if (std::max({hit.weights[0], hit.weights[1], hit.weights[2]}) > 1.0 - 1e-6) continue;  // a corner
        Contact& c = found_[t];
        c.kind = Contact::Kind::shape_face;
        c.v = {v[0], v[0], v[1], v[2]};
        c.w = {0.0f, float(hit.weights[0]), float(hit.weights[1]), float(hit.weights[2])};
        c.normal = {float(hit.normal[0]), float(hit.normal[1]), float(hit.normal[2])};
        c.distance = float(hit.distance);
        plane(c, hit.normal, hit.surface);
        c.shape = which;
        face_hit_[t] = 1;
      }
    });
    for (std::size_t t = 0; t < triangles; ++t)
      if (face_hit_[t]) all_.push_back(found_[t]);
    // Segments (threads): the point deepest in the shape along each, by
    // golden-section search (collision::capsule_against, radius 0), kept
    // between its ends, on particles (a, a, b, b) with c = (0, 1 - s, 0, s).
    for (std::size_t e = 0; e < segment_body_.size(); ++e) {
      const std::uint32_t* v = &segments_[2 * e];
      if (!movable_[v[0]] && !movable_[v[1]]) continue;
      math::Vec3 end[2];
      for (int k = 0; k < 2; ++k)
        for (int a = 0; a < 3; ++a) end[k][a] = positions_[4 * std::size_t{v[k]} + a];
      const double reach = common + 2.0 * dt * std::max(speed_[v[0]], speed_[v[1]]) + moved;
      const math::Vec3 ab = math::sub(end[1], end[0]);
      const double length2 = math::dot(ab, ab);
      if (!(length2 > 0.0)) continue;
      const collision::CapsuleContact hit = collision::capsule_against(*shape.shape, shape.position, shape.rotation,
                                                                      end[0], end[1], 0.0);
      if (-hit.depth > reach) continue;
      const double along = math::dot(math::sub(hit.point, end[0]), ab) / length2;
      if (along < 1e-6 || along > 1.0 - 1e-6) continue;  // an end: the vertex's own contact
      Contact c;
      c.kind = Contact::Kind::shape_face;
      c.v = {v[0], v[0], v[1], v[1]};
      c.w = {0.0f, float(1.0 - along), 0.0f, float(along)};
      c.normal = {float(hit.normal[0]), float(hit.normal[1]), float(hit.normal[2])};
      c.distance = float(-hit.depth);
      // The shape's surface under the segment's deepest point.
      plane(c, hit.normal, math::add(hit.point, math::mul(hit.normal, hit.depth)));
      c.shape = which;
      all_.push_back(c);
    }
  }
}

Status MeshCollision::before_frame(Device& device, const XpbdBuffers& scene_buffers,
                                   std::span<const PosedShape> colliders, std::span<const PosedShape> tool_starts,
                                   std::span<const PosedShape> tool_ends, bool& grew) {
  grew = false;
  read_back_bytes_ = 0;
  const std::size_t particles = movable_.size();
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
  speed_.assign(particles, 0.0f);
  float fastest = 0.0f;
  for (std::uint32_t p : collidable_) {
    const float* v = &velocities_[std::size_t{p} * 4];
    speed_[p] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!std::isfinite(speed_[p]))
      return Error(ErrorCode::bad_parameter, "mesh collision: particle " + std::to_string(p) +
                                                 " (device order) has a non-finite velocity");
    fastest = std::max(fastest, speed_[p]);
  }
  const double dt = time_step_;
  const double common = desc_.thickness + desc_.margin + 0.5 * gravity_ * dt * dt;
  margin_ = desc_.margin + 0.5 * gravity_ * dt * dt + 4.0 * dt * fastest;
  const auto reach = static_cast<float>(desc_.thickness + margin_);
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
  const auto sweep = [&](std::span<const std::uint32_t> corners, int arity, std::span<const float> velocities,
                         const double mean[3], std::vector<collision::Aabb>& boxes) {
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
  };
  // Each body's mean surface velocity (over its primitives' corners).
  mean_velocity_.assign(3 * std::size_t{body_count_}, 0.0);
  {
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
  const auto across_air = [&](const Contact& c) {
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
  };
  if (desc_.self_collision && solid_bodies_ > 0) {
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
  const collision::ContactFilter wanted = [&](const Contact& c) {
    if (suture_exempt(exempt_, c.v)) return false;  // a thread where it runs through a puncture
    if (!collision::facing(c, positions_) || !across_air(c)) return false;
    const bool vertex_triangle = c.kind == Contact::Kind::vertex_triangle;
    const float coefficient[4] = {c.w[0], vertex_triangle ? -c.w[1] : c.w[1], -c.w[2], -c.w[3]};
    double rel[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 4; ++k)
      for (int a = 0; a < 3; ++a) rel[a] += double(coefficient[k]) * velocities_[std::size_t{c.v[k]} * 4 + a];
    const double closing = 2.0 * dt * std::sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]);
    return double(c.distance) < common + closing;
  };
  const auto keep = [&] { all_.insert(all_.end(), found_.begin(), found_.end()); };

  // Boxes swollen by fast motion can pair most of two surfaces, and every
  // pair may make up to 15 contacts: past kMaxPairs the frame stops with an
  // error that says why, rather than exhausting memory.
  const auto check_pairs = [&]() -> Status {
    if (pairs_.size() <= kMaxPairs) return {};
    return Error(ErrorCode::capacity_exceeded,
                 "mesh collision: " + std::to_string(pairs_.size()) + " candidate pairs (at most " +
                     std::to_string(kMaxPairs) + ") within the frame's reach of " + std::to_string(1e3 * reach) +
                     " mm: the fastest collidable particle moves " + std::to_string(fastest) +
                     " m/s; smaller time steps or slower bodies keep the reach short");
  };
  all_.clear();
  const auto half = static_cast<float>(0.5 * common);
  // The primitives' boxes, swept, and each body's trees refitted to them:
  // tree with the velocities themselves (only when there is another body
  // to pair with), self_tree in the body's own frame of motion
  // (self-collision only). A self tree's boxes are computed in its leaf
  // order from its vertices gathered there (leaf_vertices.h: the liver's
  // surface in bench_broad_phase, boxes + refit 1.9 -> 1.5 ms and the
  // cones 2.6 -> 1.7, min of 8); the same floats as in the primitives'
  // order, so the same boxes and the same tree.
  const bool cross = body_count_ > 1;
  const double still[3] = {0.0, 0.0, 0.0};
  // Gathers each body's vertices for its self tree (built before this frame).
  const auto gather_body = [&](BodyTree& body, std::span<const std::uint32_t> indices, int arity) -> Status {
    if (Status s = body.leaf.index(body.self_tree,
                                   indices.subspan(std::size_t{body.first} * arity, std::size_t{body.count} * arity),
                                   arity);
        !s)
      return s;
    return body.leaf.gather(positions_);
  };
  const auto gather = [&](std::span<const std::uint32_t> indices, int arity, std::vector<BodyTree>& trees) -> Status {
    if (!desc_.self_collision) return {};
    for (BodyTree& body : trees)
      if (!body.self_tree.empty())
        if (Status s = gather_body(body, indices, arity); !s) return s;
    return {};
  };
  const auto fit = [&](std::span<const std::uint32_t> indices, int arity, std::span<const std::uint32_t> body_of,
                       std::vector<BodyTree>& trees) -> Status {
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
  };
  // Trees that refitting degraded are rebuilt after it (Bvh::update's rule).
  const auto rebuild = [&](std::vector<BodyTree>& trees) {
    for (BodyTree& body : trees) {
      if (desc_.self_collision && body.self_tree.degradation() > kMaxDegradation) body.self_tree.rebuild();
      if (cross && body.tree.degradation() > kMaxDegradation) body.tree.rebuild();
    }
  };
  if (!triangles_.empty()) {
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
    tbb::parallel_invoke([&] { fitted = fit(triangles_, 3, triangle_body_, triangle_trees_); },
                         [&] {
                           if (!cull) return;
                           for (std::size_t b = 0; b < triangle_trees_.size(); ++b)
                             if (shape[b] != 0) cones_of(triangle_trees_[b]);
                         });
    if (!fitted) return fitted;
    rebuild(triangle_trees_);
    if (cull)
      for (std::size_t b = 0; b < triangle_trees_.size(); ++b)
        if (triangle_trees_[b].self_tree.build_id() != shape[b]) {
          // A new shape: the vertices gathered anew in its leaf order.
          if (Status s = gather_body(triangle_trees_[b], triangles_, 3); !s) return s;
          cones_of(triangle_trees_[b]);
        }
    candidate_pairs<3>(triangle_trees_, triangles_, triangle_trees_, pairs_);
    if (Status s = check_pairs(); !s) return s;
    if (Status s = collision::triangle_contacts(positions_, triangles_, ownership_, pairs_, reach, found_, wanted);
        !s)
      return s;
    keep();
  }
  if (!segments_.empty()) {
    if (Status s = gather(segments_, 2, segment_trees_); !s) return s;
    if (Status s = fit(segments_, 2, segment_body_, segment_trees_); !s) return s;
    rebuild(segment_trees_);
    candidate_pairs<2>(segment_trees_, segments_, segment_trees_, pairs_);
    if (Status s = check_pairs(); !s) return s;
    if (Status s = collision::segment_contacts(positions_, segments_, pairs_, reach, found_, wanted); !s)
      return s;
    keep();
    if (!triangles_.empty()) {
      candidate_pairs<2>(segment_trees_, segments_, triangle_trees_, pairs_);
      if (Status s = check_pairs(); !s) return s;
      if (Status s = collision::segment_triangle_contacts(positions_, segments_, triangles_, pairs_, reach, found_,
                                                              wanted);
          !s)
        return s;
      keep();
    }
  }

  prune();
  shape_faces(colliders, {}, common);
  if (desc_.tool_faces) shape_faces(tool_starts, tool_ends, common);

  // Coefficients c_k (mesh_contact_params.h); contacts of immovable
  // particles only are dropped (nothing to solve).
  std::vector<std::uint32_t>& vertices = contact_particles_;
  vertices.clear();
  kept_.clear();
  for (std::size_t k = 0; k < all_.size(); ++k) {
    const Contact& c = all_[k];
    bool moves = false;
    for (std::uint32_t v : c.v) moves |= movable_[v] != 0;
    if (!moves) continue;
    kept_.push_back(static_cast<std::uint32_t>(k));
    vertices.insert(vertices.end(), c.v.begin(), c.v.end());
  }
  const auto count = static_cast<std::uint32_t>(kept_.size());
  contact_count_ = count;
  MeshContactBuffers& b = buffers_;
  appended_.clear();
  appended_slots_.clear();
  appended_colors_ = 0;
  // The last frame's continuous contacts outgrew the room kept for them.
  if (want_colors_) reserve_colors_ = std::min<std::uint32_t>(32, 2 * reserve_colors_);
  if (want_slots_) reserve_slots_ *= 2;
  want_colors_ = want_slots_ = false;
  if (count + reserve_slots_ > b.capacity) {
    b.capacity = std::max(count + reserve_slots_, 2 * b.capacity);
    for (BufferHandle h : {b.particles, b.coefficients, b.normals, b.lambda, b.lambda_sum})
      if (Status s = device.resize_buffer(h, std::size_t{b.capacity} * 16); !s) return s;
    if (Status s = device.resize_buffer(b.motion, std::size_t{b.capacity} * 4); !s) return s;
    if (b.jacobi) {
      if (Status s = device.resize_buffer(b.delta, std::size_t{b.capacity} * 64); !s) return s;
      if (Status s = device.resize_buffer(b.slots, std::size_t{b.capacity} * 16); !s) return s;
    }
    grew = true;
  }

  // Where each contact goes: colour-sorted (colour k's contacts at
  // [first_k, first_k + size_k)), or in order for the Jacobi schedule.
  std::vector<std::uint32_t> slot_of(count);
  if (b.jacobi) {
    color_count_ = 0;
    for (std::uint32_t k = 0; k < count; ++k) slot_of[k] = k;
    table_.assign(std::size_t{2} * b.colors, 0);
    table_[0] = count;
  } else {
    const Coloring coloring = color_constraints(vertices, 4, movable_);
    const std::uint32_t colors = coloring.color_count();
    color_count_ = colors;
    if (colors + reserve_colors_ > b.colors) {
      b.colors = std::max(colors + reserve_colors_, 2 * b.colors);
      if (Status s = device.resize_buffer(b.table, std::size_t{2} * b.colors * 4); !s) return s;
      grew = true;
    }
    table_.assign(std::size_t{2} * b.colors, 0);
    for (std::uint32_t k = 0; k < colors; ++k) table_[k] = coloring.color_sizes[k];
    for (std::uint32_t k = 1; k < colors; ++k) table_[b.colors + k] = table_[b.colors + k - 1] + table_[k - 1];
    std::vector<std::uint32_t> next(table_.begin() + b.colors, table_.begin() + b.colors + colors);
    for (std::uint32_t k = 0; k < count; ++k) slot_of[k] = next[coloring.color_of[k]]++;
  }
  upload_particles_.resize(std::size_t{count} * 4);
  upload_coefficients_.resize(std::size_t{count} * 4);
  upload_normals_.resize(std::size_t{count} * 4);
  upload_motion_.assign(count, 0.0f);
  tool_slots_.clear();
  for (std::uint32_t k = 0; k < count; ++k) {
    const Contact& c = all_[kept_[k]];
    const std::size_t at = std::size_t{slot_of[k]} * 4;
    if (c.shape != Contact::kNoShape) tool_slots_.push_back({slot_of[k], c.shape});
    float coefficient[4];
    coefficients_of(c, coefficient);
    for (int j = 0; j < 4; ++j) {
      upload_particles_[at + j] = c.v[j];
      upload_coefficients_[at + j] = coefficient[j];
    }
    upload_normals_[at] = c.normal[0];
    upload_normals_[at + 1] = c.normal[1];
    upload_normals_[at + 2] = c.normal[2];
    upload_normals_[at + 3] = c.offset;
    upload_motion_[slot_of[k]] = c.motion;
  }
  if (b.jacobi) {
    // Per touched (movable) particle, its correction slots 4 i + k in
    // increasing order: a counting sort by particle, so the gather sums
    // them in a fixed order.
    upload_offsets_.assign(particles + 1, 0);
    // A shape contact's repeated particle (a slot with c = 0 followed by
    // the same particle) has no correction of its own: not counted in its
    // particle's mean.
    const auto counted = [&](std::size_t s) {
      const bool repeat = s % 4 != 3 && upload_coefficients_[s] == 0.0f && upload_particles_[s] == upload_particles_[s + 1];
      return movable_[upload_particles_[s]] && !repeat;
    };
    for (std::size_t s = 0; s < upload_particles_.size(); ++s)
      if (counted(s)) ++upload_offsets_[upload_particles_[s] + 1];
    upload_touched_.clear();
    for (std::size_t p = 0; p < particles; ++p) {
      if (upload_offsets_[p + 1] > 0) upload_touched_.push_back(static_cast<std::uint32_t>(p));
      upload_offsets_[p + 1] += upload_offsets_[p];
    }
    upload_slots_.resize(upload_offsets_[particles]);
    std::vector<std::uint32_t> next(upload_offsets_.begin(), upload_offsets_.end() - 1);
    for (std::size_t s = 0; s < upload_particles_.size(); ++s)
      if (counted(s)) upload_slots_[next[upload_particles_[s]]++] = static_cast<std::uint32_t>(s);
    // Offsets of the touched particles only (the gather's CSR rows).
    compact_offsets_.clear();
    for (std::uint32_t p : upload_touched_) compact_offsets_.push_back(upload_offsets_[p]);
    compact_offsets_.push_back(upload_offsets_[particles]);
    table_[1] = static_cast<std::uint32_t>(upload_touched_.size());
    if (!upload_touched_.empty()) {
      if (Status s = device.write_buffer(b.touched, 0, upload_touched_.data(), upload_touched_.size() * 4); !s)
        return s;
      if (Status s = device.write_buffer(b.offsets, 0, compact_offsets_.data(), compact_offsets_.size() * 4); !s)
        return s;
      if (Status s = device.write_buffer(b.slots, 0, upload_slots_.data(), upload_slots_.size() * 4); !s) return s;
    }
  }
  if (Status s = device.write_buffer(b.table, 0, table_.data(), table_.size() * 4); !s) return s;
  if (count > 0) {
    const std::size_t bytes = std::size_t{count} * 16;
    if (Status s = device.write_buffer(b.particles, 0, upload_particles_.data(), bytes); !s) return s;
    if (Status s = device.write_buffer(b.coefficients, 0, upload_coefficients_.data(), bytes); !s) return s;
    if (Status s = device.write_buffer(b.normals, 0, upload_normals_.data(), bytes); !s) return s;
    if (Status s = device.write_buffer(b.motion, 0, upload_motion_.data(), bytes / 4); !s) return s;
  }
  return {};
}

}  // namespace sinew

namespace sinew {

Result<std::uint32_t> MeshCollision::append_contacts(Device& device, std::span<const collision::Contact> contacts) {
  MeshContactBuffers& b = buffers_;
  if (b.jacobi) return 0u;  // scene_checks: continuous needs the coloured schedule
  const std::uint32_t colors = std::min<std::uint32_t>(32, b.colors - color_count_);
  // Greedy colours, the frame's earlier additions first (they get the
  // colours they had): the first colour whose contacts share no movable
  // particle with this one. New contacts without a colour or a slot left
  // are not added.
  std::vector<collision::Contact> all = appended_;
  color_mask_.resize(movable_.size(), 0);
  std::vector<std::uint32_t> color_of, sizes(colors, 0);
  const auto place = [&](const collision::Contact& c) {
    std::uint32_t used = 0;
    for (std::uint32_t p : c.v)
      if (movable_[p]) used |= color_mask_[p];
    std::uint32_t k = 0;
    while (k < colors && (used >> k & 1u)) ++k;
    if (k == colors) return false;
    color_of.push_back(k);
    ++sizes[k];
    for (std::uint32_t p : c.v)
      if (movable_[p]) color_mask_[p] |= 1u << k;
    return true;
  };
  for (const collision::Contact& c : appended_)
    if (!place(c)) return Error(ErrorCode::internal, "internal: a continuous contact lost its colour");
  std::uint32_t added = 0;
  for (const collision::Contact& c : contacts) {
    if (contact_count_ + all.size() >= b.capacity) {
      want_slots_ = true;
      break;
    }
    if (!place(c)) {
      want_colors_ = true;
      continue;
    }
    all.push_back(c);
    ++added;
  }
  for (const collision::Contact& c : all)
    for (std::uint32_t p : c.v) color_mask_[p] = 0;
  if (added == 0) return 0u;
  const auto n = static_cast<std::uint32_t>(all.size());
  std::uint32_t used_colors = 0;
  for (std::uint32_t k = 0; k < colors; ++k)
    if (sizes[k] > 0) used_colors = k + 1;
  // The layout: colour color_count_ + k at [first_k, first_k + sizes[k]) after the frame's contacts.
  std::vector<std::uint32_t> next(colors, contact_count_);
  for (std::uint32_t k = 1; k < colors; ++k) next[k] = next[k - 1] + sizes[k - 1];
  for (std::uint32_t k = 0; k < std::max(used_colors, appended_colors_); ++k) {
    table_[color_count_ + k] = k < colors ? sizes[k] : 0;
    table_[b.colors + color_count_ + k] = next[k];
  }
  std::vector<std::uint32_t> slot_of(n);
  for (std::uint32_t i = 0; i < n; ++i) slot_of[i] = next[color_of[i]]++;

  // The earlier additions' multipliers move with them, this substep's
  // (lambda) and the earlier substeps' sum (lambda_sum, the tool's
  // reaction: add_tool_reactions); the new ones start at 0.
  std::vector<float> lambda(std::size_t{n} * 4, 0.0f), lambda_sum(std::size_t{n} * 4, 0.0f);
  if (!appended_.empty()) {
    std::vector<float> old(appended_.size() * 4);
    for (const auto& [buffer, moved] : {std::pair{b.lambda, &lambda}, std::pair{b.lambda_sum, &lambda_sum}}) {
      if (Status s = device.read_buffer(buffer, std::size_t{contact_count_} * 16, old.data(), old.size() * 4); !s)
        return s.error();
      read_back_bytes_ += old.size() * 4;
      for (std::size_t i = 0; i < appended_.size(); ++i)
        std::copy_n(&old[std::size_t{appended_slots_[i] - contact_count_} * 4], 4,
                    &(*moved)[std::size_t{slot_of[i] - contact_count_} * 4]);
    }
  }
  const std::size_t end = std::size_t{contact_count_ + n} * 4;
  upload_particles_.resize(end);
  upload_coefficients_.resize(end);
  upload_normals_.resize(end);
  upload_motion_.resize(contact_count_ + n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const collision::Contact& c = all[i];
    const std::size_t at = std::size_t{slot_of[i]} * 4;
    float coefficient[4];
    coefficients_of(c, coefficient);
    for (int j = 0; j < 4; ++j) {
      upload_particles_[at + j] = c.v[j];
      upload_coefficients_[at + j] = coefficient[j];
    }
    for (int a = 0; a < 3; ++a) upload_normals_[at + a] = c.normal[a];
    upload_normals_[at + 3] = c.offset;
    upload_motion_[slot_of[i]] = c.motion;
  }
  // Contacts with a tool: their reaction goes to it (add_tool_reactions).
  std::erase_if(tool_slots_, [&](const auto& slot) { return slot.first >= contact_count_; });
  for (std::uint32_t i = 0; i < n; ++i)
    if (all[i].shape != collision::Contact::kNoShape) tool_slots_.push_back({slot_of[i], all[i].shape});
  const std::size_t first = std::size_t{contact_count_} * 4, bytes = std::size_t{n} * 16;
  if (Status s = device.write_buffer(b.particles, first * 4, &upload_particles_[first], bytes); !s) return s.error();
  if (Status s = device.write_buffer(b.coefficients, first * 4, &upload_coefficients_[first], bytes); !s)
    return s.error();
  if (Status s = device.write_buffer(b.normals, first * 4, &upload_normals_[first], bytes); !s) return s.error();
  if (Status s = device.write_buffer(b.motion, std::size_t{contact_count_} * 4, &upload_motion_[contact_count_], bytes / 4);
      !s)
    return s.error();
  if (Status s = device.write_buffer(b.lambda, first * 4, lambda.data(), bytes); !s) return s.error();
  if (Status s = device.write_buffer(b.lambda_sum, first * 4, lambda_sum.data(), bytes); !s) return s.error();
  if (Status s = device.write_buffer(b.table, 0, table_.data(), table_.size() * 4); !s) return s.error();
  appended_ = std::move(all);
  appended_slots_ = std::move(slot_of);
  appended_colors_ = std::max(appended_colors_, used_colors);
  return added;
}

}  // namespace sinew

namespace sinew {

Status MeshCollision::update_topology(Device& device, const SceneDesc& scene,
                                      std::span<const std::vector<std::uint8_t>* const> tet_alive, bool& changed) {
  changed = false;
  const auto tri_bodies = static_cast<std::uint32_t>(scene.tri_bodies.size());
  if (tet_faces_.size() != solid_bodies_ || tri_first_.size() != tri_bodies ||
      line_first_.size() != scene.line_bodies.size())
    return Error(ErrorCode::bad_parameter,
                 "mesh collision: update_topology needs a MeshCollision made with SceneDesc::topology_changes, "
                 "for a scene of as many bodies");
  if (tet_alive.size() != solid_bodies_)
    return Error(ErrorCode::bad_parameter, "mesh collision: update_topology takes one alive mask per tet body (" +
                                               std::to_string(solid_bodies_) + ", got " +
                                               std::to_string(tet_alive.size()) + ")");
  // Per tet body: the tets that died since the last call, ascending. The
  // masks are compared 8 bytes at a time (a cut changes a few dozen of
  // 50,000: the byte loop took 0.05 ms a pass).
  std::vector<std::vector<std::uint32_t>> died(solid_bodies_);
  for (std::uint32_t b = 0; b < solid_bodies_; ++b) {
    const TetFaces& f = tet_faces_[b];
    if (tet_alive[b] == nullptr || tet_alive[b]->size() != f.tets.size())
      return Error(ErrorCode::bad_parameter, "mesh collision: tet body " + std::to_string(b) + "'s alive mask has " +
                                                 std::to_string(tet_alive[b] ? tet_alive[b]->size() : 0) +
                                                 " entries for " + std::to_string(f.tets.size()) + " tets");
    const std::uint8_t* now = tet_alive[b]->data();
    const std::uint8_t* was = f.alive.data();
    const std::size_t n = f.tets.size();
    for (std::size_t t0 = 0; t0 < n; t0 += 8) {
      if (t0 + 8 <= n) {
        std::uint64_t x = 0, y = 0;
        std::memcpy(&x, now + t0, 8);
        std::memcpy(&y, was + t0, 8);
        if (x == y) continue;
      }
      for (std::size_t t = t0; t < std::min(n, t0 + 8); ++t) {
        if (now[t] && !was[t])
          return Error(ErrorCode::bad_parameter, "mesh collision: tet " + std::to_string(t) + " of body " +
                                                     std::to_string(b) + " is alive again");
        if (was[t] && !now[t]) died[b].push_back(static_cast<std::uint32_t>(t));
      }
    }
  }
  const auto old_triangles = body_ranges(triangle_body_, body_count_);
  const auto old_segments = body_ranges(segment_body_, body_count_);
  // Per triangle body that changed: old local index -> new (remap) and the
  // new triangles (added, new local indices); its new triangles.
  std::vector<std::uint8_t> body_changed(body_count_, 0);
  std::vector<std::vector<std::uint32_t>> remap(solid_bodies_ + tri_bodies), added(solid_bodies_ + tri_bodies);
  std::vector<std::vector<std::uint32_t>> replaced(body_count_);
  // Tet bodies: each face of a tet that died since the last call, and the
  // faces in its ring, is on the boundary when its tet lives and it is the
  // only live face of its ring (extract_boundary_surface's rule).
  for (std::uint32_t b = 0; b < solid_bodies_; ++b) {
    TetFaces& f = tet_faces_[b];
    std::vector<std::uint32_t> touched;
    for (std::uint32_t t : died[b]) {
      f.alive[t] = 0;
      for (std::uint32_t k = 0; k < 4; ++k) touched.push_back(4 * t + k);
    }
    if (touched.empty()) continue;
    std::vector<std::uint32_t> joined;
    for (std::uint32_t s : touched) {
      std::uint32_t live = 0;
      for (std::uint32_t u = s;;) {
        live += f.alive[u / 4];
        if ((u = f.twin[u]) == s) break;
      }
      for (std::uint32_t u = s;;) {
        const std::uint8_t boundary = f.alive[u / 4] && live == 1;
        if (boundary != f.on_boundary[u]) {
          f.on_boundary[u] = boundary;
          if (boundary) joined.push_back(u);
        }
        if ((u = f.twin[u]) == s) break;
      }
    }
    std::sort(joined.begin(), joined.end());
    // The new boundary: the old one's faces still on it, merged with those that joined.
    // Its triangles: a kept face's copied from the old ones (triangles_
    // holds boundary_triangles of the old boundary), a joined face's made.
    std::vector<std::uint32_t> boundary;
    boundary.reserve(f.boundary.size() + joined.size());
    remap[b].assign(f.boundary.size(), UINT32_MAX);
    std::vector<std::uint32_t>& out = replaced[b];
    out.reserve(3 * (f.boundary.size() + joined.size()));
    const std::uint32_t* old = triangles_.data() + 3 * std::size_t{old_triangles[b].first};
    const auto join = [&](std::uint32_t s) {
      added[b].push_back(static_cast<std::uint32_t>(boundary.size()));
      boundary.push_back(s);
      const auto& tet = f.tets[s / 4];
      for (int k : kOutwardFaces[s % 4]) out.push_back(device_of_[f.first_particle + tet[std::size_t(k)]]);
    };
    std::size_t j = 0;
    for (std::size_t i = 0; i < f.boundary.size(); ++i) {
      for (; j < joined.size() && joined[j] < f.boundary[i]; ++j) join(joined[j]);
      if (!f.on_boundary[f.boundary[i]]) continue;
      remap[b][i] = static_cast<std::uint32_t>(boundary.size());
      boundary.push_back(f.boundary[i]);
      out.insert(out.end(), old + 3 * i, old + 3 * i + 3);
    }
    for (; j < joined.size(); ++j) join(joined[j]);
    f.boundary = std::move(boundary);
    body_changed[b] = 1;
  }
  // Tri bodies: replaced whole when their triangles differ. The carried
  // pairs follow the old triangles that are still there in order (a removal
  // keeps the rest in order); otherwise every triangle counts as new.
  for (std::uint32_t k = 0; k < tri_bodies; ++k) {
    const std::uint32_t b = solid_bodies_ + k;
    std::vector<std::uint32_t>& mine = replaced[b];
    for (const auto& t : scene.tri_bodies[k].mesh.triangles)
      for (std::uint32_t v : t) mine.push_back(device_of_[tri_first_[k] + v]);
    const auto [first, count] = old_triangles[b];
    const auto old = std::span<const std::uint32_t>(triangles_).subspan(3 * std::size_t{first}, 3 * std::size_t{count});
    if (std::equal(old.begin(), old.end(), mine.begin(), mine.end())) {
      mine.clear();
      continue;
    }
    body_changed[b] = 1;
    const std::size_t n = mine.size() / 3;
    remap[b].assign(count, UINT32_MAX);
    std::size_t j = 0;
    for (std::size_t i = 0; i < count && j < n; ++i)
      if (std::equal(&old[3 * i], &old[3 * i] + 3, &mine[3 * j])) remap[b][i] = static_cast<std::uint32_t>(j++);
    if (j < n) remap[b].assign(count, UINT32_MAX);  // not a removal: nothing carried
    std::vector<std::uint8_t> kept(n, 0);
    for (std::uint32_t r : remap[b])
      if (r != UINT32_MAX) kept[r] = 1;
    for (std::uint32_t t = 0; t < n; ++t)
      if (!kept[t]) added[b].push_back(t);
  }
  // Line bodies: replaced whole when their segments differ.
  for (std::uint32_t k = 0; k < scene.line_bodies.size(); ++k) {
    const std::uint32_t b = solid_bodies_ + tri_bodies + k;
    std::vector<std::uint32_t>& mine = replaced[b];
    for (const auto& s : scene.line_bodies[k].segments)
      for (std::uint32_t v : s) mine.push_back(device_of_[line_first_[k] + v]);
    const auto [first, count] = old_segments[b];
    const auto old = std::span<const std::uint32_t>(segments_).subspan(2 * std::size_t{first}, 2 * std::size_t{count});
    if (std::equal(old.begin(), old.end(), mine.begin(), mine.end())) mine.clear();
    else body_changed[b] = 1;
  }
  if (std::find(body_changed.begin(), body_changed.end(), 1) == body_changed.end()) return {};
  changed = true;

  // The primitives in create()'s order: unchanged bodies copied, changed ones replaced.
  const auto assemble = [&](const std::vector<std::uint32_t>& indices, const std::vector<std::pair<std::uint32_t, std::uint32_t>>& ranges,
                            std::size_t arity, std::uint32_t from, std::uint32_t to, std::vector<std::uint32_t>& out,
                            std::vector<std::uint32_t>& body_of) {
    out.clear();
    body_of.clear();
    for (std::uint32_t b = from; b < to; ++b) {
      if (body_changed[b]) {
        out.insert(out.end(), replaced[b].begin(), replaced[b].end());
      } else {
        const auto [first, count] = ranges[b];
        out.insert(out.end(), indices.begin() + arity * first, indices.begin() + arity * (first + count));
      }
      body_of.resize(out.size() / arity, b);
    }
  };
  std::vector<std::uint32_t> triangles, triangle_body, segments, segment_body;
  assemble(triangles_, old_triangles, 3, 0, solid_bodies_ + tri_bodies, triangles, triangle_body);
  assemble(segments_, old_segments, 2, solid_bodies_ + tri_bodies, body_count_, segments, segment_body);
  triangles_.swap(triangles);
  triangle_body_.swap(triangle_body);
  segments_.swap(segments);
  segment_body_.swap(segment_body);

  // The trees: an unchanged body keeps its own (local indices), a changed
  // one starts empty and is built in the next before_frame, as after create().
  const auto retree = [&](const std::vector<std::uint32_t>& body_of, std::vector<BodyTree>& trees,
                          bool triangles_of) -> Status {
    std::vector<BodyTree> old(body_count_);
    for (BodyTree& t : trees) {
      const std::uint32_t b = triangles_of ? triangle_body[t.first] : segment_body[t.first];  // the old body_of
      old[b] = std::move(t);
    }
    trees.clear();
    const auto ranges = body_ranges(body_of, body_count_);
    for (std::uint32_t b = 0; b < body_count_; ++b) {
      const auto [first, count] = ranges[b];
      if (count == 0) continue;
      if (!body_changed[b]) {
        trees.push_back(std::move(old[b]));
      } else {
        trees.emplace_back();
        if (triangles_of && desc_.self_collision) {
          trees.back().first = first;
          trees.back().count = count;
          if (Status s = update_rest_close(b, trees.back(), old[b].rest_close, remap[b], added[b]); !s) return s;
        }
      }
      trees.back().first = first;
      trees.back().count = count;
    }
    return {};
  };
  if (Status s = retree(triangle_body_, triangle_trees_, true); !s) return s;
  if (Status s = retree(segment_body_, segment_trees_, false); !s) return s;

  // The ownership (triangle_ownership of triangles_, 0.3 ms on the block's
  // 5,000 triangles) carried over from the old one: bodies share no
  // particle, so an unchanged body's owners are its own triangles, shifted
  // with it. In a changed body, a kept triangle's vertex that no removed or
  // added triangle has is on the same triangles as before, renumbered in
  // the same order (remap keeps it), so its owner is the old owner
  // renumbered; likewise an edge with such an end. Only the features around
  // the changed triangles are looked up, among the new triangles around
  // their lower vertex, ascending, as triangle_ownership does.
  {
    const auto new_triangles = body_ranges(triangle_body_, body_count_);
    std::vector<std::array<std::uint32_t, 6>>& owner = owner_scratch_;  // every row written below
    owner.resize(triangle_body_.size());
    std::vector<std::uint8_t>& dirty = dirty_;  // all 0 between calls
    dirty.resize(movable_.size(), 0);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> around;  // (dirty particle, new local triangle)
    std::vector<std::uint32_t> old_of;
    for (std::uint32_t b = 0; b < solid_bodies_ + tri_bodies; ++b) {
      const auto [nf, nc] = new_triangles[b];
      const auto [of, oc] = old_triangles[b];
      if (!body_changed[b]) {
        for (std::uint32_t t = 0; t < nc; ++t)
          for (int k = 0; k < 6; ++k) owner[std::size_t{nf} + t][k] = ownership_.owner[std::size_t{of} + t][k] - of + nf;
        continue;
      }
      const std::uint32_t* nt = triangles_.data() + 3 * std::size_t{nf};
      const std::uint32_t* ot = triangles.data() + 3 * std::size_t{of};  // the old triangles_ (swapped)
      const std::vector<std::uint32_t>& map = remap[b];
      old_of.assign(nc, UINT32_MAX);
      for (std::uint32_t i = 0; i < oc; ++i) {
        if (i < map.size() && map[i] != UINT32_MAX) old_of[map[i]] = i;
        else
          for (int c = 0; c < 3; ++c) dirty[ot[3 * std::size_t{i} + c]] = 1;
      }
      for (std::uint32_t t : added[b])
        for (int c = 0; c < 3; ++c) dirty[nt[3 * std::size_t{t} + c]] = 1;
      around.clear();
      for (std::uint32_t t = 0; t < nc; ++t)
        for (int c = 0; c < 3; ++c)
          if (dirty[nt[3 * std::size_t{t} + c]]) around.push_back({nt[3 * std::size_t{t} + c], t});
      std::stable_sort(around.begin(), around.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
      const auto first_around = [&](std::uint32_t v) {
        return std::lower_bound(around.begin(), around.end(), v, [](const auto& x, std::uint32_t w) { return x.first < w; });
      };
      const auto has_edge = [&](std::uint32_t u, std::uint32_t lo, std::uint32_t hi) {
        const std::uint32_t* x = nt + 3 * std::size_t{u};
        for (int e = 0; e < 3; ++e)
          if (std::min(x[e], x[(e + 1) % 3]) == lo && std::max(x[e], x[(e + 1) % 3]) == hi) return true;
        return false;
      };
      for (std::uint32_t t = 0; t < nc; ++t) {
        const std::uint32_t i = old_of[t];
        auto& row = owner[std::size_t{nf} + t];
        for (int c = 0; c < 3; ++c) {
          const std::uint32_t v = nt[3 * std::size_t{t} + c], w = nt[3 * std::size_t{t} + (c + 1) % 3];
          if (i != UINT32_MAX && !dirty[v]) row[c] = map[ownership_.owner[std::size_t{of} + i][c] - of] + nf;
          else row[c] = first_around(v)->second + nf;
          if (i != UINT32_MAX && (!dirty[v] || !dirty[w])) {
            row[3 + c] = map[ownership_.owner[std::size_t{of} + i][3 + c] - of] + nf;
          } else {
            const std::uint32_t lo = std::min(v, w), hi = std::max(v, w);
            auto k = first_around(lo);
            while (!has_edge(k->second, lo, hi)) ++k;  // ends at t itself at the latest
            row[3 + c] = k->second + nf;
          }
        }
      }
      for (std::uint32_t i = 0; i < oc; ++i)
        if (!(i < map.size() && map[i] != UINT32_MAX))
          for (int c = 0; c < 3; ++c) dirty[ot[3 * std::size_t{i} + c]] = 0;
      for (std::uint32_t t : added[b])
        for (int c = 0; c < 3; ++c) dirty[nt[3 * std::size_t{t} + c]] = 0;
    }
    ownership_.owner.swap(owner);  // the old rows: the next call's scratch
  }
  index_primitives(false);

  // Room for the new surface's particles: the Jacobi schedule's lists of
  // touched particles hold up to every collidable one.
  MeshContactBuffers& buffers = buffers_;
  if (buffers.jacobi && collidable_.size() > buffers.touched_capacity) {
    buffers.touched_capacity = static_cast<std::uint32_t>(collidable_.size());
    if (Status s = device.resize_buffer(buffers.touched, std::size_t{buffers.touched_capacity} * 4); !s) return s;
    if (Status s = device.resize_buffer(buffers.offsets, std::size_t{buffers.touched_capacity + 1} * 4); !s) return s;
  }
  if (desc_.continuous)
    reserve_slots_ = std::max(reserve_slots_, static_cast<std::uint32_t>(segments_.size()));
  return {};
}

namespace {

// Every primitive of `tree` whose box overlaps `box`. [out] out, appended.
void tree_query(const collision::Bvh& tree, const collision::Aabb& box, std::vector<std::uint32_t>& out) {
  if (tree.empty()) return;
  const auto& nodes = tree.nodes();
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const collision::Bvh::Node& node = nodes[stack[--top]];
    if (!collision::overlap(node.box, box)) continue;
    if (node.count > 0) {
      for (std::uint32_t s = node.first; s < node.first + node.count; ++s)
        if (collision::overlap(tree.leaf_boxes()[s], box)) out.push_back(tree.order()[s]);
    } else {
      stack[top++] = node.left;
      stack[top++] = node.left + 1;
    }
  }
}

}  // namespace

// A tri body's added triangles are tested against all its triangles up to
// this many box tests; past it, its pairs are all found afresh.
constexpr std::size_t kMaxRestTests = std::size_t{1} << 20;

// The carried pairs, then the added triangles' own: each added triangle's
// rest box (grown by half the thickness, as rest_close_pairs grows them)
// against the body's tets' rest boxes (a tet body: its faces on the
// boundary now are the candidates) or the body's triangles' (a tri body),
// kept when the triangles share no vertex and are closer than the
// thickness (rest_close_pairs' test, in the same argument order).
Status MeshCollision::update_rest_close(std::uint32_t body, BodyTree& tree, const collision::PairSet& old,
                                       std::span<const std::uint32_t> remap, std::span<const std::uint32_t> added) {
  std::vector<collision::Pair> pairs;
  for (const auto& [i, j] : old.pairs())
    if (i < remap.size() && j < remap.size() && remap[i] != UINT32_MAX && remap[j] != UINT32_MAX)
      pairs.push_back({remap[i], remap[j]});
  const auto mine = std::span<const std::uint32_t>(triangles_).subspan(std::size_t{tree.first} * 3,
                                                                       std::size_t{tree.count} * 3);
  const auto thickness = static_cast<float>(desc_.thickness);
  if (!added.empty()) {
    std::vector<std::uint32_t> corners;
    corners.reserve(3 * added.size());
    for (std::uint32_t t : added) corners.insert(corners.end(), &mine[3 * std::size_t{t}], &mine[3 * std::size_t{t}] + 3);
    std::vector<collision::Aabb> boxes;
    if (Status s = collision::primitive_boxes(rest_positions_, corners, 3, 0.5f * thickness, boxes); !s) return s;
    const collision::SharesVertexOf<3> shares{mine};
    // The pair of added triangle k and local triangle `other`, when their
    // boxes overlap (rest_close_pairs' candidates), kept if close.
    // A separating axis first (triangles_apart, 50 times cheaper than the
    // distance): it rejects a pair only when its exact distance exceeds the
    // thickness by 1e-4 of the pair's largest coordinate, far beyond the
    // float error of triangle_distance (a few ulps of the coordinates: it
    // measures between points on the two triangles), so every pair it
    // rejects triangle_distance would have put at or past the thickness.
    const auto test = [&](std::size_t k, std::uint32_t other, const collision::Aabb& other_box) {
      const std::uint32_t i = std::min(added[k], other), j = std::max(added[k], other);
      if (i == j || !collision::overlap(boxes[k], other_box) || shares(i, j)) return;
      const std::uint32_t* a = &mine[3 * std::size_t{i}];
      const std::uint32_t* b = &mine[3 * std::size_t{j}];
      float scale = 0.0f;
      for (const std::uint32_t* v : {a, b})
        for (int c = 0; c < 3; ++c)
          for (int d = 0; d < 3; ++d) scale = std::max(scale, std::abs(rest_positions_[4 * std::size_t{v[c]} + d]));
      if (collision::triangles_apart(rest_positions_, a, b, thickness + 1e-4f * scale)) return;
      if (collision::triangle_distance(rest_positions_, a, b) < thickness) pairs.push_back({i, j});
    };
    if (body < solid_bodies_) {
      // The boundary faces of the tets whose rest boxes the added
      // triangle's meets (a face's box lies in its tet's).
      const TetFaces& f = tet_faces_[body];
      // (The face's box made here as primitive_boxes makes it, from the
      // face's corners, and its index looked up only when the boxes meet.)
      std::vector<std::uint32_t> tets;
      const float half = 0.5f * thickness;
      for (std::size_t k = 0; k < added.size(); ++k) {
        tets.clear();
        tree_query(f.rest_tree, boxes[k], tets);
        for (std::uint32_t tet : tets)
          for (std::uint32_t s = 4 * tet; s < 4 * tet + 4; ++s) {
            if (!f.on_boundary[s]) continue;
            collision::Aabb face_box{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
            for (int c : kOutwardFaces[s % 4]) {
              const float* x = &rest_positions_[4 * std::size_t{device_of_[f.first_particle + f.tets[tet][std::size_t(c)]]}];
              for (int d = 0; d < 3; ++d)
                face_box.lo[d] = std::min(face_box.lo[d], x[d]), face_box.hi[d] = std::max(face_box.hi[d], x[d]);
            }
            for (int d = 0; d < 3; ++d) face_box.lo[d] -= half, face_box.hi[d] += half;
            if (!collision::overlap(boxes[k], face_box)) continue;
            const auto other = static_cast<std::uint32_t>(std::lower_bound(f.boundary.begin(), f.boundary.end(), s) -
                                                          f.boundary.begin());
            test(k, other, face_box);
          }
      }
    } else if (added.size() * std::size_t{tree.count} <= kMaxRestTests) {
      std::vector<collision::Aabb> all;
      if (Status s = collision::primitive_boxes(rest_positions_, mine, 3, 0.5f * thickness, all); !s) return s;
      for (std::size_t k = 0; k < added.size(); ++k)
        for (std::uint32_t other = 0; other < tree.count; ++other) test(k, other, all[other]);
    } else {  // a tri body mostly new: all its pairs found afresh
      if (Status s = collision::rest_close_pairs(rest_positions_, mine, thickness, pairs); !s) return s;
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  tree.rest_close = collision::PairSet(pairs, tree.count);
  return {};
}

}  // namespace sinew
