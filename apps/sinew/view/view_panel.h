// view_panel.h — the viewer's Dear ImGui panel (docs/viewer.md): run,
// pause, step and reset; the tool the mouse drives; what is shown; the
// force on the hand; the last frame's FrameStats and its per-stage profile.
#pragma once

#include <string>

#include "view/scene_drawer.h"
#include "view/view_snapshot.h"

namespace sinew::view {

/// What the panel shows besides the snapshot.
struct PanelInfo {
  std::string scene;          ///< the scene file
  std::string device;         ///< the Simulation's device
  std::string haptics;        ///< the haptic loop's rate and scheduling ("" without tools)
  double render_fps = 0.0;    ///< rendered frames per second, lately
  double frame_time = 0.0;    ///< the scene's time_step [s]
  int driven_tool = -1;       ///< the tool the mouse drives (-1: none)
  V3 hand_force;              ///< the force on the hand [N]
  V3 handle;                  ///< the handle's position [m]
};

/// What the user asked for in the panel this frame.
struct PanelActions {
  bool toggle_pause = false;
  bool step = false;
  bool reset = false;
  int pick_tool = -1;  ///< >= 0: drive this tool
};

/// Draws the panel (between ImGui::NewFrame and ImGui::Render); [in,out] options: the toggles.
PanelActions draw_panel(const ViewSnapshot& snap, const PanelInfo& info, DrawOptions& options);

}  // namespace sinew::view
