// simulation_state.cpp — Simulation::save_state and restore_state
// (sinew/saved_state.h): the device buffers that carry from frame to frame
// (the scene's own, and its fluid's) and the host state of the frame's
// stages, written in one order into the versioned format of
// runtime/state_format.h and read back in the same one.
//
// Why bitwise: a frame's result depends only on the device buffers listed
// in Impl::saved_buffers, the colliders' and targets' host copies (uploaded
// before the frame), the rigid tools' state, the particle forces' flags,
// the residual stepper's warm start, the mesh collision's velocities (the
// last frame's mean, which set the next frame's reach), the fluid's
// counts and the graspers' holds (the particles and points in their slots,
// written again with the program rebuilt); all are restored exactly (and the mesh collision reads the
// positions again), and the
// scene's constant data (constraint data, level-set grids) is checked to be
// unchanged through shape_generation.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "fluid/sph_solver.h"
#include "runtime/simulation_impl.h"
#include "runtime/state_format.h"

namespace sinew {
namespace {

// The rigid tools' state that changes while the scene runs, visited field by
// field in the format's order (the same visit writes and reads).
template <class Tool, class Visit>
void tool_fields(Tool& t, Visit visit) {
  for (auto* v : {&t.position, &t.velocity, &t.angular_velocity, &t.force, &t.torque, &t.contact_force,
                  &t.contact_torque, &t.coupling_force, &t.coupling_torque, &t.penalty_force, &t.penalty_torque})
    visit(*v);
  visit(t.rotation);
  visit(t.touching_mass);
  visit(t.touching_inertia);
  visit(t.penalty_points);
  visit(t.penalty_depth);
}

bool has_trocar(const std::vector<ToolBody>& tools) {
  return std::any_of(tools.begin(), tools.end(), [](const ToolBody& t) { return t.trocar; });
}

// What a state must not be saved with yet: each names itself.
Status check_saveable(const Simulation::Impl& im, const char* call) {
  const auto unsupported = [&](const std::string& what) {
    return Error(ErrorCode::bad_parameter,
                 std::string(call) + ": " + what + " is not part of a saved state yet, so this scene cannot be saved");
  };
  if (im.sutures) return unsupported("a needle (SceneDesc::needles)");
  return {};
}

}  // namespace

void Simulation::Impl::init_state_buffers(const CompiledScene& compiled) {
  const std::size_t float4s = compiled.positions.size() * 16;
  state_buffers = {{buffers.position, float4s, "positions"},
                   {buffers.previous, float4s, "previous positions"},
                   {buffers.velocity, float4s, "velocities"},
                   {buffers.contact_impulses, std::size_t{compiled.contact_impulse_slots} * 16, "contact impulses"}};
  if (buffers.external_force.valid()) state_buffers.push_back({buffers.external_force, float4s, "particle forces"});
  for (std::size_t k = 0; k < compiled.blocks.size(); ++k) {
    const ConstraintBlock& block = compiled.blocks[k];
    state_buffers.push_back({buffers.blocks[k].lambda, std::size_t{block.size()} * block.lambda_stride * 4, "multipliers"});
    state_buffers.push_back({buffers.blocks[k].residual, std::size_t{block.size()} * 4, "residuals"});
  }
  // A zero-sized buffer has nothing to carry (and a placeholder's size is not the scene's).
  std::erase_if(state_buffers, [](const StateBuffer& b) { return b.bytes == 0; });
  // The divergence checks' figures of the scene (sinew/divergence.h).
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const kernels::float4& p : compiled.positions) {
    if (p.w > 0.0f) history.movable_mass += 1.0 / double(p.w);
    const double x[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], x[k]), hi[k] = std::max(hi[k], x[k]);
  }
  if (!compiled.positions.empty())
    history.extent = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                               (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

std::vector<Simulation::Impl::StateBuffer> Simulation::Impl::saved_buffers() const {
  std::vector<StateBuffer> all = state_buffers;
  if (fluid) {  // the fluid's, asked for each time: its grid may have grown
    std::vector<std::pair<BufferHandle, std::size_t>> sized;
    fluid->solver->state_buffers(sized);
    for (const auto& [buffer, bytes] : sized) all.push_back({buffer, bytes, "fluid buffer"});
  }
  return all;
}

Status Simulation::Impl::save_state(SavedState& out, const char* call) {
  if (Status s = check_saveable(*this, call); !s) return s;
  const std::vector<StateBuffer> saved = saved_buffers();
  state_format::Writer w(out.bytes);
  w.begin();
  w.value(stats.frame);  // first: SavedState::frame() reads it
  w.value(shape_generation);
  const std::uint8_t flags[3] = {forces_for_next_frame, forces_on_device, stepper ? stepper->warm() : true};
  w.value(flags);
  w.value(history.last_energy);
  w.value(history.next_force_speed);
  w.value(stats.divergence.diverged_frames);
  w.value(static_cast<std::uint64_t>(saved.size()));
  for (const StateBuffer& b : saved)
    if (Status s = device->read_buffer(b.buffer, 0, w.reserve_array(b.bytes), b.bytes); !s) return s;
  w.array(std::span<const float>(colliders));
  w.array(std::span<const float>(targets));
  const std::uint8_t dirty[2] = {contacts.colliders_dirty, contacts.targets_dirty};
  w.value(dirty);
  w.value(static_cast<std::uint64_t>(contacts.tools.size()));
  for (const ToolBody& t : contacts.tools) tool_fields(t, [&](const auto& v) { w.value(v); });
  if (mesh_collision) {  // since version 2
    std::vector<float> velocities;
    mesh_collision->save_velocities(velocities);
    w.array(std::span<const float>(velocities));
  }
  if (fluid) {
    w.value(fluid->solver->host_state());
    w.array(std::span<const FluidEmitter>(fluid->solver->emitter_settings()));
  }
  if (graspers) {  // since version 3: each grasper's hold (open, or what it holds)
    w.value(static_cast<std::uint64_t>(graspers->count()));
    for (std::size_t g = 0; g < graspers->count(); ++g) {
      const GrasperHolds::Hold h = graspers->hold(g);
      std::vector<std::uint32_t> point_particles;
      std::vector<double> point_weights, offsets;
      for (const HeldPoint& p : h.points) {
        point_particles.insert(point_particles.end(), p.particles.begin(), p.particles.end());
        point_weights.insert(point_weights.end(), p.weights.begin(), p.weights.end());
      }
      for (const auto& o : h.offsets) offsets.insert(offsets.end(), o.begin(), o.end());
      w.value(static_cast<std::uint8_t>(h.closed));
      w.array(std::span<const std::uint32_t>(h.held));
      w.array(std::span<const std::uint32_t>(point_particles));
      w.array(std::span<const double>(point_weights));
      w.array(std::span<const double>(offsets));
    }
  }
  if (has_trocar(contacts.tools))  // since version 3: what each trocar pushed over the last frame (ToolState)
    for (const ToolBody& t : contacts.tools) {
      w.value(t.trocar_force);
      w.value(t.trocar_torque);
    }
  w.finish();
  return {};
}

Status Simulation::Impl::restore_state(const SavedState& state, const std::string& what) {
  std::span<const std::byte> payload;
  std::uint32_t version = 0;
  if (Status s = state_format::open(state.bytes, what, payload, &version); !s) return s;
  if (Status s = check_saveable(*this, what.c_str()); !s) return s;
  state_format::Reader r(payload, what);
  const std::vector<StateBuffer> saved = saved_buffers();
  // Read and checked whole before anything changes: a bad state leaves the Simulation as it was.
  std::uint64_t frame = 0, generation = 0, diverged = 0, buffer_count = 0, tools = 0;
  std::uint8_t flags[3] = {}, dirty[2] = {};
  double last_energy = 0.0, next_force_speed = 0.0;
  for (Status s : {r.value(frame), r.value(generation), r.value(flags), r.value(last_energy),
                   r.value(next_force_speed), r.value(diverged), r.value(buffer_count)})
    if (!s) return s;
  if (generation != shape_generation)
    return Error(ErrorCode::bad_parameter,
                 what + ": the state was saved after " + std::to_string(generation) +
                     " changes of the scene's shape (topology changes and level-set cuts), this Simulation has had " +
                     std::to_string(shape_generation) +
                     "; a saved state does not hold the topology, so it cannot be restored across such a change");
  if (buffer_count != saved.size()) return r.mismatch("device buffers", buffer_count, saved.size());
  std::vector<std::vector<std::byte>> contents(saved.size());
  for (std::size_t i = 0; i < saved.size(); ++i) {
    contents[i].resize(saved[i].bytes);
    if (Status s = r.array_into(contents[i].data(), saved[i].bytes, saved[i].name); !s) return s;
  }
  std::vector<float> saved_colliders, saved_targets;
  if (Status s = r.array(saved_colliders, colliders.size(), "colliders (floats)"); !s) return s;
  if (saved_colliders.size() != colliders.size())
    return r.mismatch("colliders (floats)", saved_colliders.size(), colliders.size());
  if (Status s = r.array(saved_targets, targets.size(), "targets (floats)"); !s) return s;
  if (saved_targets.size() != targets.size()) return r.mismatch("targets (floats)", saved_targets.size(), targets.size());
  if (Status s = r.value(dirty); !s) return s;
  if (Status s = r.value(tools); !s) return s;
  if (tools != contacts.tools.size()) return r.mismatch("tools", tools, contacts.tools.size());
  std::vector<ToolBody> saved_tools = contacts.tools;
  Status read_tools;
  for (ToolBody& t : saved_tools)
    tool_fields(t, [&](auto& v) {
      if (read_tools) read_tools = r.value(v);
    });
  if (!read_tools) return read_tools;
  // Version 1 did not save the mesh collision's velocities: its next frame
  // measures them from the device's, as a first frame does.
  std::vector<float> mesh_velocities;
  if (mesh_collision && version >= 2) {
    const std::size_t n = mesh_collision->particles() * 4;
    if (Status s = r.array(mesh_velocities, n, "mesh collision velocities (floats)"); !s) return s;
    if (!mesh_velocities.empty() && mesh_velocities.size() != n)
      return r.mismatch("mesh collision velocities (floats)", mesh_velocities.size(), n);
  }
  SphSolver::HostState fluid_host;
  std::vector<FluidEmitter> emitters;
  if (fluid) {
    if (Status s = r.value(fluid_host); !s) return s;
    const std::size_t n = fluid->solver->emitter_settings().size();
    if (Status s = r.array(emitters, n, "fluid emitters"); !s) return s;
    if (emitters.size() != n) return r.mismatch("fluid emitters", emitters.size(), n);
  }
  // Version 3 added the graspers' holds; an older state was saved with
  // every grasper open (closed ones could not be saved then).
  std::vector<GrasperHolds::Hold> holds(graspers ? graspers->count() : 0);
  if (graspers && version >= 3) {
    std::uint64_t count = 0;
    if (Status s = r.value(count); !s) return s;
    if (count != holds.size()) return r.mismatch("graspers", count, holds.size());
    const std::size_t particles = order.device_of.size();
    for (std::size_t g = 0; g < holds.size(); ++g) {
      GrasperHolds::Hold& h = holds[g];
      std::uint8_t closed = 0;
      std::vector<std::uint32_t> point_particles;
      std::vector<double> point_weights, offsets;
      for (Status s : {r.value(closed), r.array(h.held, particles, "held particles"),
                       r.array(point_particles, 3 * particles, "held points' particles"),
                       r.array(point_weights, 3 * particles, "held points' weights"),
                       r.array(offsets, 3 * (2 * particles), "held offsets")})
        if (!s) return s;
      if (point_particles.size() % 3 != 0 || point_weights.size() != point_particles.size() || offsets.size() % 3 != 0)
        return Error(ErrorCode::bad_input_file, what + ": grasper " + std::to_string(g) + "'s held points are malformed");
      h.closed = closed != 0;
      for (std::size_t i = 0; i < point_particles.size(); i += 3)
        h.points.push_back({{point_particles[i], point_particles[i + 1], point_particles[i + 2]},
                            {point_weights[i], point_weights[i + 1], point_weights[i + 2]}});
      for (std::size_t i = 0; i < offsets.size(); i += 3) h.offsets.push_back({offsets[i], offsets[i + 1], offsets[i + 2]});
      if (Status s = graspers->check(g, h, particles, what); !s) return s;
    }
  }
  // Version 3 added the trocars' push (reported in ToolState; an older
  // state restores it as zero, until the next frame measures it).
  for (ToolBody& t : saved_tools) t.trocar_force = t.trocar_torque = {0.0, 0.0, 0.0};
  if (has_trocar(saved_tools) && version >= 3)
    for (ToolBody& t : saved_tools)
      for (Status s : {r.value(t.trocar_force), r.value(t.trocar_torque)})
        if (!s) return s;
  if (!r.done()) return Error(ErrorCode::bad_input_file, what + ": the saved state has bytes past its end");

  for (std::size_t i = 0; i < saved.size(); ++i)
    if (Status s = device->write_buffer(saved[i].buffer, 0, contents[i].data(), contents[i].size()); !s) return s;
  if (fluid) {
    fluid->solver->set_host_state(fluid_host);
    fluid->solver->emitter_settings() = std::move(emitters);
  }
  colliders = std::move(saved_colliders);
  targets = std::move(saved_targets);
  if (!colliders.empty())
    if (Status s = device->write_buffer(buffers.colliders, 0, colliders.data(), colliders.size() * sizeof(float)); !s)
      return s;
  if (!targets.empty())
    if (Status s = device->write_buffer(buffers.targets, 0, targets.data(), targets.size() * sizeof(float)); !s)
      return s;
  contacts.colliders_dirty = dirty[0] != 0;
  contacts.targets_dirty = dirty[1] != 0;
  contacts.tools = std::move(saved_tools);
  forces_for_next_frame = flags[0] != 0;
  forces_on_device = flags[1] != 0;
  if (stepper) stepper->set_warm(flags[2] != 0);
  history.last_energy = last_energy;
  history.next_force_speed = next_force_speed;
  stats.divergence.diverged_frames = diverged;
  stats.frame = frame;
  stats.time = static_cast<double>(frame) * time_step;
  positions_mirror.changed();
  if (mesh_collision)
    if (Status s = mesh_collision->restore_velocities(std::move(mesh_velocities)); !s) return s;
  tears.clear();
  if (graspers) {  // what each grasper held when saved, and the program that solves it
    for (std::size_t g = 0; g < holds.size(); ++g)
      if (Status s = graspers->restore(*device, buffers, program_shape, order, g, holds[g]); !s) return s;
    if (Status s = rebuild_program(); !s) return s;
  }
  return {};
}

Status Simulation::save_state(SavedState& out) { return impl_->save_state(out, "save_state"); }

Status Simulation::restore_state(const SavedState& state) { return impl_->restore_state(state, "restore_state"); }

Status Simulation::save_state(const std::string& path) {
  SavedState state;
  if (Status s = impl_->save_state(state, "save_state"); !s) return s;
  return state.write_file(path);
}

Status Simulation::restore_state(const std::string& path) {
  auto state = SavedState::read_file(path);
  if (!state) return state.error();
  return impl_->restore_state(*state, path);
}

}  // namespace sinew
