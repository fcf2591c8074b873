// mesh_collision.cpp — the host side of the contacts between meshes (see
// mesh_collision.h): once per frame, read the positions back, refit the
// BVHs over boxes inflated by half the reach (thickness + motion margin),
// find the candidate pairs and the contacts closer than the reach, colour
// them (greedy, coloring/greedy_coloring.h) and upload them colour-sorted.
#include "runtime/mesh_collision.h"
#include "runtime/suture_exemption.h"

#include "collision/shape_distance.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "coloring/greedy_coloring.h"
#include "collision/parallel_pairs.h"
#include "collision/shape_distance.h"
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
  for (std::size_t b = 0; b < scene.tet_bodies.size(); ++b, ++body) {
    const std::uint32_t first = compiled.tet_body_first_particle[b];
    for (const auto& f : extract_boundary_surface(scene.tet_bodies[b].mesh).triangles) {
      for (std::uint32_t v : f) mc->triangles_.push_back(device_of[first + v]);
      mc->triangle_body_.push_back(body);
    }
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
  // One tree per body: contiguous runs of triangle_body_ / segment_body_.
  const auto ranges = [](const std::vector<std::uint32_t>& body_of, std::vector<BodyTree>& trees) {
    for (std::uint32_t k = 0; k < body_of.size(); ++k)
      if (k == 0 || body_of[k] != body_of[k - 1]) {
        trees.emplace_back();
        trees.back().first = k;
      }
    for (std::size_t t = 0; t < trees.size(); ++t)
      trees[t].count = (t + 1 < trees.size() ? trees[t + 1].first : static_cast<std::uint32_t>(body_of.size())) -
                       trees[t].first;
  };
  ranges(mc->triangle_body_, mc->triangle_trees_);
  ranges(mc->segment_body_, mc->segment_trees_);
  mc->body_of_.assign(compiled.positions.size(), UINT32_MAX);
  for (std::size_t t = 0; t < mc->triangle_body_.size(); ++t)
    for (int k = 0; k < 3; ++k) mc->body_of_[mc->triangles_[3 * t + k]] = mc->triangle_body_[t];
  for (std::size_t t = 0; t < mc->segment_body_.size(); ++t)
    for (int k = 0; k < 2; ++k) mc->body_of_[mc->segments_[2 * t + k]] = mc->segment_body_[t];
  mc->ownership_ = collision::triangle_ownership(mc->triangles_);
  mc->solid_triangles_ = 0;
  while (mc->solid_triangles_ < mc->triangle_body_.size() && mc->triangle_body_[mc->solid_triangles_] < mc->solid_bodies_)
    ++mc->solid_triangles_;
  if (mc->desc_.self_collision) {
    mc->index_solid_edges();
    std::vector<float> start(4 * compiled.positions.size());
    for (std::size_t p = 0; p < compiled.positions.size(); ++p) {
      const auto& x = compiled.positions[p];
      start[4 * p] = x.x, start[4 * p + 1] = x.y, start[4 * p + 2] = x.z, start[4 * p + 3] = 0.0f;
    }
    if (Status s = mc->find_rest_close(start); !s) return s.error();
  }
  mc->collidable_ = mc->triangles_;
  mc->collidable_.insert(mc->collidable_.end(), mc->segments_.begin(), mc->segments_.end());
  std::sort(mc->collidable_.begin(), mc->collidable_.end());
  mc->collidable_.erase(std::unique(mc->collidable_.begin(), mc->collidable_.end()), mc->collidable_.end());
  mc->movable_.resize(compiled.positions.size());
  for (std::size_t p = 0; p < compiled.positions.size(); ++p) mc->movable_[p] = compiled.positions[p].w > 0.0f;

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

// The solids' surface edges and their two faces, sorted by edge (create).
void MeshCollision::index_solid_edges() {
  solid_edges_.clear();
  for (std::uint32_t t = 0; t < solid_triangles_; ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = triangles_[3 * std::size_t{t} + k], b = triangles_[3 * std::size_t{t} + (k + 1) % 3];
      solid_edges_.push_back({(std::uint64_t{std::min(a, b)} << 32) | std::max(a, b), t});
    }
  std::sort(solid_edges_.begin(), solid_edges_.end());
}

// The faces on edge (a, b) of a solid's surface: [first, last) in solid_edges_.
std::pair<std::size_t, std::size_t> MeshCollision::faces_on(std::uint32_t a, std::uint32_t b) const {
  const std::uint64_t key = (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
  const auto lo = std::lower_bound(solid_edges_.begin(), solid_edges_.end(), std::pair{key, std::uint32_t{0}});
  auto hi = lo;
  while (hi != solid_edges_.end() && hi->first == key) ++hi;
  return {std::size_t(lo - solid_edges_.begin()), std::size_t(hi - solid_edges_.begin())};
}

std::uint32_t MeshCollision::solid_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
  const auto [first, last] = faces_on(a, b);
  for (std::size_t k = first; k < last; ++k) {
    const std::uint32_t* v = &triangles_[3 * std::size_t{solid_edges_[k].second}];
    if (v[0] == c || v[1] == c || v[2] == c) return solid_edges_[k].second;
  }
  return UINT32_MAX;
}

bool MeshCollision::solid_edge(std::uint32_t a, std::uint32_t b, float out[3]) const {
  const auto [first, last] = faces_on(a, b);
  if (first == last) return false;
  out[0] = out[1] = out[2] = 0.0f;
  for (std::size_t k = first; k < last; ++k)
    for (int d = 0; d < 3; ++d) out[d] += face_out_[3 * std::size_t{solid_edges_[k].second} + d];
  return true;
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
  if (Status s = device.read_buffer(scene_buffers.position, 0, positions_.data(), positions_.size() * 4); !s) return s;
  read_back_bytes_ += positions_.size() * 4;
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
