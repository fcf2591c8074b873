// src/haptics/scripted_device.cpp — a device moved by a function of time,
// and a device that never moves.
#include "sinew/haptics/scripted_device.h"

#include <cmath>
#include <string>

#include "math/vec3.h"
#include "sinew/haptics/clock.h"

namespace sinew::haptics {

namespace {
Status check_scripted(const ScriptedDevice::Script& script, double rate_hz, double difference_step) {
  if (!script) return Error(ErrorCode::bad_parameter, "scripted device: the script is empty");
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz))
    return Error(ErrorCode::bad_parameter,
                 "scripted device: rate_hz must be finite and > 0 [Hz] (got " + std::to_string(rate_hz) + ")");
  if (!(difference_step > 0.0) || !std::isfinite(difference_step))
    return Error(ErrorCode::bad_parameter,
                 "scripted device: difference_step must be finite and > 0 [s] (got " +
                 std::to_string(difference_step) + ")");
  return {};
}
}  // namespace

Result<ScriptedDevice> ScriptedDevice::create(Script script, std::int64_t origin_ns, double rate_hz,
                                              double difference_step) {
  if (auto s = check_scripted(script, rate_hz, difference_step); !s) return s.error();
  return ScriptedDevice(std::move(script), origin_ns, rate_hz, difference_step);
}

Status ScriptedDevice::start(std::int64_t) { return check_scripted(script_, rate_hz_, h_); }

bool ScriptedDevice::sample(std::int64_t now_ns, DeviceSample& out) noexcept {
  const double t = ns_to_seconds(now_ns - origin_ns_);
  const ScriptedPose p = script_(t);
  const ScriptedPose before = script_(t - h_);
  const ScriptedPose after = script_(t + h_);
  out.sequence = ++sequence_;
  out.time_ns = now_ns;
  out.position = p.position;
  out.rotation = math::normalize(p.rotation);  // NaN stays NaN: the coupling zeroes force and torque
  out.velocity = math::mul(math::sub(after.position, before.position), 0.5 / h_);
  out.angular_velocity = math::angular_velocity(math::normalize(before.rotation), math::normalize(after.rotation), 2.0 * h_);
  out.buttons = p.buttons;
  return true;
}

void ScriptedDevice::command(const Vec3& force, const Vec3& torque, std::int64_t) noexcept {
  force_ = force;
  torque_ = torque;
  ++commands_;
}

bool NullDevice::sample(std::int64_t now_ns, DeviceSample& out) noexcept {
  out.sequence = ++sequence_;
  out.time_ns = now_ns;
  out.position = pose_.position;
  out.rotation = math::normalize(pose_.rotation);
  out.velocity = {0.0, 0.0, 0.0};
  out.angular_velocity = {0.0, 0.0, 0.0};
  out.buttons = pose_.buttons;
  return true;
}

void NullDevice::command(const Vec3&, const Vec3&, std::int64_t) noexcept { ++commands_; }

}  // namespace sinew::haptics
