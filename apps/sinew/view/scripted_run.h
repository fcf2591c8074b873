// scripted_run.h — the viewer driven by a script instead of a hand
// (`sinew view --script-test DIR`, docs/viewer.md), for a headless test:
// it lets the scene settle, takes a screenshot, waits as long again
// without touching anything and takes another, then moves the virtual
// device's handle by a given offset, waits for the tool to follow and
// takes a third. It reports how far the tool moved.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include "view/view_math.h"
#include "view/view_snapshot.h"

namespace sinew::view {

class ScriptedRun {
 public:
  /// [in] dir: where the screenshots go (made if missing); [in] move: the handle's offset [m].
  ScriptedRun(std::filesystem::path dir, V3 move) : dir_(std::move(dir)), move_(move) {}

  /// What to do in the frame about to be drawn, given the newest snapshot.
  struct Step {
    std::string screenshot;  ///< non-empty: save this frame (drawn without the panel) to this file
    bool move = false;       ///< move the handle by the offset now
    bool done = false;       ///< the script has finished (after this frame's screenshot)
  };
  Step next(const ViewSnapshot& snap, int driven_tool);
  /// The lines to print at the end: the screenshots and the tool's motion.
  [[nodiscard]] std::string report() const { return report_; }
  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }

 private:
  static constexpr std::uint64_t kSettle = 150, kStill = 30, kFollow = 60;  // physics frames
  std::filesystem::path dir_;
  V3 move_;
  int stage_ = 0;
  std::uint64_t mark_ = 0;
  std::array<double, 3> tool_before_{};
  std::string report_;
};

}  // namespace sinew::view
