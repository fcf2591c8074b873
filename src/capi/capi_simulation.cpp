// capi_simulation.cpp — the C API's simulations (sinew/sinew.h): made from
// a scene file or JSON text, stepped with their script, described, and
// read back (positions, velocities, surface triangles, the frame's figures).
#include <memory>
#include <string>

#include "capi/capi_internal.h"
#include "sinew/mesh.h"

namespace sinew::capi {
namespace {

// The simulation of a scene file read (or the reading's error).
sinew_status create(const char* call, Result<SceneFile> file, const char* backend, int threads,
                    sinew_simulation** out) {
  if (!file) return fail(file.error());
  if (threads < 0)
    return fail(SINEW_BAD_PARAMETER, std::string(call) + ": threads must be >= 0 (0: all hardware threads), got " +
                                         std::to_string(threads));
  auto handle = std::make_unique<sinew_simulation>();
  handle->file = std::move(*file);
  // No backend named: the file's, as `sinew run` without --backend.
  const std::string name = backend && *backend ? backend : handle->file.run.backend;
  auto sim = Simulation::create(handle->file.scene, {.backend = name, .threads = threads, .quiet = true});
  if (!sim) return fail(sim.error());
  handle->sim.emplace(std::move(*sim));
  handle->player.emplace(handle->file.script);
  if (!handle->file.hands.empty()) {
    auto hands = sinew::haptics::ScriptedHands::create(handle->file.hands, *handle->sim, handle->file.scene.solver.time_step);
    if (!hands) return fail(hands.error());
    handle->hands = std::move(*hands);
  }
  handle->punctures.resize(handle->sim->needles().count());
  // Without topology changes a tet body's surface is its whole mesh's, for good.
  if (!handle->file.scene.topology_changes)
    for (const TetBodyDesc& body : handle->file.scene.tet_bodies)
      handle->fixed_tet_surfaces.push_back(extract_boundary_surface(body.mesh).triangles);
  *out = handle.release();
  return SINEW_OK;
}

// Every body's surface triangles now, in its own vertex numbering: the tet
// bodies' boundaries, then the tri bodies' triangles.
Result<std::vector<std::vector<std::array<std::uint32_t, 3>>>> surfaces(sinew_simulation& h) {
  std::vector<std::vector<std::array<std::uint32_t, 3>>> out;
  const SceneDesc& scene = h.file.scene;
  Topology topology = h.sim->topology();
  for (std::size_t b = 0; b < scene.tet_bodies.size(); ++b) {
    if (!scene.topology_changes) {
      out.push_back(h.fixed_tet_surfaces[b]);
      continue;
    }
    auto id = topology.tet_body(b);
    if (!id) return id.error();
    auto tets = topology.current_tets(*id);
    if (!tets) return tets.error();
    TetMesh live;
    live.vertices = scene.tet_bodies[b].mesh.vertices;
    live.tets = std::move(*tets);
    out.push_back(extract_boundary_surface(live).triangles);
  }
  for (std::size_t b = 0; b < scene.tri_bodies.size(); ++b) {
    if (!scene.topology_changes) {
      out.push_back(scene.tri_bodies[b].mesh.triangles);
      continue;
    }
    auto id = topology.tri_body(b);
    if (!id) return id.error();
    auto triangles = topology.current_triangles(*id);
    if (!triangles) return triangles.error();
    out.push_back(std::move(*triangles));
  }
  return out;
}

// Body `body` of the C numbering (tet, then tri, then line bodies): its kind, index and particles.
struct BodyRange {
  BodyKind kind;
  std::uint32_t index, first, count;
};
std::optional<BodyRange> body_range(const sinew_simulation& h, std::uint32_t body) {
  const SceneDesc& scene = h.file.scene;
  const SceneInfo& info = h.sim->info();
  std::size_t b = body;
  if (b < scene.tet_bodies.size())
    return BodyRange{BodyKind::tet, std::uint32_t(b), info.tet_body_first_particle[b],
                     std::uint32_t(scene.tet_bodies[b].mesh.vertices.size())};
  b -= scene.tet_bodies.size();
  if (b < scene.tri_bodies.size())
    return BodyRange{BodyKind::tri, std::uint32_t(b), info.tri_body_first_particle[b],
                     std::uint32_t(scene.tri_bodies[b].mesh.vertices.size())};
  b -= scene.tri_bodies.size();
  if (b < scene.line_bodies.size())
    return BodyRange{BodyKind::line, std::uint32_t(b), info.line_body_first_particle[b],
                     std::uint32_t(scene.line_bodies[b].vertices.size())};
  return std::nullopt;
}

std::size_t body_count(const SceneDesc& scene) {
  return scene.tet_bodies.size() + scene.tri_bodies.size() + scene.line_bodies.size();
}

// The positions' or velocities' read-back into the caller's buffer.
sinew_status read_xyzw(const char* call, sinew_simulation* h, bool velocities, float* xyzw, std::size_t capacity,
                       std::size_t* count) {
  const std::size_t particles = h->sim->info().particles;
  if (sinew_status s = check_capacity(call, xyzw, capacity, particles, count); s != SINEW_OK || !xyzw) return s;
  const Status read = velocities ? h->sim->read_velocities(h->scratch) : h->sim->read_positions(h->scratch);
  if (!read) return fail(read.error());
  std::copy(h->scratch.begin(), h->scratch.begin() + 4 * particles, xyzw);
  return SINEW_OK;
}

// The events of the step just made: tears, then punctures made and ended.
void step_events(sinew_simulation& h, std::uint64_t frame, std::vector<sinew_event>& out) {
  for (const TopologyEvent& e : h.sim->topology().last_tears()) out.push_back(topology_event(SINEW_EVENT_TEAR, e, frame));
  Needles needles = h.sim->needles();
  for (std::uint32_t n = 0; n < h.punctures.size(); ++n) {
    auto id = needles.needle(n);
    if (!id) continue;
    auto state = needles.state(*id);
    if (!state) continue;
    std::vector<Puncture>& before = h.punctures[n];
    std::vector<bool> kept(before.size(), false);
    auto record = [&](sinew_event_kind kind, const Puncture& p) {
      sinew_event e{};
      e.kind = kind, e.object = n, e.body_kind = std::uint32_t(p.body_kind), e.body = p.body, e.frame = frame;
      e.triangle = p.triangle, e.exit = p.exit ? 1u : 0u;
      for (int c = 0; c < 3; ++c) e.weights[c] = p.weights[c];
      out.push_back(e);
    };
    // A puncture is the same one when its body, triangle, side and point are.
    auto same = [](const Puncture& a, const Puncture& b) {
      return a.body_kind == b.body_kind && a.body == b.body && a.triangle == b.triangle && a.exit == b.exit &&
             a.weights == b.weights;
    };
    for (const Puncture& p : state->punctures) {
      bool found = false;
      for (std::size_t k = 0; k < before.size() && !found; ++k)
        if (!kept[k] && same(before[k], p)) kept[k] = found = true;
      if (!found) record(SINEW_EVENT_PUNCTURE, p);
    }
    for (std::size_t k = 0; k < before.size(); ++k)
      if (!kept[k]) record(SINEW_EVENT_PUNCTURE_END, before[k]);
    before = std::move(state->punctures);
  }
}

sinew_event action_event(const ScriptEvent& r, std::uint64_t frame) {
  switch (r.kind) {
    case ScriptActionKind::cut: return topology_event(SINEW_EVENT_CUT, r.topology, frame);
    case ScriptActionKind::cauterize: return topology_event(SINEW_EVENT_CAUTERY, r.topology, frame);
    case ScriptActionKind::remove: return topology_event(SINEW_EVENT_REMOVAL, r.topology, frame);
    default: break;
  }
  sinew_event e{};
  e.object = r.index, e.frame = frame;
  if (r.kind == ScriptActionKind::close_grasper || r.kind == ScriptActionKind::open_grasper) {
    e.kind = r.kind == ScriptActionKind::close_grasper ? SINEW_EVENT_GRASP : SINEW_EVENT_RELEASE;
    e.count = static_cast<std::uint32_t>(r.particles.size());
  } else if (r.kind == ScriptActionKind::cut_collider) {
    e.kind = SINEW_EVENT_COLLIDER_CUT;
    e.volume_removed = r.collider_cut.removed_volume;
  }
  return e;
}

}  // namespace
}  // namespace sinew::capi

