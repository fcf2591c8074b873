// sinew/haptics/replay_device.h — a device that replays a recorded
// trajectory, and the trajectory CSV format.
//
// Trajectory CSV: '#' starts a comment line; the first other line is the
// header, one of
//   time,x,y,z
//   time,x,y,z,qw,qx,qy,qz
//   time,x,y,z,qw,qx,qy,qz,buttons
// then one row per sample: time [s] strictly increasing, position [m],
// optional unit quaternion (normalised on load, must not be zero) and
// button bits (an integer).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "sinew/haptics/haptic_device.h"
#include "sinew/result.h"

namespace sinew::haptics {

/// One recorded sample.
struct TrajectorySample {
  double time = 0.0;                  ///< [s]
  Vec3 position{};                    ///< [m]
  Quat rotation{1.0, 0.0, 0.0, 0.0};  ///< unit quaternion (w, x, y, z)
  std::uint32_t buttons = 0;
};

/// Reads a trajectory CSV. Errors name the file and line.
Result<std::vector<TrajectorySample>> read_trajectory_csv(const std::filesystem::path& path);
/// Writes a trajectory CSV (with rotation and buttons) that read_trajectory_csv reads back.
Status write_trajectory_csv(const std::filesystem::path& path, std::span<const TrajectorySample> samples);

/// Replays a trajectory: the pose at t = (now - origin) [s] is interpolated
/// linearly between the samples around t (rotations by normalised lerp),
/// velocities are the slopes of that segment, buttons those of the sample
/// at or before t. Before the first sample it holds the first; after the
/// last it holds the last (velocity zero), or wraps around when `loop`.
class ReplayDevice final : public HapticDevice {
 public:
  /// [in] samples: at least one, times strictly increasing, finite values. Errors name the sample.
  static Result<ReplayDevice> create(std::vector<TrajectorySample> samples, std::int64_t origin_ns = 0,
                                     bool loop = false, std::string name = "replay");
  /// Reads `path` (read_trajectory_csv) and makes a device of it.
  static Result<ReplayDevice> load(const std::filesystem::path& path, std::int64_t origin_ns = 0, bool loop = false);

  [[nodiscard]] std::string name() const override { return name_; }
  /// Samples per second of the recording (its mean rate) [Hz].
  [[nodiscard]] double update_rate_hz() const override { return rate_hz_; }
  bool sample(std::int64_t now_ns, DeviceSample& out) noexcept override;
  void command(const Vec3& force, const Vec3& torque, std::int64_t now_ns) noexcept override;

  void set_origin(std::int64_t origin_ns) { origin_ns_ = origin_ns; }
  [[nodiscard]] const std::vector<TrajectorySample>& samples() const { return samples_; }
  [[nodiscard]] const Vec3& last_force() const { return force_; }

 private:
  ReplayDevice() = default;
  std::vector<TrajectorySample> samples_;
  std::int64_t origin_ns_ = 0;
  bool loop_ = false;
  std::string name_;
  double rate_hz_ = 0.0;
  std::size_t cursor_ = 0;  // segment of the previous sample (searched from here: O(1) per tick)
  std::uint64_t sequence_ = 0;
  Vec3 force_{};
};

}  // namespace sinew::haptics
