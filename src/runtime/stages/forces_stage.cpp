// forces_stage.cpp — SceneDesc::external_forces as a stage: a frame's
// forces last one frame (Simulation::Impl::begin_frame_forces).
#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class ForcesStage final : public FrameStage {
 public:
  explicit ForcesStage(Simulation::Impl& sim) : sim_(sim) {}
  std::string_view name() const override { return "forces"; }
  Status before_frame(FrameContext&) override { return sim_.begin_frame_forces(); }

 private:
  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_forces_stage(Simulation::Impl& sim) { return std::make_unique<ForcesStage>(sim); }

}  // namespace sinew