using namespace sinew::capi;

extern "C" {

sinew_status sinew_create_from_file(const char* path, const char* backend, int threads, sinew_simulation** out) {
  constexpr const char* call = "sinew_create_from_file";
  return guarded(call, [&]() -> sinew_status {
    if (sinew_status s = need(out, call, "out"); s != SINEW_OK) return s;
    *out = nullptr;
    if (sinew_status s = need(path, call, "path"); s != SINEW_OK) return s;
    return create(call, sinew::load_scene_file(path), backend, threads, out);
  });
}

sinew_status sinew_create_from_json(const char* json, const char* base_dir, const char* backend, int threads,
                                    sinew_simulation** out) {
  constexpr const char* call = "sinew_create_from_json";
  return guarded(call, [&]() -> sinew_status {
    if (sinew_status s = need(out, call, "out"); s != SINEW_OK) return s;
    *out = nullptr;
    if (sinew_status s = need(json, call, "json"); s != SINEW_OK) return s;
    return create(call, sinew::parse_scene_json(json, base_dir ? base_dir : ""), backend, threads, out);
  });
}

sinew_status sinew_destroy(sinew_simulation* sim) {
  return guarded("sinew_destroy", [&]() -> sinew_status {
    delete sim;
    return SINEW_OK;
  });
}

sinew_status sinew_get_scene_info(const sinew_simulation* sim, sinew_scene_info* info) {
  return with_sim("sinew_get_scene_info", sim, [&]() -> sinew_status {
    const sinew::SceneDesc& scene = sim->file.scene;
    sinew_scene_info full{};
    full.particles = sim->sim->info().particles;
    full.tet_bodies = std::uint32_t(scene.tet_bodies.size());
    full.tri_bodies = std::uint32_t(scene.tri_bodies.size());
    full.line_bodies = std::uint32_t(scene.line_bodies.size());
    full.tools = std::uint32_t(scene.tools.size());
    full.colliders = std::uint32_t(scene.colliders.size());
    full.targets = std::uint32_t(scene.targets.size());
    full.graspers = std::uint32_t(scene.graspers.size());
    full.needles = std::uint32_t(scene.needles.size());
    full.constraints = sim->sim->info().constraints();
    full.script_frames = std::uint32_t(sim->file.run.frames);
    return copy_sized("sinew_get_scene_info", full, info);
  });
}

sinew_status sinew_get_backend_name(const sinew_simulation* sim, char* name, size_t capacity, size_t* count) {
  constexpr const char* call = "sinew_get_backend_name";
  return with_sim(call, sim, [&]() -> sinew_status {
    const std::string backend = sim->sim->backend_name();
    size_t needed = backend.size() + 1;
    size_t ignored = 0;
    if (sinew_status s = check_capacity(call, name, capacity, needed, count ? count : &ignored);
        s != SINEW_OK || !name)
      return s;
    std::memcpy(name, backend.c_str(), needed);
    return SINEW_OK;
  });
}

sinew_status sinew_get_body_info(sinew_simulation* sim, uint32_t body, sinew_body_info* info) {
  constexpr const char* call = "sinew_get_body_info";
  return with_sim(call, sim, [&]() -> sinew_status {
    const auto range = body_range(*sim, body);
    if (!range)
      return fail(SINEW_BAD_PARAMETER, std::string(call) + ": body " + std::to_string(body) +
                                           " does not exist (the scene has " +
                                           std::to_string(body_count(sim->file.scene)) + ")");
    auto all = surfaces(*sim);
    if (!all) return fail(all.error());
    sinew_body_info full{};
    full.kind = std::uint32_t(range->kind);
    full.index = range->index;
    full.first_particle = range->first;
    full.particle_count = range->count;
    // Surfaces are numbered over the tet and tri bodies; a thread's starts where theirs end.
    const std::size_t surfaced = std::min<std::size_t>(body, all->size());
    for (std::size_t b = 0; b < surfaced; ++b) full.first_triangle += std::uint32_t((*all)[b].size());
    full.triangle_count = body < all->size() ? std::uint32_t((*all)[body].size()) : 0;
    return copy_sized(call, full, info);
  });
}

sinew_status sinew_step(sinew_simulation* sim) {
  return with_sim("sinew_step", sim, [&]() -> sinew_status {
    const std::uint64_t frame = std::uint64_t(sim->frames_done) + 1;
    if (sim->play_script) {
      std::vector<sinew::ScriptEvent> done;
      const sinew::Status played = sim->player->before_frame(*sim->sim, sim->frames_done + 1, done);
      // Emitters and sinks changed make no event (kind 0): the C API has none for them.
      for (const sinew::ScriptEvent& r : done)
        if (const sinew_event e = action_event(r, frame); e.kind != 0) sim->pending_events.push_back(e);
      if (!played) return fail(played.error());
      if (sim->hands)
        if (const sinew::Status s = sim->hands->before_step(*sim->sim); !s) return fail(s.error());
    }
    ++sim->frames_done;
    const sinew::Status stepped = sim->sim->step();
    if (stepped && sim->play_script && sim->hands)
      if (const sinew::Status s = sim->hands->after_step(*sim->sim); !s) return fail(s.error());
    sim->last_events = std::move(sim->pending_events);
    sim->pending_events.clear();
    step_events(*sim, frame, sim->last_events);
    return status_of(stepped);
  });
}

sinew_status sinew_set_script_playing(sinew_simulation* sim, int playing) {
  return with_sim("sinew_set_script_playing", sim, [&]() -> sinew_status {
    sim->play_script = playing != 0;
    return SINEW_OK;
  });
}

sinew_status sinew_get_frame_stats(const sinew_simulation* sim, sinew_frame_stats* stats) {
  return with_sim("sinew_get_frame_stats", sim, [&]() -> sinew_status {
    const sinew::FrameStats& st = sim->sim->last_frame();
    sinew_frame_stats full{};
    full.stop = std::uint32_t(st.stop);
    full.frame = st.frame;
    full.time = st.time;
    full.wall_ms = st.wall_ms;
    full.measure_ms = st.measure_ms;
    full.residual_rms = st.residual_rms;
    full.max_residual = st.max_residual;
    full.kinetic_energy = st.kinetic_energy;
    full.volume_change = st.volume_change;
    full.checked_residual = st.checked_residual;
    full.sweeps = st.sweeps;
    full.read_back_bytes = st.read_back_bytes;
    full.inverted_tets = st.inverted_tets;
    full.position_reads = st.position_reads;
    full.host_reads = st.host_reads;
    full.host_waits = st.host_waits;
    full.residual_checks = st.residual_checks;
    full.contacts = st.mesh_contacts;
    full.contact_colors = st.mesh_contact_colors;
    full.ccd_hits = st.ccd_hits;
    full.ccd_repairs = st.ccd_repairs;
    full.ccd_reverted = st.ccd_reverted;
    full.ccd_carried = st.ccd_carried;
    full.ccd_forced = st.ccd_forced;
    full.collision_margin = st.collision_margin;
    full.collision_ms = st.collision_ms;
    full.contact_violation = st.contact_violation;
    full.ccd_ms = st.ccd_ms;
    full.suture_ms = st.suture_ms;
    full.device_ms = st.device.span_ms;
    full.device_timed = st.device.timed ? 1u : 0u;
    full.divergence = std::uint32_t(st.divergence.kind);
    full.diverged_frames = st.divergence.diverged_frames;
    return copy_sized("sinew_get_frame_stats", full, stats);
  });
}

sinew_status sinew_get_stage_ms(const sinew_simulation* sim, const char* stage, double* ms) {
  constexpr const char* call = "sinew_get_stage_ms";
  return with_sim(call, sim, [&]() -> sinew_status {
    if (sinew_status s = need(stage, call, "stage"); s != SINEW_OK) return s;
    if (sinew_status s = need(ms, call, "ms"); s != SINEW_OK) return s;
    *ms = sim->sim->last_frame().stage_ms(stage);
    return SINEW_OK;
  });
}

sinew_status sinew_get_stage_counter(const sinew_simulation* sim, const char* stage, const char* counter,
                                     double* value) {
  constexpr const char* call = "sinew_get_stage_counter";
  return with_sim(call, sim, [&]() -> sinew_status {
    if (sinew_status s = need(stage, call, "stage"); s != SINEW_OK) return s;
    if (sinew_status s = need(counter, call, "counter"); s != SINEW_OK) return s;
    if (sinew_status s = need(value, call, "value"); s != SINEW_OK) return s;
    *value = sim->sim->last_frame().counter(stage, counter);
    return SINEW_OK;
  });
}

sinew_status sinew_read_positions(sinew_simulation* sim, float* xyzw, size_t capacity, size_t* count) {
  return with_sim("sinew_read_positions", sim,
                  [&] { return read_xyzw("sinew_read_positions", sim, false, xyzw, capacity, count); });
}

sinew_status sinew_read_velocities(sinew_simulation* sim, float* xyzw, size_t capacity, size_t* count) {
  return with_sim("sinew_read_velocities", sim,
                  [&] { return read_xyzw("sinew_read_velocities", sim, true, xyzw, capacity, count); });
}

sinew_status sinew_read_surface_triangles(sinew_simulation* sim, uint32_t* indices, size_t capacity, size_t* count) {
  constexpr const char* call = "sinew_read_surface_triangles";
  return with_sim(call, sim, [&]() -> sinew_status {
    auto all = surfaces(*sim);
    if (!all) return fail(all.error());
    std::size_t triangles = 0;
    for (const auto& body : *all) triangles += body.size();
    if (sinew_status s = check_capacity(call, indices, capacity, triangles, count); s != SINEW_OK || !indices)
      return s;
    // Each body's own vertex numbers become particle indices.
    std::size_t at = 0;
    for (std::uint32_t b = 0; b < all->size(); ++b) {
      const std::uint32_t first = body_range(*sim, b)->first;
      for (const auto& t : (*all)[b])
        for (std::uint32_t v : t) indices[at++] = first + v;
    }
    return SINEW_OK;
  });
}

}  // extern "C"
