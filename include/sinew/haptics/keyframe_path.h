// sinew/haptics/keyframe_path.h — a scripted hand's path as keyframes in
// time: the pose a ScriptedDevice follows in scene files (their "haptics"
// section) and in the examples, written as data instead of code.
//
//   auto path = sinew::haptics::KeyframePath::create(
//       {{.time = 0.0, .position = {0, 0.05, 0}}, {.time = 1.0, .position = {0, 0.04, 0}}},
//       sinew::haptics::PathInterpolation::smooth);
//   sinew::haptics::ScriptedDevice device(path->script());
#pragma once

#include <vector>

#include "sinew/haptics/scripted_device.h"
#include "sinew/result.h"

namespace sinew::haptics {

/// How a path moves between two keys.
enum class PathInterpolation {
  linear,  ///< a + (b - a) s, s = (t - t_a) / (t_b - t_a): constant speed, a velocity jump at each key
  /// a + (b - a) (1 - cos(pi s)) / 2: starts and stops at rest at every key (a
  /// cosine ramp, as a hand moves from one place to the next), so the
  /// device's velocity is continuous and the coupling feels no jolt.
  smooth,
};

/// One key: at `time` the hand is at this pose.
struct PathKey {
  double time = 0.0;                   ///< [s] since the path's start, >= 0; keys strictly increasing
  Vec3 position{};                     ///< [m], finite
  Quat rotation{1.0, 0.0, 0.0, 0.0};   ///< unit quaternion (w, x, y, z), finite, non-zero (normalised here)
};

/// A pose as a function of time through its keys: before the first key the
/// first pose, after the last the last; between two keys positions move as
/// `interpolation` says and rotations by normalised linear interpolation of
/// the quaternions along the shorter arc, with the same parameter.
/// Evaluating it allocates nothing (it runs inside a haptic tick).
class KeyframePath {
 public:
  /// A hand that stays at the origin, unrotated (one key at t = 0).
  KeyframePath() : keys_{PathKey{}}, interpolation_(PathInterpolation::smooth) {}
  /// [in] keys: at least one, times finite, >= 0 and strictly increasing;
  /// [in] interpolation. Errors (bad_parameter) name the key and the rule,
  /// e.g. "keys[2].time: must be greater than the previous key's (got 0.5 after 0.5)".
  static Result<KeyframePath> create(std::vector<PathKey> keys, PathInterpolation interpolation);

  /// The pose at time t [s] (any t; NaN gives the first key's).
  [[nodiscard]] ScriptedPose at(double t) const noexcept;
  /// The path as a ScriptedDevice's script (a copy of the keys).
  [[nodiscard]] ScriptedDevice::Script script() const;

  [[nodiscard]] const std::vector<PathKey>& keys() const { return keys_; }
  [[nodiscard]] PathInterpolation interpolation() const { return interpolation_; }
  /// The last key's time [s]: when the hand stops.
  [[nodiscard]] double duration() const { return keys_.back().time; }

 private:
  KeyframePath(std::vector<PathKey> keys, PathInterpolation interpolation)
      : keys_(std::move(keys)), interpolation_(interpolation) {}
  std::vector<PathKey> keys_;
  PathInterpolation interpolation_;
};

}  // namespace sinew::haptics
