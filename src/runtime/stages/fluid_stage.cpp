// fluid_stage.cpp — SceneDesc::fluid as a stage (runtime/scene_fluid.h):
// the fluid's frame before the tissue's, on the same device, its forces in
// the tissue's force buffer; an emitter that outgrew the capacity is
// reported once the tissue's frame is done.
#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class FluidStage final : public FrameStage {
 public:
  explicit FluidStage(Simulation::Impl& sim) : sim_(sim) {}
  std::string_view name() const override { return "fluid"; }
  // After the forces stage: whether the host set forces for this frame.
  Status before_frame(FrameContext&) override { return sim_.fluid->run_frame(sim_.host_forces_this_frame); }
  Status after_frame(FrameContext&) override { return sim_.fluid->pending; }
  std::uint64_t read_back_bytes() const override { return sim_.fluid->read_back_bytes; }

 private:
  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_fluid_stage(Simulation::Impl& sim) { return std::make_unique<FluidStage>(sim); }

}  // namespace sinew
