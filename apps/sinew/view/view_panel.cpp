// view_panel.cpp — see view_panel.h.
#include "view/view_panel.h"

#include <imgui.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace sinew::view {

PanelActions draw_panel(const ViewSnapshot& snap, const PanelInfo& info, DrawOptions& options) {
  PanelActions act;
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(460, 0), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.85f);
  ImGui::Begin("sinew view");
  ImGui::TextWrapped("%s", info.scene.c_str());
  ImGui::TextWrapped("%s", info.device.c_str());
  ImGui::TextWrapped("rendering %.1f fps; physics %.1f Hz (the scene's rate %.1f Hz)", info.render_fps, snap.physics_hz,
              info.frame_time > 0 ? 1.0 / info.frame_time : 0.0);
  if (!snap.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "stopped: %s", snap.error.c_str());

  if (ImGui::Button(snap.paused ? "run (space)" : "pause (space)")) act.toggle_pause = true;
  ImGui::SameLine();
  if (ImGui::Button("step (n)")) act.step = true;
  ImGui::SameLine();
  if (ImGui::Button("reset (r)")) act.reset = true;

  ImGui::Checkbox("contact forces (c)", &options.contacts);
  ImGui::SameLine();
  ImGui::Checkbox("colour by speed (v)", &options.colour_by_speed);
  ImGui::Checkbox("colliders", &options.colliders);
  ImGui::SameLine();
  ImGui::Checkbox("fluid", &options.fluid);

  if (!snap.tools.empty()) {
    ImGui::Separator();
    const std::string current = info.driven_tool >= 0 ? "tool " + std::to_string(info.driven_tool) : "none";
    if (ImGui::BeginCombo("driven tool (tab)", current.c_str())) {
      for (int t = 0; t < static_cast<int>(snap.tools.size()); ++t)
        if (ImGui::Selectable(("tool " + std::to_string(t)).c_str(), t == info.driven_tool)) act.pick_tool = t;
      ImGui::EndCombo();
    }
    const V3 f = info.hand_force;
    ImGui::Text("force on the hand %.3f N  (%.2f, %.2f, %.2f)", length(f), f.x, f.y, f.z);
    ImGui::Text("handle at (%.4f, %.4f, %.4f) m", info.handle.x, info.handle.y, info.handle.z);
    if (info.driven_tool >= 0 && static_cast<std::size_t>(info.driven_tool) < snap.tools.size()) {
      const ToolState& s = snap.tools[static_cast<std::size_t>(info.driven_tool)];
      ImGui::Text("tool at   (%.4f, %.4f, %.4f) m", s.position[0], s.position[1], s.position[2]);
      ImGui::Text("contact force %.3f N", length(V3(s.contact_force)));
    }
    ImGui::TextWrapped("%s", info.haptics.c_str());
  }

  const FrameStats& st = snap.stats;
  ImGui::Separator();
  ImGui::Text("frame %llu  t = %.4f s  wall %.3f ms", static_cast<unsigned long long>(st.frame), st.time, st.wall_ms);
  ImGui::Text("residual rms %.3e  max %.3e", st.residual_rms, st.max_residual);
  ImGui::Text("kinetic energy %.4e J  volume change %+.3e", st.kinetic_energy, st.volume_change);
  ImGui::Text("mesh contacts %u  ccd hits %u  sweeps %llu", st.mesh_contacts, st.ccd_hits,
              static_cast<unsigned long long>(st.sweeps));
  if (ImGui::BeginTable("stages", 3, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
    ImGui::TableSetupColumn("stage", ImGuiTableColumnFlags_WidthFixed, 150.0f);
    ImGui::TableSetupColumn("ms", ImGuiTableColumnFlags_WidthFixed, 60.0f);
    ImGui::TableSetupColumn("counters", ImGuiTableColumnFlags_WidthStretch);
    ImGui::TableHeadersRow();
    for (const StageProfile& s : st.stages) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(s.name.c_str());
      ImGui::TableNextColumn();
      ImGui::Text("%.3f", s.ms);
      ImGui::TableNextColumn();
      std::string counters;
      for (const StageProfile::Counter& c : s.counters) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "%s%s %g", counters.empty() ? "" : ", ", c.name.c_str(), c.value);
        counters += buf;
      }
      ImGui::TextWrapped("%s", counters.c_str());
    }
    ImGui::EndTable();
  }
  ImGui::Separator();
  ImGui::TextWrapped(
      "left drag: turn; wheel: zoom; middle drag: pan; right drag (or ctrl + left): move the handle in the view "
      "plane, with shift: in depth; click a tool: drive it; h: hide this panel");
  ImGui::End();
  return act;
}

}  // namespace sinew::view
