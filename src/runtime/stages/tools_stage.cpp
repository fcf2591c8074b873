// tools_stage.cpp — colliders, targets and rigid tools as a stage
// (simulation_contacts.cpp): before the frame the tools are integrated and
// what moved is uploaded; after the frame's statistics are read, what moved
// settles at its end pose and each tool takes its reaction.
#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class ToolsStage final : public FrameStage {
 public:
  explicit ToolsStage(Simulation::Impl& sim) : sim_(sim) {}
  std::string_view name() const override { return "colliders and tools"; }
  Status before_frame(FrameContext&) override { return sim_.before_frame(); }
  Status after_frame(FrameContext&) override { return sim_.after_frame(); }
  // A grasper's held points may have died with the removed elements.
  Status topology_changed(Device&, TopologyChange&) override {
    if (sim_.graspers) sim_.graspers->invalidate();
    return {};
  }

 private:
  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_tools_stage(Simulation::Impl& sim) { return std::make_unique<ToolsStage>(sim); }

}  // namespace sinew
