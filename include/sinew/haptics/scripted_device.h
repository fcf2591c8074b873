// sinew/haptics/scripted_device.h — a device whose pose is a function of
// time (examples, benchmarks, tests), and a null device.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "sinew/haptics/haptic_device.h"

namespace sinew::haptics {

/// A pose given by a script.
struct ScriptedPose {
  Vec3 position{};                    ///< [m]
  Quat rotation{1.0, 0.0, 0.0, 0.0};  ///< quaternion (w, x, y, z), normalised when sampled; NaN/Inf stays non-finite
  std::uint32_t buttons = 0;
};

/// A device moved by a script: pose = script(t), t = (now - origin) [s].
/// Velocities are central differences of the script over +-`difference_step`.
/// The script runs inside the tick: it must not allocate, lock or do I/O.
/// Forces commanded are kept (last_force()) and summed up as work.
class ScriptedDevice final : public HapticDevice {
 public:
  using Script = std::function<ScriptedPose(double t)>;
  /// [in] script: the pose at time t [s] since `origin_ns`, not empty;
  /// [in] origin_ns: the loop clock's time at t = 0 [ns];
  /// [in] rate_hz: the nominal update rate reported [Hz], finite and > 0;
  /// [in] difference_step: the central difference's half step [s], finite and > 0.
  /// Errors name the bad parameter.
  static Result<ScriptedDevice> create(Script script, std::int64_t origin_ns = 0, double rate_hz = 1000.0,
                                       double difference_step = 1e-4);
  /// The same parameters, unchecked: start() (HapticLoop::start()) reports
  /// a bad one; ticked by hand without start(), prefer create().
  explicit ScriptedDevice(Script script, std::int64_t origin_ns = 0, double rate_hz = 1000.0,
                          double difference_step = 1e-4)
      : script_(std::move(script)), origin_ns_(origin_ns), rate_hz_(rate_hz), h_(difference_step) {}

  [[nodiscard]] std::string name() const override { return "scripted"; }
  [[nodiscard]] double update_rate_hz() const override { return rate_hz_; }
  /// Checks the parameters (as create() does); errors name the bad one.
  Status start(std::int64_t now_ns) override;
  bool sample(std::int64_t now_ns, DeviceSample& out) noexcept override;
  void command(const Vec3& force, const Vec3& torque, std::int64_t now_ns) noexcept override;

  /// [in] origin_ns: the loop clock's time at t = 0 [ns] (before the loop starts).
  void set_origin(std::int64_t origin_ns) { origin_ns_ = origin_ns; }
  /// The newest force and torque commanded [N, N m] (read on the loop's thread, or after it stopped).
  [[nodiscard]] const Vec3& last_force() const { return force_; }
  [[nodiscard]] const Vec3& last_torque() const { return torque_; }
  [[nodiscard]] std::uint64_t commands() const { return commands_; }

 private:
  Script script_;
  std::int64_t origin_ns_;
  double rate_hz_;
  double h_;
  std::uint64_t sequence_ = 0;
  std::uint64_t commands_ = 0;
  Vec3 force_{}, torque_{};
};

/// A device that stays at one pose and discards forces (a loop without
/// hardware; a placeholder while the real device is unplugged).
class NullDevice final : public HapticDevice {
 public:
  explicit NullDevice(const ScriptedPose& pose = {}, double rate_hz = 1000.0) : pose_(pose), rate_hz_(rate_hz) {}
  [[nodiscard]] std::string name() const override { return "null"; }
  [[nodiscard]] double update_rate_hz() const override { return rate_hz_; }
  bool sample(std::int64_t now_ns, DeviceSample& out) noexcept override;
  void command(const Vec3& force, const Vec3& torque, std::int64_t now_ns) noexcept override;
  [[nodiscard]] std::uint64_t commands() const { return commands_; }

 private:
  ScriptedPose pose_;
  double rate_hz_;
  std::uint64_t sequence_ = 0;
  std::uint64_t commands_ = 0;
};

}  // namespace sinew::haptics
