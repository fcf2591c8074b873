// capi_drive.cpp — the C API's calls that drive a running scene
// (sinew/sinew.h): particle forces, colliders, targets, tools, graspers,
// cuts and needles, through the feature handles; and the events they and
// the frames made.
#include <span>
#include <string>

#include "capi/capi_internal.h"

namespace sinew::capi {
namespace {

// The arrays a call needs, each checked for NULL (named in the message).
sinew_status need_all(const char* call, std::initializer_list<std::pair<const void*, const char*>> pointers) {
  for (const auto& [p, name] : pointers)
    if (sinew_status s = need(p, call, name); s != SINEW_OK) return s;
  return SINEW_OK;
}

// An id from a handle's lookup, or its error.
template <class Id>
sinew_status id_of(Result<Id> id, Id& out) {
  if (!id) return fail(id.error());
  out = *id;
  return SINEW_OK;
}

// The shape of every call on one object of the scene: the handle and the
// caller's arrays checked, the object's id looked up (`lookup` returns a
// Result<Id>: an index past the scene's objects is its error), then `act`
// run on the id.
template <class Sim, class Lookup, class Act>
sinew_status on_object(const char* call, Sim* sim, std::initializer_list<std::pair<const void*, const char*>> pointers,
                       Lookup&& lookup, Act&& act) {
  return with_sim(call, sim, [&]() -> sinew_status {
    if (sinew_status s = need_all(call, pointers); s != SINEW_OK) return s;
    auto id = lookup();
    if (!id) return fail(id.error());
    return act(*id);
  });
}

// A C array from a std::array of the same length.
template <std::size_t N>
void put(double (&out)[N], const std::array<double, N>& in) {
  std::copy(in.begin(), in.end(), out);
}

// A grasper's close or open, as an event of the coming frame.
void grasp_event(sinew_simulation& sim, sinew_event_kind kind, std::uint32_t grasper, std::size_t particles) {
  sinew_event e{};
  e.kind = kind, e.object = grasper, e.frame = std::uint64_t(sim.frames_done) + 1;
  e.count = std::uint32_t(particles);
  sim.pending_events.push_back(e);
}

// A tool's or needle's pose and velocities into its C state.
template <class CState, class State>
void put_pose(CState& out, const State& in) {
  put(out.position, in.position);
  put(out.rotation, in.rotation);
  put(out.velocity, in.velocity);
  put(out.angular_velocity, in.angular_velocity);
}

}  // namespace
}  // namespace sinew::capi

using namespace sinew::capi;

