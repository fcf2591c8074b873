// sinew/haptics/snapshot_interpolator.h — the tool state the haptic loop
// renders at its own clock, from the two newest physics snapshots.
//
// Render time: one publication interval behind the newest snapshot, the
// usual interpolation buffer (as in networked simulation; e.g. Y. W.
// Bernier, "Latency compensating methods in client/server in-game protocol
// design", GDC 2001). With A the older and B the newer snapshot, published
// at a and b (loop clock), D = b - a and `now` the tick's time:
//   u = (now - b) / D                    (u = 0 when B arrives, 1 one interval later)
//   state(u) = A + u (B - A)             positions, velocities, contact force, angular velocity
//   rotation(u) = normalise(qA + u (qB' - qA)), qB' = +-qB on qA's hemisphere
//                 (a NaN/Inf rotation stays non-finite: the coupling then zeroes force and torque)
// 0 <= u <= 1 interpolates (the rendered state is D old). u > 1 means the
// next snapshot is late: the line through A and B is extrapolated, but only
// for `extrapolation_horizon` seconds past B (u <= 1 + horizon / D); after
// that the state holds there. u < 0 (a snapshot stamped after the tick
// started) is taken as 0. Snapshots more than max_interval apart (a stall)
// are not interpolated: the newest is held. Nor are snapshots less than
// min_interval apart: D is when they were published, not how much
// simulated time lies between them, so a frame published late and the next
// at once (microseconds apart) would multiply the extrapolated speed by
// frame time / D. Interpolating costs one physics frame of latency
// in the loop tool -> device -> tool: the coupled tool is stable when the
// physics frame is short against the tool's coupled period (docs/haptics.md).
#pragma once

#include <cstdint>

#include "sinew/haptics/snapshot_channel.h"
#include "sinew/result.h"

namespace sinew::haptics {

/// How the loop interpolates and extrapolates the tool's snapshots.
struct InterpolationParams {
  /// How far past the newest snapshot the state may be extrapolated [s], >= 0.
  double extrapolation_horizon = 0.010;
  /// Two snapshots further apart than this [s], > 0, are not interpolated
  /// (a stall came between them): the newest is held until the next
  /// arrives. Raise it for physics slower than 1 / max_interval frames/s.
  double max_interval = 0.050;
  /// Two snapshots closer than this [s], 0 <= min_interval <= max_interval,
  /// are not interpolated or extrapolated: the newest is held until the next
  /// arrives. Lower it for physics faster than 1 / min_interval frames/s.
  double min_interval = 0.001;
};
/// Errors name the bad parameter.
Status check(const InterpolationParams& params);

/// How a rendered state was obtained.
enum class RenderMode : std::uint32_t {
  none,          ///< no snapshot yet: no state
  single,        ///< one snapshot (or two further apart than max_interval, or closer than min_interval): the newest held
  interpolated,  ///< between the two newest (0 <= u <= 1)
  extrapolated,  ///< past the newest, within the horizon
  held,          ///< past the horizon: held at the horizon
};

/// The tool state rendered at one instant.
struct RenderedTool {
  RenderMode mode = RenderMode::none;
  Vec3 position{};                    ///< [m]
  Quat rotation{1.0, 0.0, 0.0, 0.0};
  Vec3 velocity{};                    ///< [m/s]
  Vec3 angular_velocity{};            ///< [rad/s]
  Vec3 contact_force{};               ///< [N]
  Vec3 contact_normal{};              ///< the newest snapshot's
  bool in_contact = false;            ///< the newest snapshot's
  double u = 0.0;                     ///< the interpolation parameter used (after the horizon clamp)
  double snapshot_age = 0.0;          ///< now - newest snapshot's stamp [s]
  double render_age = 0.0;            ///< now - the time the rendered state stands for [s]
  [[nodiscard]] bool valid() const { return mode != RenderMode::none; }
};

/// The two newest snapshots. Not thread-safe: owned by the haptic thread.
class SnapshotHistory {
 public:
  /// Keeps `snapshot` as the newest, the previous newest as the older.
  void push(const HapticSnapshot& snapshot) noexcept;
  void clear() noexcept { count_ = 0; }
  /// [in] now_ns: the tick's time on the loop clock [ns].
  [[nodiscard]] RenderedTool render(std::int64_t now_ns, const InterpolationParams& params) const noexcept;
  [[nodiscard]] int count() const { return count_; }
  [[nodiscard]] const HapticSnapshot& newest() const { return newest_; }
  [[nodiscard]] const HapticSnapshot& older() const { return older_; }

 private:
  HapticSnapshot older_{}, newest_{};
  int count_ = 0;  // 0, 1 or 2
};

}  // namespace sinew::haptics
