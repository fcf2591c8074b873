// mesh_collision.cpp — the host side of the contacts between meshes (see
// mesh_collision.h): making the collidable primitives and the contact
// buffers (create, release), reading the positions back after each frame
// (the next frame's detection starts from them) and the tools' share of the
// contacts' multipliers (after_frame, add_tool_reactions). The frame's
// detection is in mesh_collision_detect.cpp, the contacts with the
// colliders' and tools' faces in mesh_collision_shapes.cpp, colouring and
// upload in mesh_collision_schedule.cpp, the trees and rest-close pairs in
// mesh_collision_trees.cpp and topology changes in
// mesh_collision_topology.cpp.
#include "runtime/mesh_collision.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

#include "mesh/tet_faces.h"
#include "sinew/mesh.h"

namespace sinew {
namespace {

constexpr std::uint32_t kFirstColors = 16;
// Colours kept free for continuous collision's contacts at first (doubled,
// up to 32, when a frame needs more: append_contacts).
constexpr std::uint32_t kContinuousColors = 8;

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
  if (mc->desc_.schedule == ContactSchedule::device_colored)
    if (Status s = mc->make_device_coloring(device); !s) return s.error();
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

Status MeshCollision::make_device_coloring(Device& device) {
  MeshContactBuffers& b = buffers_;
  if (b.device_colored)
    if (Status s = destroy_device_contact_coloring(device, b.coloring); !s) return s;
  b.device_colored = false;  // until the new buffers exist
  auto made = make_device_contact_coloring(device, b.capacity, static_cast<std::uint32_t>(movable_.size()),
                                           desc_.device_colors, desc_.device_rounds);
  if (!made) return made.error();
  b.coloring = *made;
  b.device_colored = true;
  return {};
}

Status MeshCollision::take_counters(std::span<const std::uint32_t> counters) {
  if (!buffers_.device_colored) return {};
  const std::uint32_t cap = buffers_.coloring.colors;
  if (counters.size() < DeviceColoringCounters::first_color + cap)
    return Error(ErrorCode::internal, "internal: the frame program has " + std::to_string(counters.size()) +
                                          " counters, fewer than the contacts' device colouring declares");
  color_count_ = 0;
  for (std::uint32_t k = 0; k < cap; ++k)
    if (counters[DeviceColoringCounters::first_color + k] > 0) color_count_ = k + 1;
  overflow_count_ = counters[DeviceColoringCounters::overflow];
  return {};
}

Status MeshCollision::release(Device& device) {
  MeshContactBuffers& b = buffers_;
  if (b.device_colored) {
    if (Status s = destroy_device_contact_coloring(device, b.coloring); !s) return s;
    b.device_colored = false;
  }
  for (BufferHandle* h : {&b.table, &b.particles, &b.coefficients, &b.normals, &b.lambda, &b.lambda_sum, &b.motion,
                          &b.delta, &b.touched, &b.offsets, &b.slots})
    if (h->valid()) {
      if (Status s = device.destroy_buffer(*h); !s) return s;
      *h = {};
    }
  return {};
}

// The velocities that set the reach are the frame's mean ones, (end - start)
// / dt, not the device's, which are the last substep's: after an impact those
// carry the jitter of single corrections (measured: a kidney landing on the
// liver's surface showed 1.4-2.4 m/s after a 0.3 m/s fall), and a reach
// grown from them paired most of both surfaces, frame after frame. Only the
// first frame, with no previous positions, reads the device's velocities.
Status MeshCollision::read_back(Device& device, const XpbdBuffers& scene_buffers) {
  const std::size_t particles = movable_.size();
  const bool have_start = positions_.size() == particles * 4 && !restored_;
  if (have_start) start_positions_.swap(positions_);
  positions_.resize(particles * 4);
  velocities_.resize(particles * 4);
  if (mirror_) {
    if (Status s = mirror_->copy_to(device, scene_buffers.position, particles * 4, positions_); !s) return s;
  } else if (Status s = device.read_buffer(scene_buffers.position, 0, positions_.data(), positions_.size() * 4); !s) {
    return s;
  }
  if (restored_) {
    restored_ = false;  // velocities_ are the saved state's
  } else if (have_start) {
    const auto inv_dt = static_cast<float>(1.0 / time_step_);
    for (std::size_t k = 0; k < positions_.size(); ++k)
      velocities_[k] = inv_dt * (positions_[k] - start_positions_[k]);
  } else if (Status s = device.read_buffer(scene_buffers.velocity, 0, velocities_.data(), velocities_.size() * 4);
             !s) {
    return s;
  }
  fresh_ = true;
  return {};
}

void MeshCollision::save_velocities(std::vector<float>& out) const {
  // After a frame (fresh_) or a restore, velocities_ are what the next
  // frame measures from; before the first frame there are none.
  if (fresh_ || restored_)
    out = velocities_;
  else
    out.clear();
}

// Why saved: the next frame's reach and boxes come from the last frame's
// mean velocities, which the device does not hold (its velocities are the
// last substep's); measured from the positions read before the restore, a
// restored run found other contacts than the run it was saved from.
Status MeshCollision::restore_velocities(std::vector<float> velocities) {
  if (!velocities.empty() && velocities.size() != movable_.size() * 4)
    return Error(ErrorCode::bad_parameter, "mesh collision: " + std::to_string(velocities.size()) +
                                               " restored velocity floats for " + std::to_string(movable_.size()) +
                                               " particles (4 each)");
  fresh_ = false;
  restored_ = !velocities.empty();
  if (restored_) {
    velocities_ = std::move(velocities);
  } else {
    positions_.clear();  // as before the first frame: the device's velocities are read
    velocities_.clear();
  }
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
  }
  // How far the frame's contacts ended inside their thickness, from the
  // very positions the next frame's detection starts from.
  // Split by kind: a body against itself (both primitives of one body),
  // and a face or segment against a tool (tool_slots_).
  double worst = 0.0, worst_self = 0.0, worst_tool = 0.0;
  const auto slots = contact_count_ + static_cast<std::uint32_t>(appended_.size());
  tool_slot_.assign(slots, 0);
  for (const auto& [slot, tool] : tool_slots_)
    if (slot < slots) tool_slot_[slot] = 1;
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
    const double inside = desc_.thickness - gap;
    worst = std::max(worst, inside);
    // A shape's contact repeats its first particle (mesh_contact_params.h);
    // between primitives, particles 0 and 3 are on either side.
    const std::uint32_t* v = &upload_particles_[4 * std::size_t{k}];
    if (v[0] != v[1] && body_of_[v[0]] == body_of_[v[3]]) worst_self = std::max(worst_self, inside);
    if (tool_slot_[k]) worst_tool = std::max(worst_tool, inside);
  }
  violation_ = worst;
  self_violation_ = worst_self;
  tool_violation_ = worst_tool;
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

}  // namespace sinew
