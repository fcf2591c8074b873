// sinew/haptics/haptic_device.h — what the haptic loop needs from a device:
// a pose sample per tick, and a force command per tick.
//
// Adding a real device SDK (e.g. OpenHaptics for a 3D Systems Touch, the
// Force Dimension SDK, CHAI3D's drivers): derive from HapticDevice in your
// own code; open the device in start(), close it in stop(); in sample() read
// the SDK's newest pose and velocity (or copy what the SDK's own servo
// callback left in a SeqlockChannel), convert it to the simulation frame
// (workspace offset and scale, metres) and stamp it with the loop clock's
// time; in command() convert the force back (a workspace scale s on
// positions means a force scale s on forces, so power is preserved) and hand
// it to the SDK. sample() and command() run inside the real-time tick: no
// allocation, lock, I/O or logging there. Devices with their own servo
// scheduler can instead call HapticLoop::tick() from that scheduler. To keep
// the SDK out of the application's build, write the driver as a plug-in
// against the C ABI of sinew/haptics/device_plugin_abi.h instead and load
// it at run time (sinew/haptics/device_plugin.h).
#pragma once

#include <cstdint>
#include <string>

#include "sinew/haptics/snapshot_channel.h"
#include "sinew/result.h"

namespace sinew::haptics {

/// One device reading, in the simulation's world frame.
struct DeviceSample {
  std::uint64_t sequence = 0;        ///< increases by one per new reading
  std::int64_t time_ns = 0;          ///< when it was taken, on the loop's clock [ns]
  Vec3 position{};                   ///< end effector [m]
  Quat rotation{1.0, 0.0, 0.0, 0.0}; ///< end-effector orientation (unit quaternion w, x, y, z)
  Vec3 velocity{};                   ///< [m/s]
  Vec3 angular_velocity{};           ///< world frame [rad/s]
  std::uint32_t buttons = 0;         ///< bit i: button i pressed
};

/// A haptic device. start() and stop() run outside the real-time loop and
/// may allocate or block; sample() and command() run inside every tick and
/// must not allocate, lock, do I/O or log.
class HapticDevice {
 public:
  virtual ~HapticDevice() = default;
  /// A human-readable name ("scripted", "replay trajectory.csv", ...).
  [[nodiscard]] virtual std::string name() const = 0;
  /// Nominal rate at which the device produces new samples [Hz].
  [[nodiscard]] virtual double update_rate_hz() const = 0;
  /// Opens the device. [in] now_ns: the loop clock's time [ns]. Errors say why.
  virtual Status start(std::int64_t now_ns) { (void)now_ns; return {}; }
  /// Closes the device; forces stop.
  virtual void stop() noexcept {}
  /// [in] now_ns: the tick's time on the loop clock [ns].
  /// [out] out: the newest sample. Returns false when there is none (the
  /// loop then keeps the previous one and its watchdog sees it age).
  virtual bool sample(std::int64_t now_ns, DeviceSample& out) noexcept = 0;
  /// Commands the force [N] and torque [N m] (world frame) applied to the
  /// user's hand until the next command. A loop set up for a 3-DOF device
  /// (HapticLoopSettings::degrees_of_freedom = 3) commands exactly zero torque.
  virtual void command(const Vec3& force, const Vec3& torque, std::int64_t now_ns) noexcept = 0;
};

}  // namespace sinew::haptics
