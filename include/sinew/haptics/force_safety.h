// sinew/haptics/force_safety.h — what stands between a computed force and
// the device: a non-finite filter, a magnitude clamp, the watchdog gain and
// a per-tick change (slew) limit, in that order.
//
// The chain, for a raw force F (or torque) and the previous output P:
//   1. any component NaN/Inf -> output exactly zero this tick (counted),
//      bypassing the slew limit (dropping to zero is the safe direction);
//   2. |F| > max -> F * max / |F| (direction kept);
//   3. F * gain, gain in [0, 1] from the Watchdog;
//   4. |F - P| > max_change -> P + (F - P) max_change / |F - P|.
// Steps 3-4 are convex combinations of values inside the clamp ball, so the
// output never exceeds `max`. A fading watchdog is therefore also
// slew-limited (smooth), and an interpolation jump (a late snapshot) is
// spread over a few ticks. The passivity controller, when on, adds its
// damper after this chain, clamped but not slew-limited (passivity_observer.h).
#pragma once

#include <cstdint>

#include "sinew/haptics/snapshot_channel.h"

namespace sinew::haptics {

/// What the chain did in one tick (bits, OR-ed into TickRecord::flags).
enum TickFlags : std::uint32_t {
  kNonFinite = 1u << 0,     ///< the raw force or torque had a NaN/Inf: output zeroed
  kClamped = 1u << 1,       ///< magnitude clamped
  kSlewLimited = 1u << 2,   ///< per-tick change limited
  kStale = 1u << 3,         ///< watchdog: snapshots (or device samples) stale
  kFading = 1u << 4,        ///< watchdog gain below 1
  kNoSnapshot = 1u << 5,    ///< no snapshot yet
  kNoDeviceSample = 1u << 6,  ///< the device had no sample this tick
  kExtrapolated = 1u << 7,  ///< state extrapolated past the newest snapshot
  kHeld = 1u << 8,          ///< state held at the extrapolation horizon
  kMissedDeadline = 1u << 9,  ///< this tick started more than 2 periods after the previous one
  /// The passivity observer's: the cumulative energy is below
  /// -tolerance (passivity_observer.h). A bit apart from the others.
  kPassivityViolation = 1u << 16,
  kPassivityDamping = 1u << 17,  ///< the passivity controller added a damper to the device's command
};

/// The non-finite / clamp / gain / slew chain for one 3-vector (a force or
/// a torque). Not thread-safe: owned by the haptic thread.
class SafetyFilter {
 public:
  /// [in] max_magnitude: the clamp (N or N m), > 0; [in] max_change: per call, > 0.
  SafetyFilter(double max_magnitude, double max_change) : max_(max_magnitude), max_change_(max_change) {}
  /// [in] raw: the computed value; [in] gain: watchdog gain (clamped to [0, 1], non-finite -> 0);
  /// [in,out] flags: kNonFinite / kClamped / kSlewLimited added. Returns the output.
  Vec3 apply(const Vec3& raw, double gain, std::uint32_t& flags) noexcept;
  /// Forgets the previous output (the next call slews from zero).
  void reset() noexcept { last_ = {0.0, 0.0, 0.0}; }
  /// The last output.
  [[nodiscard]] const Vec3& last() const { return last_; }

 private:
  double max_, max_change_;
  Vec3 last_{};
};

}  // namespace sinew::haptics
