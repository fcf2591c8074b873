// mouse_device.h — the viewer's virtual haptic device (docs/viewer.md):
// a HapticDevice whose handle the mouse moves. The haptic loop samples it
// and renders the virtual coupling to it exactly as to a real device; the
// force it is commanded is what a hand would feel, shown as an arrow.
#pragma once

#include <cstdint>
#include <string>

#include "sinew/haptics/haptic_device.h"
#include "sinew/haptics/seqlock_channel.h"

namespace sinew::view {

using haptics::Quat;
using haptics::Vec3;

/// A 3-DOF device moved by the mouse. The viewer (one thread) sets where
/// the mouse puts the handle; the haptic loop's ticks sample a handle that
/// follows it through a first-order low-pass of time constant `smoothing`
/// (a hand moves a device smoothly: the mouse moves in jumps, once per
/// rendered frame, and a jump would be a spike of velocity in the
/// coupling's damping term). Its velocity is the filter's own derivative.
class MouseDevice final : public haptics::HapticDevice {
 public:
  /// [in] smoothing: the low-pass time constant [s], > 0; [in] rate_hz: the nominal update rate [Hz].
  explicit MouseDevice(double smoothing = 0.02, double rate_hz = 1000.0) : tau_(smoothing), rate_hz_(rate_hz) {}

  [[nodiscard]] std::string name() const override { return "mouse (virtual)"; }
  [[nodiscard]] double update_rate_hz() const override { return rate_hz_; }
  bool sample(std::int64_t now_ns, haptics::DeviceSample& out) noexcept override;
  void command(const Vec3& force, const Vec3& torque, std::int64_t now_ns) noexcept override;

  /// Where the mouse puts the handle [m] (the viewer's thread); the handle follows it.
  void move_to(const Vec3& position);
  /// Puts the handle at `position` at once, without filtering (a new tool
  /// picked, a reset): no jump of the coupling's spring.
  void place(const Vec3& position);
  /// Where the mouse put the handle last [m] (the viewer's thread).
  [[nodiscard]] const Vec3& goal() const { return goal_.position; }

 private:
  struct Goal {
    Vec3 position{};
    std::uint64_t placed = 0;  // +1 at every place(): the handle jumps there
  };
  haptics::SeqlockChannel<Goal> channel_;  // viewer -> haptic tick
  Goal goal_{};                            // the viewer's copy
  double tau_, rate_hz_;
  // The haptic tick's own state.
  Vec3 handle_{}, velocity_{};
  std::uint64_t placed_seen_ = UINT64_MAX;
  std::int64_t last_ns_ = 0;
  std::uint64_t sequence_ = 0;
};

}  // namespace sinew::view
