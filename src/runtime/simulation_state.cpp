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
// counts, the graspers' holds (the particles and points in their slots,
// written again with the program rebuilt), the needles' state (their rows
// are written to the device before every frame) and the level-set
// colliders' values; all are restored exactly (and the mesh collision and
// the needles read the positions again). The scene's constant data
// (constraint slots, colours, masses) is the compiled scene's changed by
// the topology log, which a restore replays where this Simulation's log is
// the first part of the state's (topology_log.h), or replays whole in a
// Simulation made again (SimulationInternals::restore). The continuous
// collision carries nothing between frames: it fits its trees and takes
// its reference positions at every frame's start.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "fluid/sph_solver.h"
#include "level_set/level_set_values.h"
#include "runtime/simulation_internals.h"
#include "runtime/simulation_impl.h"
#include "runtime/state_format.h"
#include "runtime/tool_fields.h"

namespace sinew {
namespace {

bool has_trocar(const std::vector<ToolBody>& tools) {
  return std::any_of(tools.begin(), tools.end(), [](const ToolBody& t) { return t.trocar; });
}

// The level-set colliders a cut can change (LevelSet::cut needs the whole
// inside stored): their values are part of the state.
std::vector<std::size_t> cuttable_level_sets(const ContactState& c) {
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < c.shapes.size(); ++k)
    if (c.shapes[k].shape == ColliderShape::level_set && c.shapes[k].level_set &&
        std::isinf(c.shapes[k].level_set->interior_band()))
      out.push_back(k);
  return out;
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

Status Simulation::Impl::save_state(SavedState& out) {
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
  // Since version 4: the topology changes made, in order, and the cautery's
  // heat; the needles; the values of the level sets a cut can change.
  if (topology) {
    write_log(w, topology_log);
    for (BodyKind kind : {BodyKind::tet, BodyKind::tri})
      for (std::size_t b = 0; b < topology->bodies(kind); ++b)
        w.array(std::span<const double>(topology->heat(kind, b)));
  }
  if (sutures) sutures->save(w);
  for (std::size_t k : cuttable_level_sets(contacts)) w.array(contacts.shapes[k].level_set->nanovdb_bytes());
  w.finish();
  return {};
}

Status Simulation::Impl::restore_state(const SavedState& state, const std::string& what, bool* rebuild) {
  std::span<const std::byte> payload;
  std::uint32_t version = 0;
  if (Status s = state_format::open(state.bytes, what, payload, &version); !s) return s;
  state_format::Reader r(payload, what);
  const std::vector<StateBuffer> saved = saved_buffers();
  // Read and checked whole before anything changes: a bad state leaves the Simulation as it was.
  std::uint64_t frame = 0, generation = 0, diverged = 0, buffer_count = 0, tools = 0;
  std::uint8_t flags[3] = {}, dirty[2] = {};
  double last_energy = 0.0, next_force_speed = 0.0;
  for (Status s : {r.value(frame), r.value(generation), r.value(flags), r.value(last_energy),
                   r.value(next_force_speed), r.value(diverged), r.value(buffer_count)})
    if (!s) return s;
  if (version < 4 && generation != 0)
    return Error(ErrorCode::bad_parameter,
                 what + ": the state was saved after " + std::to_string(generation) +
                     " changes of the scene's shape (topology changes and level-set cuts) in format version " +
                     std::to_string(version) + ", which does not hold the topology; it cannot be restored");
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
  // Version 4 added the topology log and the cautery's heat, the needles
  // and the level sets' values; an older state holds none (it was saved
  // with no topology change, no needle, and restores no level set).
  TopologyLog saved_log;
  std::vector<std::vector<double>> heat;
  std::vector<Sutures::Needle> needles;
  std::vector<std::vector<std::byte>> grids;
  if (sutures && version < 4)
    return Error(ErrorCode::bad_parameter, what + ": the saved state (format version " + std::to_string(version) +
                                               ") holds no needles' state; this scene has needles");
  if (version >= 4) {
    if (topology) {
      if (Status s = read_log(r, topology.get(), what, saved_log); !s) return s;
      for (BodyKind kind : {BodyKind::tet, BodyKind::tri})
        for (std::size_t b = 0; b < topology->bodies(kind); ++b) {
          const std::size_t n = topology->heat(kind, b).size();
          if (Status s = r.array(heat.emplace_back(), n, "cautery heat (elements)"); !s) return s;
          if (heat.back().size() != n) return r.mismatch("cautery heat (elements)", heat.back().size(), n);
        }
    }
    if (sutures)
      if (Status s = sutures->read(r, what, needles); !s) return s;
    for (std::size_t k : cuttable_level_sets(contacts)) {
      const std::size_t n = contacts.shapes[k].level_set->nanovdb_bytes().size();
      if (Status s = r.array(grids.emplace_back(), n, "level set (bytes)"); !s) return s;
      if (grids.back().size() != n) return r.mismatch("level set (bytes)", grids.back().size(), n);
    }
  }
  if (!r.done()) return Error(ErrorCode::bad_input_file, what + ": the saved state has bytes past its end");
  // The topology: the state's log must continue this Simulation's.
  if (!is_prefix(topology_log, saved_log)) {
    if (rebuild) *rebuild = true;
    return Error(ErrorCode::bad_parameter,
                 what + ": the state was saved after " + std::to_string(saved_log.size()) +
                     " topology changes that do not continue this Simulation's " +
                     std::to_string(topology_log.size()) +
                     "; only a Simulation made again from the SceneDesc can take it");
  }

  // The level sets first: a layout that is not this scene's is found before anything changes.
  const std::vector<std::size_t> level_sets = cuttable_level_sets(contacts);
  for (std::size_t i = 0; i < grids.size(); ++i) {
    std::vector<std::array<std::uint64_t, 2>> changed;
    const std::size_t k = level_sets[i];
    if (Status s = set_level_set_values(*contacts.shapes[k].level_set, grids[i], what, changed); !s) return s;
    const std::span<const std::byte> bytes = contacts.shapes[k].level_set->nanovdb_bytes();
    for (const auto& [offset, size] : changed)
      if (Status s = device->write_buffer(buffers.level_set_grids, contacts.level_set_offsets[k] + offset,
                                          bytes.data() + offset, size);
          !s)
        return s;
  }
  // The changes this Simulation has not made yet, in the order they were made.
  const bool replay = saved_log.size() > topology_log.size();
  replaying = true;
  for (std::size_t i = topology_log.size(); i < saved_log.size(); ++i)
    if (auto event = edit(saved_log[i], std::chrono::steady_clock::now()); !event) {
      replaying = false;
      return event.error();
    }
  replaying = false;
  if (replay)  // the program of the last shape (finish_change rebuilds none while replaying)
    if (Status s = rebuild_program(); !s) return s;

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
  if (!heat.empty()) {
    std::size_t i = 0;
    for (BodyKind kind : {BodyKind::tet, BodyKind::tri})
      for (std::size_t b = 0; b < topology->bodies(kind); ++b) topology->heat(kind, b) = std::move(heat[i++]);
  }
  if (sutures) sutures->restore_needles(std::move(needles));
  shape_generation = generation;
  if (graspers) {  // what each grasper held when saved, and the program that solves it
    for (std::size_t g = 0; g < holds.size(); ++g)
      if (Status s = graspers->restore(*device, buffers, program_shape, order, g, holds[g]); !s) return s;
    if (Status s = rebuild_program(); !s) return s;
  }
  // After a replay the restored state is the one to roll back to.
  if (replay && divergence.on_divergence == OnDivergence::roll_back && &state != &last_good) last_good = state;
  return {};
}

Status SimulationInternals::restore(Simulation& sim, const SavedState& state, const std::string& what) {
  Simulation::Impl& old = *sim.impl_;
  bool rebuild = false;
  const Status restored = old.restore_state(state, what, &rebuild);
  if (!rebuild) return restored;
  if (!old.source_scene || !old.device_options)
    return Error(restored.error().code(), restored.error().message() +
                                              " (this one was made on a device given to it, which cannot be made again)");
  // Made again as Simulation::create makes it, with this one's ids and
  // settings; it takes this one's place only once the state is in it.
  auto compiled = compile_scene(*old.source_scene);
  if (!compiled) return compiled.error();
  auto device = create_device(*old.device_options);
  if (!device) return device.error();
  auto made = assemble(*old.source_scene, *compiled, std::move(*device));
  if (!made) return made.error();
  Simulation::Impl& im = *made->impl_;
  im.serial = old.serial;
  im.source_scene = old.source_scene;
  im.device_options = old.device_options;
  im.warnings = old.warnings;
  im.divergence = old.divergence;
  if (Status s = im.restore_state(state, what); !s) return s;
  if (im.divergence.on_divergence == OnDivergence::roll_back) im.last_good = state;
  sim.impl_ = std::move(made->impl_);
  return {};
}

Status Simulation::save_state(SavedState& out) { return impl_->save_state(out); }

Status Simulation::restore_state(const SavedState& state) {
  return SimulationInternals::restore(*this, state, "restore_state");
}

Status Simulation::save_state(const std::string& path) {
  SavedState state;
  if (Status s = impl_->save_state(state); !s) return s;
  return state.write_file(path);
}

Status Simulation::restore_state(const std::string& path) {
  auto state = SavedState::read_file(path);
  if (!state) return state.error();
  return SimulationInternals::restore(*this, *state, path);
}

}  // namespace sinew
