// src/haptics/passivity_observer.cpp — the time-domain passivity observer of
// Hannaford and Ryu, "Time-domain passivity control of haptic interfaces",
// IEEE Trans. Robotics and Automation 18(1), 2002, for force and torque,
// with a sliding window of its energy for reporting (criterion and what it
// sees: sinew/haptics/passivity_observer.h).
#include "sinew/haptics/passivity_observer.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "math/vec3.h"

namespace sinew::haptics {

Status check(const PassivityParams& p) {
  if (p.window < 1 || p.window > kMaxPassivityWindow)
    return Error(ErrorCode::bad_parameter, "passivity.window must be in 1.." + std::to_string(kMaxPassivityWindow) +
                                               " ticks (got " + std::to_string(p.window) + ")");
  if (!(p.tolerance >= 0.0) || !std::isfinite(p.tolerance))
    return Error(ErrorCode::bad_parameter,
                 "passivity.tolerance must be finite and >= 0 [J] (got " + std::to_string(p.tolerance) + ")");
  for (auto [name, v] : {std::pair{"passivity.max_damping", p.max_damping},
                         std::pair{"passivity.max_rotational_damping", p.max_rotational_damping}})
    if (!(v >= 0.0) || !std::isfinite(v))
      return Error(ErrorCode::bad_parameter,
                   std::string(name) + " must be finite and >= 0 (got " + std::to_string(v) + ")");
  return {};
}

namespace {
// v scaled down to length at most `limit` (direction kept).
Vec3 clamp_length(const Vec3& v, double limit) {
  const double n = std::sqrt(math::dot(v, v));
  return n > limit ? math::mul(v, limit / n) : v;
}
}  // namespace

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

bool PassivityObserver::control(const Vec3& position, const Quat& rotation, const Vec3& velocity,
                                const Vec3& angular_velocity, double period, double max_force, double max_torque,
                                bool render_torque, Vec3& force, Vec3& torque) const noexcept {
  if (!have_prev_) return false;
  // E(n): with the interval that just ended (observe() adds it afterwards).
  const Vec3 dx = math::sub(position, prev_position_);
  const Vec3 dtheta = math::rotation_vector(math::qmul(rotation, math::conj(prev_rotation_)));
  const double now = energy_ - (math::dot(prev_force_, dx) + math::dot(prev_torque_, dtheta));
  // The coming interval's, at the present velocity.
  const double coming = -period * (math::dot(force, velocity) + math::dot(torque, angular_velocity));
  const double deficit = -(now + coming);
  if (!(deficit > 0.0) || !std::isfinite(deficit)) return false;
  const double v2 = math::dot(velocity, velocity), w2 = math::dot(angular_velocity, angular_velocity);
  const double alpha = v2 > 0.0 ? std::min(p_.max_damping, deficit / (period * v2)) : 0.0;
  const double left = deficit - alpha * v2 * period;
  // A 3-DOF device is commanded no torque: no rotational damper either.
  const double alpha_r =
      render_torque && w2 > 0.0 && left > 0.0 ? std::min(p_.max_rotational_damping, left / (period * w2)) : 0.0;
  if (!(alpha > 0.0) && !(alpha_r > 0.0)) return false;
  force = clamp_length(math::sub(force, math::mul(velocity, alpha)), max_force);
  if (alpha_r > 0.0) torque = clamp_length(math::sub(torque, math::mul(angular_velocity, alpha_r)), max_torque);
  return true;
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
