// scripted_run.cpp — see scripted_run.h.
#include "view/scripted_run.h"

#include <cmath>
#include <cstdio>

namespace sinew::view {

ScriptedRun::Step ScriptedRun::next(const ViewSnapshot& snap, int driven_tool) {
  Step step;
  const bool tool = driven_tool >= 0 && static_cast<std::size_t>(driven_tool) < snap.tools.size();
  const auto tool_position = [&] { return tool ? snap.tools[static_cast<std::size_t>(driven_tool)].position : std::array<double, 3>{}; };
  switch (stage_) {
    case 0:  // let the scene settle, then the first picture
      if (snap.frame < kSettle) break;
      step.screenshot = (dir_ / "before.ppm").string();
      mark_ = snap.frame, stage_ = 1;
      break;
    case 1:  // as long again untouched: what time alone changes
      if (snap.frame < mark_ + kStill) break;
      step.screenshot = (dir_ / "still.ppm").string();
      step.move = true;
      tool_before_ = tool_position();
      mark_ = snap.frame, stage_ = 2;
      break;
    case 2: {  // the handle moved: the tool follows it
      if (snap.frame < mark_ + kFollow) break;
      step.screenshot = (dir_ / "after.ppm").string();
      step.done = true;
      stage_ = 3;
      const std::array<double, 3> after = tool_position();
      const double moved = std::hypot(after[0] - tool_before_[0], after[1] - tool_before_[1], after[2] - tool_before_[2]);
      char line[256];
      std::snprintf(line, sizeof line, "script-test: handle moved %.4f m; tool %d moved %.4f m in %llu frames\n",
                    static_cast<double>(length(move_)), driven_tool, moved,
                    static_cast<unsigned long long>(snap.frame - mark_));
      report_ = "script-test: wrote before.ppm, still.ppm, after.ppm to " + dir_.string() + "\n" + line;
      break;
    }
    default: step.done = true;
  }
  return step;
}

}  // namespace sinew::view
