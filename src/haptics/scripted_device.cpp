// src/haptics/scripted_device.cpp — a device moved by a function of time,
// and a device that never moves.
#include "sinew/haptics/scripted_device.h"

#include "haptics/vec_math.h"
#include "sinew/haptics/clock.h"

namespace sinew::haptics {

bool ScriptedDevice::sample(std::int64_t now_ns, DeviceSample& out) noexcept {
  const double t = ns_to_seconds(now_ns - origin_ns_);
  const ScriptedPose p = script_(t);
  const ScriptedPose before = script_(t - h_);
  const ScriptedPose after = script_(t + h_);
  out.sequence = ++sequence_;
  out.time_ns = now_ns;
  out.position = p.position;
  out.rotation = vm::normalize(p.rotation);  // NaN stays NaN: the coupling zeroes force and torque
  out.velocity = vm::mul(vm::sub(after.position, before.position), 0.5 / h_);
  out.angular_velocity = vm::angular_velocity(vm::normalize(before.rotation), vm::normalize(after.rotation), 2.0 * h_);
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
  out.rotation = vm::normalize(pose_.rotation);
  out.velocity = {0.0, 0.0, 0.0};
  out.angular_velocity = {0.0, 0.0, 0.0};
  out.buttons = pose_.buttons;
  return true;
}

void NullDevice::command(const Vec3&, const Vec3&, std::int64_t) noexcept { ++commands_; }

}  // namespace sinew::haptics
