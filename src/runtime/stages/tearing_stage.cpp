// tearing_stage.cpp — tearing as a stage (SceneDesc::topology_changes with a
// tear strain): after the frame, the elements stretched past it are removed
// (Simulation::Impl::tear); the next frame runs without them.
#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class TearingStage final : public FrameStage {
 public:
  explicit TearingStage(Simulation::Impl& sim) : sim_(sim) {}
  std::string_view name() const override { return "tearing"; }
  Status after_frame(FrameContext&) override { return sim_.tear(); }

 private:
  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_tearing_stage(Simulation::Impl& sim) { return std::make_unique<TearingStage>(sim); }

}  // namespace sinew
