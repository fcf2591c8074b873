// mouse_device.cpp — see mouse_device.h.
#include "view/mouse_device.h"

#include <algorithm>
#include <cmath>

namespace sinew::view {

bool MouseDevice::sample(std::int64_t now_ns, haptics::DeviceSample& out) noexcept {
  Goal goal;
  if (!channel_.try_read(goal)) return false;  // nothing placed yet: the loop keeps no sample
  if (goal.placed != placed_seen_) {
    handle_ = goal.position;
    velocity_ = {};
    placed_seen_ = goal.placed;
  } else {
    // x' = (goal - x) / tau, integrated exactly over the tick: the handle
    // never overshoots, however long the tick was.
    const double dt = std::max(0.0, static_cast<double>(now_ns - last_ns_) * 1e-9);
    const double keep = std::exp(-dt / tau_);
    for (int i = 0; i < 3; ++i) {
      handle_[i] = goal.position[i] + (handle_[i] - goal.position[i]) * keep;
      velocity_[i] = (goal.position[i] - handle_[i]) / tau_;
    }
  }
  last_ns_ = now_ns;
  out.sequence = ++sequence_;
  out.time_ns = now_ns;
  out.position = handle_;
  out.rotation = {1.0, 0.0, 0.0, 0.0};
  out.velocity = velocity_;
  out.angular_velocity = {};
  out.buttons = 0;
  return true;
}

void MouseDevice::command(const Vec3&, const Vec3&, std::int64_t) noexcept {
  // A mouse pushes nothing back; the force is shown by the viewer, which
  // reads it from the loop's feedback channel (CouplingFeedback::force).
}

void MouseDevice::move_to(const Vec3& position) {
  goal_.position = position;
  channel_.publish(goal_);
}

void MouseDevice::place(const Vec3& position) {
  goal_.position = position;
  ++goal_.placed;
  channel_.publish(goal_);
}

}  // namespace sinew::view
