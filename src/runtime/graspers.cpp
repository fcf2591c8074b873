// graspers.cpp — see graspers.h.
#include "runtime/graspers.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "compiler/float_words.h"
#include "contact_params.h"
#include "math/proximity_math.h"
#include "math/vec3.h"

namespace sinew {

namespace {

constexpr std::size_t kTargetFloats = sizeof(kernels::TargetEntry) / 4;

math::Vec3 place(const Pose& pose, const std::array<double, 3>& local) {
  return math::add(pose.position, math::rotate(pose.rotation, local));
}

bool inside(const math::Vec3& local, const std::array<double, 3>& half) {
  return std::abs(local[0]) <= half[0] && std::abs(local[1]) <= half[1] && std::abs(local[2]) <= half[2];
}

// Whether triangle t (in the box's frame) and the box [-half, half] share a
// point: no separating axis among the box's 3 normals, the triangle's
// normal and the 9 cross products of their edges (Akenine-Möller, "Fast
// 3D Triangle-Box Overlap Testing", 2001). Touching counts.
bool crosses(const std::array<math::Vec3, 3>& t, const std::array<double, 3>& half) {
  const auto separates = [&](const math::Vec3& axis) {
    if (math::dot(axis, axis) <= 0.0) return false;  // parallel edges: no axis
    double lo = 1e300, hi = -1e300;
    for (const math::Vec3& p : t) lo = std::min(lo, math::dot(p, axis)), hi = std::max(hi, math::dot(p, axis));
    const double r = half[0] * std::abs(axis[0]) + half[1] * std::abs(axis[1]) + half[2] * std::abs(axis[2]);
    return lo > r || hi < -r;
  };
  const std::array<math::Vec3, 3> box{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  const std::array<math::Vec3, 3> edge{math::sub(t[1], t[0]), math::sub(t[2], t[1]), math::sub(t[0], t[2])};
  for (const math::Vec3& a : box)
    if (separates(a)) return false;
  if (separates(math::cross(edge[0], edge[1]))) return false;
  for (const math::Vec3& a : box)
    for (const math::Vec3& e : edge)
      if (separates(math::cross(a, e))) return false;
  return true;
}

// A triangle's point nearest the jaws' centre (the origin of the box's frame).
struct Candidate {
  double distance2;
  HeldPoint point;
  math::Vec3 local;  // the point, in the grasper's frame
};

}  // namespace

GrasperHolds::GrasperHolds(const SceneDesc& scene, const CompiledScene& compiled) {
  for (std::size_t i = 0; i < scene.graspers.size(); ++i) {
    Grasper g;
    g.block = compiled.grasper_block[i];
    g.first_target = compiled.grasper_first_target[i];
    g.capacity = scene.graspers[i].capacity;
    g.point_block = compiled.grasper_point_block[i];
    g.point_first_target = compiled.grasper_point_first_target[i];
    g.point_capacity = scene.graspers[i].point_capacity;
    g.compliance = scene.graspers[i].compliance;
    graspers_.push_back(std::move(g));
  }
  for (std::size_t b = 0; b < scene.tet_bodies.size(); ++b) {
    tet_meshes_.push_back(scene.tet_bodies[b].mesh);
    tet_first_.push_back(compiled.tet_body_first_particle[b]);
  }
  for (std::size_t b = 0; b < scene.tri_bodies.size(); ++b) {
    tri_meshes_.push_back(scene.tri_bodies[b].mesh);
    tri_first_.push_back(compiled.tri_body_first_particle[b]);
  }
}

const std::vector<std::uint32_t>& GrasperHolds::surface(const TopologyEditor* topology) {
  if (!surface_stale_) return surface_;
  surface_.clear();
  for (std::size_t b = 0; b < tet_meshes_.size(); ++b) {
    TetMesh live;
    live.vertices = tet_meshes_[b].vertices;
    live.tets = topology ? topology->live_tets(b) : tet_meshes_[b].tets;
    for (const auto& f : extract_boundary_surface(live).triangles)
      for (std::uint32_t v : f) surface_.push_back(tet_first_[b] + v);
  }
  for (std::size_t b = 0; b < tri_meshes_.size(); ++b)
    for (const auto& f : topology ? topology->live_triangles(b) : tri_meshes_[b].triangles)
      for (std::uint32_t v : f) surface_.push_back(tri_first_[b] + v);
  surface_stale_ = false;
  return surface_;
}

Result<std::vector<std::uint32_t>> GrasperHolds::close(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                                   std::vector<float>& targets, const ParticleOrder& order,
                                                   std::size_t index, const Pose& pose,
                                                   const std::array<double, 3>& half_extents,
                                                   std::span<const float> xyzw, std::span<const std::uint32_t> surface) {
  Grasper& g = graspers_[index];
  const std::string name = "grasper " + std::to_string(index);
  if (g.closed) return Error(ErrorCode::bad_parameter, name + " is closed already (open it first)");
  // The query: movable particles (inverse mass > 0 on the device's copy,
  // which xyzw carries in w) inside the jaws' box, in the grasper's frame.
  const math::Quat inverse = math::conj(pose.rotation);
  const auto local_of = [&](std::uint32_t p) {
    const math::Vec3 x{xyzw[4 * p], xyzw[4 * p + 1], xyzw[4 * p + 2]};
    return math::rotate(inverse, math::sub(x, pose.position));
  };
  const auto movable = [&](std::uint32_t p) { return xyzw[4 * std::size_t{p} + 3] > 0.0f; };
  std::vector<std::uint32_t> held;
  std::vector<std::array<double, 3>> offsets;
  std::vector<std::uint8_t> in_jaws(xyzw.size() / 4, 0);
  for (std::uint32_t p = 0; 4 * std::size_t{p} + 3 < xyzw.size(); ++p) {
    const math::Vec3 local = local_of(p);
    if (!inside(local, half_extents)) continue;
    in_jaws[p] = 1;
    if (!movable(p)) continue;
    held.push_back(p);
    offsets.push_back(local);
  }
  if (held.size() > g.capacity)
    return Error(ErrorCode::capacity_exceeded, name + " would hold " + std::to_string(held.size()) +
                                                   " particles, more than its capacity " + std::to_string(g.capacity) +
                                                   " (GrasperDesc::capacity); it holds none");
  // Surface points: triangles across the jaws with no vertex inside them,
  // nearest first; one per vertex.
  std::vector<Candidate> candidates;
  for (std::size_t t = 0; g.point_capacity > 0 && 3 * t + 2 < surface.size(); ++t) {
    const std::uint32_t* q = &surface[3 * t];
    if (in_jaws[q[0]] || in_jaws[q[1]] || in_jaws[q[2]] || !(movable(q[0]) || movable(q[1]) || movable(q[2])))
      continue;
    const std::array<math::Vec3, 3> corner{local_of(q[0]), local_of(q[1]), local_of(q[2])};
    if (!crosses(corner, half_extents)) continue;
    using V = kernels::vec4<double>;
    const auto v = [](const math::Vec3& a) { return V{a[0], a[1], a[2], 0.0}; };
    const auto w = kernels::proximity::closest_on_triangle(V{0, 0, 0, 0}, v(corner[0]), v(corner[1]), v(corner[2]));
    const V at = kernels::proximity::at(w, v(corner[0]), v(corner[1]), v(corner[2]));
    candidates.push_back({at.x * at.x + at.y * at.y + at.z * at.z, {{q[0], q[1], q[2]}, {w.wa, w.wb, w.wc}},
                          {at.x, at.y, at.z}});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.distance2 != b.distance2 ? a.distance2 < b.distance2 : a.point.particles < b.point.particles;
  });
  std::vector<HeldPoint> points;
  std::vector<std::array<double, 3>> point_offsets;
  std::vector<std::uint8_t> taken(in_jaws.size(), 0);
  for (const Candidate& c : candidates) {
    const auto& q = c.point.particles;
    if (taken[q[0]] || taken[q[1]] || taken[q[2]]) continue;
    taken[q[0]] = taken[q[1]] = taken[q[2]] = 1;
    points.push_back(c.point);
    point_offsets.push_back(c.local);
  }
  if (points.size() > g.point_capacity)
    return Error(ErrorCode::capacity_exceeded, name + " would hold " + std::to_string(points.size()) +
                                                   " surface points, more than its point_capacity " +
                                                   std::to_string(g.point_capacity) +
                                                   " (GrasperDesc::point_capacity); it holds none");
  // Each held particle's slot and its target, where the particle is now.
  const auto set_target = [&](std::uint32_t target, const math::Vec3& x) {
    kernels::TargetEntry e{};
    e.start_x = e.end_x = static_cast<float>(x[0]);
    e.start_y = e.end_y = static_cast<float>(x[1]);
    e.start_z = e.end_z = static_cast<float>(x[2]);
    store_words(targets, target * kTargetFloats, e);
  };
  for (std::size_t i = 0; i < held.size(); ++i)
    set_target(g.first_target + static_cast<std::uint32_t>(i),
               {xyzw[4 * held[i]], xyzw[4 * held[i] + 1], xyzw[4 * held[i] + 2]});
  // Each point's target: the point now, its offset placed by the pose.
  for (std::size_t i = 0; i < points.size(); ++i)
    set_target(g.point_first_target + static_cast<std::uint32_t>(i), place(pose, point_offsets[i]));
  if (Status s = write_slots(device, buffers, shape, order, g, held, points); !s) return s.error();
  g.closed = true;
  g.held = held;
  g.points = std::move(points);
  g.offsets = std::move(offsets);
  g.offsets.insert(g.offsets.end(), point_offsets.begin(), point_offsets.end());
  return held;
}

Status GrasperHolds::write_slots(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                 const ParticleOrder& order, const Grasper& g, std::span<const std::uint32_t> held,
                                 std::span<const HeldPoint> points) const {
  std::vector<std::uint32_t> slots(held.size());
  for (std::size_t i = 0; i < held.size(); ++i) slots[i] = order.device_of[held[i]];
  if (!slots.empty())
    if (Status s = device.write_buffer(buffers.blocks[g.block].particles, 0, slots.data(), slots.size() * 4); !s)
      return s;
  // Each point's triangle, weights and target.
  if (!points.empty()) {
    std::vector<std::uint32_t> triangles;
    std::vector<float> data;
    for (std::size_t i = 0; i < points.size(); ++i) {
      for (std::uint32_t p : points[i].particles) triangles.push_back(order.device_of[p]);
      // The whole slot: the program's shape keeps no constraint data.
      const std::uint32_t target = g.point_first_target + static_cast<std::uint32_t>(i);
      data.insert(data.end(), {static_cast<float>(points[i].weights[0]), static_cast<float>(points[i].weights[1]),
                               static_cast<float>(points[i].weights[2]), static_cast<float>(g.compliance),
                               static_cast<float>(target), 0.0f, 0.0f, 0.0f});
    }
    const BlockBuffers& b = buffers.blocks[g.point_block];
    if (Status s = device.write_buffer(b.particles, 0, triangles.data(), triangles.size() * 4); !s) return s;
    if (Status s = device.write_buffer(b.data, 0, data.data(), data.size() * 4); !s) return s;
  }
  if (g.point_block != UINT32_MAX) shape.blocks[g.point_block].color_counts = {static_cast<std::uint32_t>(points.size())};
  shape.blocks[g.block].color_counts = {static_cast<std::uint32_t>(held.size())};
  return {};
}

GrasperHolds::Hold GrasperHolds::hold(std::size_t index) const {
  const Grasper& g = graspers_[index];
  return {g.closed, g.held, g.points, g.offsets};
}

Status GrasperHolds::check(std::size_t index, const Hold& hold, std::size_t particles, const std::string& what) const {
  const Grasper& g = graspers_[index];
  const std::string name = what + ": grasper " + std::to_string(index);
  if (!hold.closed && (!hold.held.empty() || !hold.points.empty() || !hold.offsets.empty()))
    return Error(ErrorCode::bad_input_file, name + " is open but holds particles");
  if (hold.held.size() > g.capacity || hold.points.size() > g.point_capacity)
    return Error(ErrorCode::bad_input_file, name + " holds " + std::to_string(hold.held.size()) + " particles and " +
                                                std::to_string(hold.points.size()) + " points, past its capacities " +
                                                std::to_string(g.capacity) + " and " + std::to_string(g.point_capacity));
  if (hold.offsets.size() != hold.held.size() + hold.points.size())
    return Error(ErrorCode::bad_input_file, name + " has " + std::to_string(hold.offsets.size()) + " offsets for " +
                                                std::to_string(hold.held.size() + hold.points.size()) + " holds");
  for (std::uint32_t p : hold.held)
    if (p >= particles) return Error(ErrorCode::bad_input_file, name + " holds particle " + std::to_string(p) + " of " +
                                                                    std::to_string(particles));
  for (const HeldPoint& q : hold.points)
    for (std::uint32_t p : q.particles)
      if (p >= particles) return Error(ErrorCode::bad_input_file, name + "'s point has particle " + std::to_string(p) +
                                                                     " of " + std::to_string(particles));
  return {};
}

Status GrasperHolds::restore(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                             const ParticleOrder& order, std::size_t index, const Hold& hold) {
  Grasper& g = graspers_[index];
  if (Status s = write_slots(device, buffers, shape, order, g, hold.held, hold.points); !s) return s;
  g.closed = hold.closed;
  g.held = hold.held;
  g.points = hold.points;
  g.offsets = hold.offsets;
  return {};
}

void GrasperHolds::move(std::vector<float>& targets, std::size_t index, const Pose& pose) {
  Grasper& g = graspers_[index];
  const auto end_at = [&](std::uint32_t target, const std::array<double, 3>& offset) {
    auto e = load_words<kernels::TargetEntry>(targets, target * kTargetFloats);
    const math::Vec3 x = place(pose, offset);
    e.end_x = static_cast<float>(x[0]);
    e.end_y = static_cast<float>(x[1]);
    e.end_z = static_cast<float>(x[2]);
    store_words(targets, target * kTargetFloats, e);
  };
  for (std::size_t i = 0; i < g.held.size(); ++i) end_at(g.first_target + static_cast<std::uint32_t>(i), g.offsets[i]);
  for (std::size_t i = 0; i < g.points.size(); ++i)
    end_at(g.point_first_target + static_cast<std::uint32_t>(i), g.offsets[g.held.size() + i]);
}

Result<std::vector<std::uint32_t>> GrasperHolds::open(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                                  std::size_t index) {
  Grasper& g = graspers_[index];
  for (const auto& [block, count] : {std::pair{g.block, g.held.size()}, std::pair{g.point_block, g.points.size()}}) {
    if (count == 0) continue;
    const std::vector<float> zeros(count, 0.0f);
    if (Status s = device.write_buffer(buffers.blocks[block].residual, 0, zeros.data(), zeros.size() * 4); !s)
      return s.error();
    shape.blocks[block].color_counts = {0};
  }
  std::vector<std::uint32_t> released = std::move(g.held);
  g.held.clear();
  g.points.clear();
  g.offsets.clear();
  g.closed = false;
  shape.blocks[g.block].color_counts = {0};
  return released;
}

}  // namespace sinew
