// simulation_contacts.cpp — moving colliders and targets between frames, and
// the tissue's side of the tools: their colliders and the reaction the
// tissue exerts on them.
//
// Colliders and targets: each entry of the collider and target buffers
// (kernels/shared/contact_params.h) holds a pose at the start and at the end
// of the frame, which the kernels interpolate per substep. set_collider_pose
// and set_target write the end pose; after each frame the start pose becomes
// that end pose. The buffers are uploaded before a frame only when something
// changed, so static colliders cost no transfer.
//
// Tools: a tool is a capsule or level-set collider whose motion the host
// integrates (rigid_tool.h: the coupling with the tissue, its stabilisation
// and its limits; tool_penalty.h: a level-set tool against colliders and
// tools). Here is the tissue's side: before each frame (before_frame) each
// tool is integrated over the frame and its collider entry moves from the
// old pose to the new one across the frame's substeps; during the frame
// the contact kernel sums each correction's impulse, and its moment about
// the tool's centre, per particle and tool in the contact-impulse buffer;
// at the end of the frame they are reduced on the device, in a fixed order
// and double-float precision (program/stats_program.h), and after it
// (after_frame) a few words come back as the tool's reaction: the frame's
// average contact force and torque (tool_state), the force and torque of
// its last substep and the mass and inertia of the particles touching the
// tool at its end (which the next integration uses).
//
// State: Impl::colliders and Impl::targets are host copies of the device
// buffers; the tools' rigid state lives in Impl::contacts (contact_state.h),
// all sized in init_contacts: nothing here allocates per frame.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "compiler/float_words.h"
#include "contact_params.h"
#include "math/vec3.h"
#include "runtime/call_checks.h"
#include "runtime/simulation_impl.h"
#include "runtime/simulation_internals.h"
#include "runtime/tool_contacts.h"
#include "runtime/tool_penalty.h"
#include "runtime/trocar.h"

