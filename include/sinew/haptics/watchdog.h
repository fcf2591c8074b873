// sinew/haptics/watchdog.h — fades the device force to zero when the
// physics stops publishing (or the device stops sampling), and brings it
// back when they resume.
//
// Gain g in [0, 1], multiplied into the force before the slew limit
// (force_safety.h). Every tick, with dt the time since the previous tick:
//   stale (age of the newest snapshot > stale_after, or of the newest
//   device sample > device_stale_after):  g = max(0, g - dt / fade_time)
//   fresh:                                g = min(1, g + dt / recover_time)
// Linear ramps: from full force, the force is zero at most fade_time after
// the staleness is detected, i.e. stale_after + fade_time after the last
// snapshot. The gain starts at 0, so a loop that starts ramps its force up
// over recover_time instead of kicking the hand.
#pragma once

#include <cstdint>

#include "sinew/result.h"

namespace sinew::haptics {

/// When the tool's or the device's state counts as stale, and how the
/// force fades out and back in.
struct WatchdogParams {
  double stale_after = 0.050;         ///< snapshot age beyond which the state is stale [s], > 0 (3 frames at 60 Hz)
  double device_stale_after = 0.010;  ///< device sample age beyond which it is stale [s], > 0 (10 ticks at 1 kHz)
  double fade_time = 0.100;           ///< full force to zero [s], > 0
  double recover_time = 0.250;        ///< zero to full force once fresh again [s], > 0
};
/// Errors name the bad parameter.
Status check(const WatchdogParams& params);

/// Not thread-safe: owned by the haptic thread.
class Watchdog {
 public:
  explicit Watchdog(const WatchdogParams& params) : p_(params) {}
  /// [in] snapshot_age, device_age: ages of the newest snapshot and device
  /// sample [s] (infinity when there is none); [in] dt: time since the
  /// previous update [s], >= 0. Returns the gain in [0, 1].
  double update(double snapshot_age, double device_age, double dt) noexcept;
  [[nodiscard]] double gain() const { return gain_; }
  [[nodiscard]] bool stale() const { return stale_; }
  /// How many times it went from fresh to stale.
  [[nodiscard]] std::uint64_t stalls() const { return stalls_; }
  void reset() noexcept { gain_ = 0.0; stale_ = true; }

 private:
  WatchdogParams p_;
  double gain_ = 0.0;
  bool stale_ = true;
  std::uint64_t stalls_ = 0;
};

}  // namespace sinew::haptics