extern "C" {

sinew_status sinew_set_particle_forces(sinew_simulation* sim, const float* xyz, size_t particles) {
  constexpr const char* call = "sinew_set_particle_forces";
  return with_sim(call, sim, [&]() -> sinew_status {
    if (sinew_status s = need(xyz, call, "xyz"); s != SINEW_OK) return s;
    return status_of(sim->sim->set_particle_forces(std::span<const float>(xyz, 3 * particles)));
  });
}

sinew_status sinew_set_collider_pose(sinew_simulation* sim, uint32_t collider, const double position[3],
                                     const double rotation[4]) {
  return on_object(
      "sinew_set_collider_pose", sim, {{position, "position"}, {rotation, "rotation"}},
      [&] { return sim->sim->tools().collider(collider); },
      [&](sinew::ColliderId id) { return status_of(sim->sim->tools().set_pose(id, vec3(position), quat(rotation))); });
}

sinew_status sinew_set_target_position(sinew_simulation* sim, uint32_t target, const double position[3]) {
  return on_object(
      "sinew_set_target_position", sim, {{position, "position"}}, [&] { return sim->sim->tools().target(target); },
      [&](sinew::TargetId id) { return status_of(sim->sim->tools().set_position(id, vec3(position))); });
}

sinew_status sinew_apply_tool_force(sinew_simulation* sim, uint32_t tool, const double force[3],
                                    const double torque[3]) {
  return on_object(
      "sinew_apply_tool_force", sim, {{force, "force"}, {torque, "torque"}},
      [&] { return sim->sim->tools().tool(tool); },
      [&](sinew::ToolId id) { return status_of(sim->sim->tools().apply_force(id, vec3(force), vec3(torque))); });
}

sinew_status sinew_get_tool_state(const sinew_simulation* sim, uint32_t tool, sinew_tool_state* state) {
  // The handles are views of a mutable Simulation; reading a state changes nothing.
  sinew::Simulation* s = sim ? &const_cast<sinew::Simulation&>(*sim->sim) : nullptr;
  return on_object(
      "sinew_get_tool_state", sim, {}, [&] { return s->tools().tool(tool); },
      [&](sinew::ToolId id) -> sinew_status {
        auto st = s->tools().state(id);
        if (!st) return fail(st.error());
        sinew_tool_state full{};
        full.penalty_points = st->penalty_points;
        full.penalty_depth = st->penalty_depth;
        put_pose(full, *st);
        put(full.contact_force, st->contact_force);
        put(full.contact_torque, st->contact_torque);
        put(full.penalty_force, st->penalty_force);
        put(full.penalty_torque, st->penalty_torque);
        return copy_sized("sinew_get_tool_state", full, state);
      });
}

sinew_status sinew_close_grasper(sinew_simulation* sim, uint32_t grasper, const double position[3],
                                 const double rotation[4], const double half_extents[3], size_t* held) {
  return on_object(
      "sinew_close_grasper", sim, {{position, "position"}, {rotation, "rotation"}, {half_extents, "half_extents"}},
      [&] { return sim->sim->graspers().grasper(grasper); },
      [&](sinew::GrasperId id) -> sinew_status {
        auto particles = sim->sim->graspers().close(id, {vec3(position), quat(rotation)}, vec3(half_extents));
        if (!particles) return fail(particles.error());
        if (held) *held = particles->size();
        grasp_event(*sim, SINEW_EVENT_GRASP, grasper, particles->size());
        return SINEW_OK;
      });
}

sinew_status sinew_move_grasper(sinew_simulation* sim, uint32_t grasper, const double position[3],
                                const double rotation[4]) {
  return on_object(
      "sinew_move_grasper", sim, {{position, "position"}, {rotation, "rotation"}},
      [&] { return sim->sim->graspers().grasper(grasper); },
      [&](sinew::GrasperId id) { return status_of(sim->sim->graspers().move(id, {vec3(position), quat(rotation)})); });
}

sinew_status sinew_open_grasper(sinew_simulation* sim, uint32_t grasper, size_t* released) {
  return on_object(
      "sinew_open_grasper", sim, {}, [&] { return sim->sim->graspers().grasper(grasper); },
      [&](sinew::GrasperId id) -> sinew_status {
        auto particles = sim->sim->graspers().open(id);
        if (!particles) return fail(particles.error());
        if (released) *released = particles->size();
        grasp_event(*sim, SINEW_EVENT_RELEASE, grasper, particles->size());
        return SINEW_OK;
      });
}

sinew_status sinew_cut(sinew_simulation* sim, sinew_body_kind kind, uint32_t body, const double from_a[3],
                       const double from_b[3], const double to_a[3], const double to_b[3], size_t* removed) {
  constexpr const char* call = "sinew_cut";
  return with_sim(call, sim, [&]() -> sinew_status {
    if (sinew_status s = need_all(call, {{from_a, "from_a"}, {from_b, "from_b"}, {to_a, "to_a"}, {to_b, "to_b"}});
        s != SINEW_OK)
      return s;
    const sinew::Blade from{vec3(from_a), vec3(from_b)}, to{vec3(to_a), vec3(to_b)};
    sinew::Topology topology = sim->sim->topology();
    sinew::Result<sinew::TopologyEvent> event = sinew::Error(sinew::ErrorCode::bad_parameter, "");
    if (kind == SINEW_BODY_TET) {
      sinew::TetBodyId id;
      if (sinew_status s = id_of(topology.tet_body(body), id); s != SINEW_OK) return s;
      event = topology.cut(id, from, to);
    } else if (kind == SINEW_BODY_TRI) {
      sinew::TriBodyId id;
      if (sinew_status s = id_of(topology.tri_body(body), id); s != SINEW_OK) return s;
      event = topology.cut(id, from, to);
    } else {
      return fail(SINEW_BAD_PARAMETER, std::string(call) + ": kind must be SINEW_BODY_TET or SINEW_BODY_TRI, got " +
                                           std::to_string(int(kind)));
    }
    if (!event) return fail(event.error());
    const sinew_event e = topology_event(SINEW_EVENT_CUT, *event, std::uint64_t(sim->frames_done) + 1);
    if (removed) *removed = e.count;
    sim->pending_events.push_back(e);
    return SINEW_OK;
  });
}

sinew_status sinew_set_needle_pose(sinew_simulation* sim, uint32_t needle, const double position[3],
                                   const double rotation[4]) {
  return on_object(
      "sinew_set_needle_pose", sim, {{position, "position"}, {rotation, "rotation"}},
      [&] { return sim->sim->needles().needle(needle); },
      [&](sinew::NeedleId id) { return status_of(sim->sim->needles().set_pose(id, vec3(position), quat(rotation))); });
}

sinew_status sinew_apply_needle_force(sinew_simulation* sim, uint32_t needle, const double force[3],
                                      const double torque[3]) {
  return on_object(
      "sinew_apply_needle_force", sim, {{force, "force"}, {torque, "torque"}},
      [&] { return sim->sim->needles().needle(needle); },
      [&](sinew::NeedleId id) { return status_of(sim->sim->needles().apply_force(id, vec3(force), vec3(torque))); });
}

sinew_status sinew_get_needle_state(const sinew_simulation* sim, uint32_t needle, sinew_needle_state* state) {
  sinew::Simulation* s = sim ? &const_cast<sinew::Simulation&>(*sim->sim) : nullptr;
  return on_object(
      "sinew_get_needle_state", sim, {}, [&] { return s->needles().needle(needle); },
      [&](sinew::NeedleId id) -> sinew_status {
        auto st = s->needles().state(id);
        if (!st) return fail(st.error());
        sinew_needle_state full{};
        full.punctures = std::uint32_t(st->punctures.size());
        full.pushing = st->pushing ? 1u : 0u;
        full.tip_force = st->tip_force;
        put_pose(full, *st);
        put(full.reaction_force, st->reaction_force);
        put(full.reaction_torque, st->reaction_torque);
        return copy_sized("sinew_get_needle_state", full, state);
      });
}

sinew_status sinew_read_events(const sinew_simulation* sim, sinew_event* events, size_t capacity, size_t event_size,
                               size_t* count) {
  constexpr const char* call = "sinew_read_events";
  return with_sim(call, sim, [&]() -> sinew_status {
    if (event_size < sizeof(std::uint32_t))
      return fail(SINEW_BAD_PARAMETER, std::string(call) + ": event_size is " + std::to_string(event_size) +
                                           " (pass sizeof(sinew_event))");
    const std::vector<sinew_event>& all = sim->last_events;
    if (sinew_status s = check_capacity(call, events, capacity, all.size(), count); s != SINEW_OK || !events)
      return s;
    // Records event_size apart, each with the fields that fit: a caller built
    // against a header with a longer or shorter record reads its own layout.
    unsigned char* out = reinterpret_cast<unsigned char*>(events);
    for (std::size_t i = 0; i < all.size(); ++i)
      std::memcpy(out + i * event_size, &all[i], std::min(event_size, sizeof(sinew_event)));
    return SINEW_OK;
  });
}

}  // extern "C"