namespace sinew {
namespace {

using call_checks::check_finite;
using call_checks::check_index;
using call_checks::check_rotation;
using call_checks::str;

using kernels::ColliderEntry;
using kernels::ColliderHeader;
using kernels::TargetEntry;
using V3 = math::Vec3;
using Q4 = math::Quat;

constexpr std::size_t kHeaderFloats = sizeof(ColliderHeader) / sizeof(float);
constexpr std::size_t kEntryFloats = sizeof(ColliderEntry) / sizeof(float);
constexpr std::size_t kTargetFloats = sizeof(TargetEntry) / sizeof(float);

std::size_t entry_at(std::size_t k) { return kHeaderFloats + k * kEntryFloats; }

// The header, the entries and the implicit shapes' nodes after them.
std::size_t device_floats(const std::vector<float>& c) {
  const auto h = load_words<ColliderHeader>(c, 0);
  const std::size_t entries = std::size_t{h.colliders} + h.tools;
  std::size_t nodes = 0;
  for (std::size_t k = 0; k < entries && entry_at(k + 1) <= c.size(); ++k)
    nodes += load_words<ColliderEntry>(c, entry_at(k)).implicit_count;
  return entry_at(entries) + nodes * (sizeof(kernels::ImplicitEntry) / sizeof(float));
}

void set_end_pose(ColliderEntry& e, const V3& p, const Q4& q) {
  e.end_px = static_cast<float>(p[0]);
  e.end_py = static_cast<float>(p[1]);
  e.end_pz = static_cast<float>(p[2]);
  e.end_qw = static_cast<float>(q[0]);
  e.end_qx = static_cast<float>(q[1]);
  e.end_qy = static_cast<float>(q[2]);
  e.end_qz = static_cast<float>(q[3]);
}

// Start pose := end pose; true when that changed it.
bool settle(ColliderEntry& e) {
  const bool moved = e.start_px != e.end_px || e.start_py != e.end_py || e.start_pz != e.end_pz ||
                     e.start_qw != e.end_qw || e.start_qx != e.end_qx || e.start_qy != e.end_qy ||
                     e.start_qz != e.end_qz;
  e.start_px = e.end_px;
  e.start_py = e.end_py;
  e.start_pz = e.end_pz;
  e.start_qw = e.end_qw;
  e.start_qx = e.end_qx;
  e.start_qy = e.end_qy;
  e.start_qz = e.end_qz;
  return moved;
}

// `shape` at the start or end pose of collider entry k.
PosedShape posed(const ColliderDesc& shape, const std::vector<float>& colliders, std::size_t k, bool start) {
  const auto e = load_words<ColliderEntry>(colliders, entry_at(k));
  if (start) return {&shape, {e.start_px, e.start_py, e.start_pz}, {e.start_qw, e.start_qx, e.start_qy, e.start_qz}};
  return {&shape, {e.end_px, e.end_py, e.end_pz}, {e.end_qw, e.end_qx, e.end_qy, e.end_qz}};
}

}  // namespace

Status Simulation::Impl::init_contacts(const SceneDesc& scene, const CompiledScene& compiled) {
  colliders = compiled.colliders;
  targets = compiled.targets;
  if (colliders.size() < kHeaderFloats) {  // no collider buffer compiled: an empty header
    colliders.assign(kHeaderFloats, 0.0f);
    store_words(colliders, 0, ColliderHeader{0, 0, 1.0f, 0});
  }
  const auto header = load_words<ColliderHeader>(colliders, 0);
  if (header.colliders != scene.colliders.size() || header.tools != scene.tools.size() ||
      colliders.size() != device_floats(colliders))
    return Error(ErrorCode::internal,
                 "internal: the compiled collider buffer does not match the scene's colliders and tools");

  contacts = ContactState{};
  contacts.colliders = header.colliders;
  contacts.substeps = static_cast<std::uint32_t>(scene.solver.substeps);
  contacts.iterations = static_cast<std::uint32_t>(scene.solver.iterations);
  for (const ToolDesc& d : scene.tools) {
    ToolBody& b = contacts.tools.emplace_back();
    b.position = d.position;
    b.rotation = d.rotation;
    if (d.gravity) b.gravity = scene.gravity;
    b.inertia = d.inertia;
    b.mass = d.mass;
    b.radius = d.radius;
    b.half_height = d.half_height;
    b.dynamic_friction = d.dynamic_friction;
    if (d.trocar) {  // checked: the shaft line within kTrocarPoseTolerance of the pivot, the axis non-zero
      b.trocar = true;
      b.pivot = d.trocar->pivot;
      b.shaft_axis = math::mul(d.trocar->axis, 1.0 / std::sqrt(math::dot(d.trocar->axis, d.trocar->axis)));
      b.position = math::add(b.position, trocar_offset(b.pivot, math::rotate(b.rotation, b.shaft_axis), b.position));
    }
    if (d.shape == ToolShape::level_set) {
      // Its point shell: the level set's zero surface, a third of each
      // triangle's area to each corner (tool_penalty.h).
      const SurfacePoints shell = surface_points(d.level_set->surface());
      for (std::size_t i = 0; i < shell.points.size(); ++i) {
        if (!(shell.areas[i] > 0.0)) continue;  // a vertex of no triangle
        b.points.push_back(shell.points[i]);
        b.areas.push_back(shell.areas[i]);
      }
      if (b.points.empty())
        return Error(ErrorCode::bad_parameter, "tools[" + std::to_string(contacts.tools.size() - 1) +
                                                   "].level_set has no surface (no zero crossing in its grid)");
      b.level_set = true;
      b.penalty_stiffness = d.penalty_stiffness;
      b.penalty_damping = d.penalty_damping;
      ColliderDesc shape;
      shape.shape = ColliderShape::level_set;
      shape.level_set = d.level_set;
      shape.static_friction = d.static_friction;
      shape.dynamic_friction = d.dynamic_friction;
      contacts.tool_shapes.push_back(std::move(shape));
    } else {
      contacts.tool_shapes.push_back(tool_capsule(b));
    }
  }
  contacts.shapes = scene.colliders;
  contacts.level_set_offsets = compiled.level_set_offsets;
  return {};
}

std::vector<PosedShape> Simulation::Impl::collider_shapes(bool start) const {
  std::vector<PosedShape> shapes;
  for (std::uint32_t k = 0; k < contacts.colliders; ++k) shapes.push_back(posed(contacts.shapes[k], colliders, k, start));
  return shapes;
}

std::vector<PosedShape> Simulation::Impl::tool_shapes(bool start) const {
  std::vector<PosedShape> shapes;
  for (std::size_t t = 0; t < contacts.tools.size(); ++t)
    shapes.push_back(posed(contacts.tool_shapes[t], colliders, contacts.colliders + t, start));
  return shapes;
}

std::vector<FrameCapsule> Simulation::Impl::frame_capsules() const {
  std::vector<FrameCapsule> capsules;
  for (std::uint32_t k = 0; k < contacts.colliders; ++k)
    if (contacts.shapes[k].shape == ColliderShape::capsule)
      capsules.push_back({posed(contacts.shapes[k], colliders, k, true), posed(contacts.shapes[k], colliders, k, false),
                          collision::Contact::kNoShape});
  for (std::size_t t = 0; t < contacts.tools.size(); ++t) {
    if (contacts.tools[t].level_set) continue;  // not swept (scene.h, ToolDesc)
    const std::size_t k = contacts.colliders + t;
    capsules.push_back({posed(contacts.tool_shapes[t], colliders, k, true),
                        posed(contacts.tool_shapes[t], colliders, k, false), static_cast<std::uint32_t>(t)});
  }
  return capsules;
}

Status Simulation::Impl::before_frame() {
  ContactState& c = contacts;
  // Level-set tools: the penalty where everything is at the frame's start
  // (the colliders where the last frame left them) drives this frame.
  if (std::any_of(c.tools.begin(), c.tools.end(), [](const ToolBody& b) { return b.level_set; }))
    add_tool_penalties(c.tools, c.tool_shapes, collider_shapes(true));
  for (ToolBody& b : c.tools) integrate_tool(b, time_step, double(c.iterations) * c.substeps * c.substeps);
  // The tools against the colliders where those end this frame, and each other.
  if (!c.tools.empty()) resolve_tool_contacts(c.tools, collider_shapes(), time_step);
  // A collider may have pushed a tool sideways through its port: the port wins.
  for (ToolBody& b : c.tools) hold_trocar(b, time_step, double(c.iterations) * c.substeps * c.substeps);
  for (std::size_t t = 0; t < c.tools.size(); ++t) {
    const ToolBody& b = c.tools[t];
    const std::size_t at = entry_at(c.colliders + t);
    auto e = load_words<ColliderEntry>(colliders, at);
    settle(e);  // the frame starts where the last one ended
    set_end_pose(e, b.position, b.rotation);
    store_words(colliders, at, e);
    c.colliders_dirty = true;
  }
  if (c.colliders_dirty) {
    if (Status s = device->write_buffer(buffers.colliders, 0, colliders.data(), colliders.size() * sizeof(float)); !s)
      return s;
    c.colliders_dirty = false;
  }
  if (c.targets_dirty && !targets.empty()) {
    if (Status s = device->write_buffer(buffers.targets, 0, targets.data(), targets.size() * sizeof(float)); !s)
      return s;
  }
  c.targets_dirty = false;
  return {};
}

Status Simulation::Impl::after_frame() {
  ContactState& c = contacts;
  // What moved during this frame stays at its end pose from now on.
  for (std::uint32_t k = 0; k < c.colliders; ++k) {
    auto e = load_words<ColliderEntry>(colliders, entry_at(k));
    if (settle(e)) {
      store_words(colliders, entry_at(k), e);
      c.colliders_dirty = true;
    }
  }
  for (std::size_t at = 0; at + kTargetFloats <= targets.size(); at += kTargetFloats) {
    auto e = load_words<TargetEntry>(targets, at);
    if (e.start_x != e.end_x || e.start_y != e.end_y || e.start_z != e.end_z) {
      e.start_x = e.end_x;
      e.start_y = e.end_y;
      e.start_z = e.end_z;
      store_words(targets, at, e);
      c.targets_dirty = true;
    }
  }
  if (c.tools.empty()) return {};

  // The tissue's reaction on each tool: the frame's impulse sums and the
  // touching particles' mass and inertia, reduced on the device (stats_program.h).
  const double h = time_step / c.substeps;
  for (std::size_t t = 0; t < c.tools.size(); ++t) {
    const DeviceStats::Tool& sums = device_stats.tools[t];
    ToolBody& b = c.tools[t];
    for (int k = 0; k < 3; ++k) {
      b.contact_force[k] = sums.sums[0][k] / time_step;
      b.contact_torque[k] = sums.sums[1][k] / time_step;
      b.coupling_force[k] = sums.sums[2][k] / h;
      b.coupling_torque[k] = sums.sums[3][k] / h;
    }
    b.touching_mass = sums.mass;
    b.touching_inertia = sums.inertia;
  }
  // The reaction through the meshes' faces and segments (mesh contacts
  // with the tools' capsules), read back by the mesh collision.
  if (mesh_collision) mesh_collision->add_tool_reactions(c.tools, time_step, h);
  return {};
}

Status Simulation::set_collider_pose(std::size_t index, const std::array<double, 3>& position,
                                     const std::array<double, 4>& rotation) {
  constexpr const char* call = "set_collider_pose";
  if (Status s = check_index(call, "collider", index, impl_->contacts.colliders); !s) return s;
  if (Status s = check_finite(call, "position", position); !s) return s;
  if (Status s = check_rotation(call, rotation); !s) return s;
  std::vector<float>& c = impl_->colliders;
  auto e = load_words<ColliderEntry>(c, entry_at(index));
  set_end_pose(e, position, rotation);
  store_words(c, entry_at(index), e);
  impl_->contacts.colliders_dirty = true;
  return {};
}

Pose SimulationInternals::collider_pose(const Simulation& sim, std::size_t index) {
  const auto e = load_words<ColliderEntry>(sim.impl_->colliders, entry_at(index));
  return Pose{.position = {e.end_px, e.end_py, e.end_pz}, .rotation = {e.end_qw, e.end_qx, e.end_qy, e.end_qz}};
}

Status Simulation::set_target(std::size_t index, const std::array<double, 3>& position) {
  constexpr const char* call = "set_target";
  std::vector<float>& targets = impl_->targets;
  if (Status s = check_index(call, "target", index, impl_->scene_targets); !s) return s;
  if (Status s = check_finite(call, "position", position); !s) return s;
  auto e = load_words<TargetEntry>(targets, index * kTargetFloats);
  e.end_x = static_cast<float>(position[0]);
  e.end_y = static_cast<float>(position[1]);
  e.end_z = static_cast<float>(position[2]);
  store_words(targets, index * kTargetFloats, e);
  impl_->contacts.targets_dirty = true;
  return {};
}

Status Simulation::apply_tool_force(std::size_t index, const std::array<double, 3>& force,
                                    const std::array<double, 3>& torque) {
  constexpr const char* call = "apply_tool_force";
  std::vector<ToolBody>& tools = impl_->contacts.tools;
  if (Status s = check_index(call, "tool", index, tools.size()); !s) return s;
  if (Status s = check_finite(call, "force", force); !s) return s;
  if (Status s = check_finite(call, "torque", torque); !s) return s;
  ToolBody& b = tools[index];
  return add_frame_force(b, force, torque, impl_->time_step, std::string(call) + ": tool " + std::to_string(index));
}

Result<ToolState> Simulation::tool_state(std::size_t index) const {
  const std::vector<ToolBody>& tools = impl_->contacts.tools;
  if (Status s = check_index("tool_state", "tool", index, tools.size()); !s) return s.error();
  const ToolBody& b = tools[index];
  ToolState state;
  state.position = b.position;
  state.rotation = b.rotation;
  state.velocity = b.velocity;
  state.angular_velocity = b.angular_velocity;
  state.contact_force = b.contact_force;
  state.contact_torque = b.contact_torque;
  state.penalty_force = b.penalty_force;
  state.penalty_torque = b.penalty_torque;
  state.penalty_points = b.penalty_points;
  state.penalty_depth = b.penalty_depth;
  state.trocar_force = b.trocar_force;
  state.trocar_torque = b.trocar_torque;
  state.cut_volume = b.cut_volume;
  return state;
}

Status Simulation::set_needle_pose(std::size_t index, const std::array<double, 3>& position,
                                   const std::array<double, 4>& rotation) {
  constexpr const char* call = "set_needle_pose";
  if (Status s = check_index(call, "needle", index, impl_->sutures ? impl_->sutures->needles() : 0); !s) return s;
  if (Status s = check_finite(call, "position", position); !s) return s;
  if (Status s = check_rotation(call, rotation); !s) return s;
  return impl_->sutures->set_pose(index, position, rotation);
}

Status Simulation::apply_needle_force(std::size_t index, const std::array<double, 3>& force,
                                      const std::array<double, 3>& torque) {
  constexpr const char* call = "apply_needle_force";
  if (Status s = check_index(call, "needle", index, impl_->sutures ? impl_->sutures->needles() : 0); !s) return s;
  if (Status s = check_finite(call, "force", force); !s) return s;
  if (Status s = check_finite(call, "torque", torque); !s) return s;
  return impl_->sutures->apply_force(index, force, torque, impl_->time_step);
}

Result<NeedleState> Simulation::needle_state(std::size_t index) const {
  if (Status s = check_index("needle_state", "needle", index, impl_->sutures ? impl_->sutures->needles() : 0); !s)
    return s.error();
  return impl_->sutures->state(index);
}

Result<CutReport> Simulation::cut_collider(std::size_t index, const CutterShape& shape, const Pose& from,
                                           const Pose& to) {
  return impl_->cut_collider(index, shape, from, to);
}

Result<CutReport> Simulation::Impl::cut_collider(std::size_t index, const CutterShape& shape, const Pose& from,
                                                 const Pose& to) {
  constexpr const char* call = "cut_collider";
  ContactState& c = contacts;
  if (Status s = check_index(call, "collider", index, c.shapes.size()); !s) return s.error();
  ColliderDesc& collider = c.shapes[index];
  if (collider.shape != ColliderShape::level_set || !collider.level_set)
    return Error(ErrorCode::bad_parameter,
                 std::string(call) + ": collider " + std::to_string(index) + " is not a level set");
  auto report = collider.level_set->cut(shape, from, to);
  if (!report) return report.error();
  // The device's copy: the changed leaves, at the grid's place in the
  // grids buffer, before the next frame reads them.
  const std::span<const std::byte> bytes = collider.level_set->nanovdb_bytes();
  const std::uint64_t base = c.level_set_offsets[index];
  if (!report->changed_bytes.empty()) ++shape_generation;
  for (const auto& [offset, size] : report->changed_bytes)
    if (Status s = device->write_buffer(buffers.level_set_grids, base + offset, bytes.data() + offset,
                                               size);
        !s)
      return s.error();
  return report;
}

}  // namespace sinew
