// src/haptics/passivity_observer.cpp — the time-domain passivity observer of
// Hannaford and Ryu, "Time-domain passivity control of haptic interfaces",
// IEEE Trans. Robotics and Automation 18(1), 2002, for force and torque,
// with a sliding window of its energy for reporting (criterion and what it
// sees: sinew/haptics/passivity_observer.h).
#include "sinew/haptics/passivity_observer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "math/vec3.h"

namespace sinew::haptics {

Status check(const PassivityParams& p) {
  if (p.window < 1 || p.window > kMaxPassivityWindow)
    return Error(ErrorCode::bad_parameter, "passivity.window must be in 1.." + std::to_string(kMaxPassivityWindow) +
                                               " ticks (got " + std::to_string(p.window) + ")");
  if (!(p.tolerance >= 0.0) || !std::isfinite(p.tolerance))
    return Error(ErrorCode::bad_parameter,
                 "passivity.tolerance must be finite and >= 0 [J] (got " + std::to_string(p.tolerance) + ")");
  return {};
}

PassivityObserver::PassivityObserver(const PassivityParams& params) : p_(params), ring_(params.window, 0.0) {}

void PassivityObserver::reset() noexcept {
  std::fill(ring_.begin(), ring_.end(), 0.0);
  n_ = 0;
  have_prev_ = false;
  prev_position_ = prev_force_ = prev_torque_ = {0.0, 0.0, 0.0};
  prev_rotation_ = {1.0, 0.0, 0.0, 0.0};
  energy_ = min_window_ = 0.0;
  violations_ = 0;
}

PassivityReading PassivityObserver::observe(const Vec3& position, const Quat& rotation, const Vec3& force,
                                            const Vec3& torque) noexcept {
  if (have_prev_) {
    // Work done by the hand against the held force and torque over the interval.
    const Vec3 dx = math::sub(position, prev_position_);
    const Vec3 dtheta = math::rotation_vector(math::qmul(rotation, math::conj(prev_rotation_)));
    const double work = -(math::dot(prev_force_, dx) + math::dot(prev_torque_, dtheta));
    // A non-finite pose or force (the safety chain zeroes a non-finite
    // force; a device may still report a NaN pose) adds nothing: the
    // observer must not turn NaN and stay so.
    if (std::isfinite(work)) energy_ += work;
  }
  have_prev_ = true;
  prev_position_ = position;
  prev_rotation_ = rotation;
  prev_force_ = force;
  prev_torque_ = torque;

  double& slot = ring_[static_cast<std::size_t>(n_ % ring_.size())];
  PassivityReading r;
  r.energy = energy_;
  r.window_energy = energy_ - slot;  // slot holds E(n - window) (0 before the first tick)
  slot = energy_;
  ++n_;
  min_window_ = std::min(min_window_, r.window_energy);
  r.violation = energy_ < -p_.tolerance;
  if (r.violation) ++violations_;
  return r;
}

}  // namespace sinew::haptics
