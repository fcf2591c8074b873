// tool_cuts_stage.cpp — tools that cut a level-set collider as they move
// (ToolDesc::cuts; a burr in bone): the tools' poses at the frame's start,
// taken before the tools stage integrates them, and after the frame the
// collider cut along each tool's motion (Simulation::Impl::cut_collider,
// as Tools::cut). Voxmap-pointshell cutting as in haptic bone surgery
// simulators (Morris, Sewell, Barbagli and Salisbury, "Visuohaptic
// simulation of bone surgery for training and evaluation", IEEE CG&A
// 26(6), 2006): the burr removes the voxels it sweeps, its penalty
// against what is left is the force felt.
#include <vector>

#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class ToolCutsStage final : public FrameStage {
 public:
  ToolCutsStage(Simulation::Impl& sim, std::vector<std::pair<std::size_t, ToolCutDesc>> cuts)
      : sim_(sim), cuts_(std::move(cuts)), from_(cuts_.size()) {}
  std::string_view name() const override { return "tool cuts"; }

  // Registered before the tools stage: the poses the tools start the frame at.
  Status before_frame(FrameContext&) override {
    for (std::size_t i = 0; i < cuts_.size(); ++i) from_[i] = pose(sim_.contacts.tools[cuts_[i].first]);
    return {};
  }

  // The frame's motion of each cutting tool, cut out of its collider.
  Status after_frame(FrameContext&) override {
    removed_ = 0.0;
    changed_bytes_ = 0;
    for (std::size_t i = 0; i < cuts_.size(); ++i) {
      ToolBody& tool = sim_.contacts.tools[cuts_[i].first];
      const Pose to = pose(tool);
      tool.cut_volume = 0.0;
      if (to.position == from_[i].position && to.rotation == from_[i].rotation) continue;  // it did not move
      auto report = sim_.cut_collider(cuts_[i].second.collider, cuts_[i].second.cutter, from_[i], to);
      if (!report) return report.error();
      tool.cut_volume = report->removed_volume;
      removed_ += report->removed_volume;
      for (const auto& range : report->changed_bytes) changed_bytes_ += range[1];
    }
    return {};
  }

  void report(StageProfile& p) const override {
    p.set("removed_mm3", removed_ * 1e9);
    p.set("changed_bytes", static_cast<double>(changed_bytes_));
  }

 private:
  static Pose pose(const ToolBody& t) {
    return {.position = {t.position[0], t.position[1], t.position[2]},
            .rotation = {t.rotation[0], t.rotation[1], t.rotation[2], t.rotation[3]}};
  }
  Simulation::Impl& sim_;
  std::vector<std::pair<std::size_t, ToolCutDesc>> cuts_;  // (tool, what it cuts)
  std::vector<Pose> from_;
  double removed_ = 0.0;
  std::uint64_t changed_bytes_ = 0;
};

}  // namespace

std::unique_ptr<FrameStage> make_tool_cuts_stage(Simulation::Impl& sim, const std::vector<ToolDesc>& tools) {
  std::vector<std::pair<std::size_t, ToolCutDesc>> cuts;
  for (std::size_t t = 0; t < tools.size(); ++t)
    if (tools[t].cuts) cuts.emplace_back(t, *tools[t].cuts);
  if (cuts.empty()) return nullptr;
  return std::make_unique<ToolCutsStage>(sim, std::move(cuts));
}

}  // namespace sinew
