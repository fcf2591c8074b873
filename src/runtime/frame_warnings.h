// frame_warnings.h — the warnings of sinew/warnings.h: a scene's Courant
// numbers when it is created, and per frame the overruns of the wall-time
// budget and the counts near their capacity, sent to the log.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "sinew/scene.h"
#include "sinew/warnings.h"

namespace sinew {

struct FrameStats;

/// Logs a warning for each stable Neo-Hookean tet body of `scene` whose
/// shear-wave Courant number per substep is above its stable limit.
void warn_about_scene(const SceneDesc& scene);

/// The shear-wave Courant number per substep of tet body `body` of `scene`
/// (sinew/warnings.h's k; 0 for a body with no shear modulus).
double shear_courant_number(const SceneDesc& scene, std::size_t body);

/// What the per-frame warnings remember between frames.
class FrameWarnings {
 public:
  /// Errors (bad_parameter, naming the field): frame_budget_ms < 0,
  /// repeat_seconds not > 0, capacity_fraction outside (0, 1], or non-finite.
  Status set(const WarningSettings& settings);
  [[nodiscard]] const WarningSettings& settings() const { return settings_; }
  /// After each frame: logs its overrun and its counts near their capacity.
  void after_frame(const FrameStats& stats);

 private:
  using Clock = std::chrono::steady_clock;
  WarningSettings settings_;
  // Overruns since the last warning: how many, of how many frames, the worst.
  std::uint64_t overruns_ = 0, frames_since_warning_ = 0, worst_frame_ = 0;
  double worst_ms_ = 0.0;
  bool warned_overrun_ = false;
  Clock::time_point last_warning_{};
  // Counters ("stage/counter") now at or above the fraction (warned, not re-armed).
  std::vector<std::string> full_;
};

}  // namespace sinew
