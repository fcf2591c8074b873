// fluid_stage.cpp — SceneDesc::fluid as a stage (runtime/scene_fluid.h):
// the fluid's frame before the tissue's, on the same device, its forces in
// the tissue's force buffer; an emitter that outgrew the capacity is
// reported once the frame is done (FrameContext::deferred).
#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class FluidStage final : public FrameStage {
 public:
  explicit FluidStage(Simulation::Impl& sim) : sim_(sim) {}
  std::string_view name() const override { return "fluid"; }
  // After the forces stage: whether the host set forces for this frame.
  Status before_frame(FrameContext& frame) override {
    if (Status s = sim_.fluid->run_frame(sim_.host_forces_this_frame); !s) return s;
    if (!sim_.fluid->pending) frame.deferred = sim_.fluid->pending;
    return {};
  }
  void report(StageProfile& profile) const override {
    profile.set("particles", sim_.fluid->solver->stats().particles);
    profile.set("particles_capacity", sim_.fluid->solver->capacity());
    profile.set("steps", sim_.fluid->info.steps_per_frame);
  }

 private:
  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_fluid_stage(Simulation::Impl& sim) { return std::make_unique<FluidStage>(sim); }

}  // namespace sinew
