// src/haptics/tool_bridge.cpp — the physics thread's side: the tool's state
// out to the haptic loop after each frame, and minus the frame's mean
// coupling force into the tool before the next (sign convention in
// sinew/haptics/snapshot_channel.h).
#include "sinew/haptics/tool_bridge.h"

#include <cmath>
#include <string>

#include "math/vec3.h"

// The bridge reads a const Simulation's tool state through the index-based
// calls (deprecated for users; the Tools handle is a mutable view).
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"

namespace sinew::haptics {

Status HapticToolBridge::set_damping(double linear, double angular) {
  if (!(linear >= 0.0) || !std::isfinite(linear))
    return Error(ErrorCode::bad_parameter,
                 "tool damping must be finite and >= 0 [N s/m] (got " + std::to_string(linear) + ")");
  if (!(angular >= 0.0) || !std::isfinite(angular))
    return Error(ErrorCode::bad_parameter,
                 "tool angular damping must be finite and >= 0 [N m s/rad] (got " + std::to_string(angular) + ")");
  damping_ = linear;
  angular_damping_ = angular;
  return {};
}

Status HapticToolBridge::apply_feedback(Simulation& sim) {
  CouplingFeedback fb;
  force_ = {0.0, 0.0, 0.0};
  torque_ = {0.0, 0.0, 0.0};
  const bool got = feedback_.try_read(fb, 64);
  // A reading from another loop than the previous one (a HapticLoop
  // recreated on the same channel) starts over as a first reading: the two
  // impulse integrals have different origins.
  const bool same_loop = have_prev_ && fb.loop == prev_.loop;
  if (got && same_loop && fb.time_ns > prev_.time_ns) {
    // Mean device force over the interval between the two readings (exact:
    // the impulse integral is a zero-order hold of every tick's output).
    const double dt = ns_to_seconds(fb.time_ns - prev_.time_ns);
    force_ = math::mul(math::sub(fb.impulse, prev_.impulse), -1.0 / dt);
    torque_ = math::mul(math::sub(fb.angular_impulse, prev_.angular_impulse), -1.0 / dt);
  } else if (got && !same_loop) {
    // First reading (of this loop): the newest tick's output (no interval to average over yet).
    force_ = math::mul(fb.force, -1.0);
    torque_ = math::mul(fb.torque, -1.0);
  } else {
    ++missing_;  // no tick since the previous frame: the tool gets nothing
  }
  if (got) {
    prev_ = fb;
    have_prev_ = true;
  }
  if (!math::finite(force_) || !math::finite(torque_)) {  // cannot happen with the safety chain; never pass it on
    force_ = torque_ = {0.0, 0.0, 0.0};
  }
  Vec3 f = force_, t = torque_;
  if (damping_ > 0.0 || angular_damping_ > 0.0) {
    auto state = sim.tool_state(tool_);
    if (!state) return state.error();
    f = math::sub(f, math::mul(state->velocity, damping_));
    t = math::sub(t, math::mul(state->angular_velocity, angular_damping_));
  }
  return sim.apply_tool_force(tool_, f, t);
}

Status HapticToolBridge::set_local_contacts(LocalContactBuilder builder) {
  if (builder.tool() != tool_)
    return Error(ErrorCode::bad_parameter, "local contacts built for tool " + std::to_string(builder.tool()) +
                                               " given to the bridge of tool " + std::to_string(tool_));
  builder_ = std::move(builder);
  return {};
}

Status HapticToolBridge::publish(const Simulation& sim) {
  auto state = sim.tool_state(tool_);
  if (!state) return state.error();
  HapticSnapshot s;
  s.sequence = ++sequence_;
  s.stamp_ns = clock_.now_ns();
  s.sim_time = sim.last_frame().time;
  s.frame = sim.last_frame().frame;
  s.position = state->position;
  s.rotation = state->rotation;
  s.velocity = state->velocity;
  s.angular_velocity = state->angular_velocity;
  s.contact_force = state->contact_force;
  s.contact_torque = state->contact_torque;
  const double f = math::norm(s.contact_force);
  s.in_contact = f > 0.0 ? 1u : 0u;
  s.contact_normal = f > 0.0 ? math::mul(s.contact_force, 1.0 / f) : Vec3{0.0, 0.0, 0.0};
  if (builder_) {
    if (auto r = sim.read_positions(positions_); !r) return r;
    s.local_contacts = builder_->build(positions_, *state);
  }
  last_model_ = s.local_contacts;
  snapshots_.publish(s);
  return {};
}

}  // namespace sinew::haptics
