// solve_stage.cpp — the frame's device programs as a stage: the one fixed
// program, or the programs the stepper sequences (residual mode, the
// accelerator, or a SubstepHook: continuous collision).
#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class SolveStage final : public FrameStage {
 public:
  explicit SolveStage(Simulation::Impl& sim) : sim_(sim) {}
  std::string_view name() const override { return "solve"; }

  Status solve(FrameContext& frame) override {
    sim_.positions_mirror.changed();  // whatever the host held is the frame's start
    if (sim_.stepper) return sim_.stepper->run_frame(frame.device, frame.stats, sim_.continuous.get());
    if (Status s = frame.device.run_program(sim_.prepared); !s) return s;
    if (Status s = frame.device.last_run_times(frame.stats.device); !s) return s;
    frame.stats.sweeps = std::uint64_t(sim_.substeps) * std::uint64_t(sim_.iterations);
    return {};
  }


 private:
  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_solve_stage(Simulation::Impl& sim) { return std::make_unique<SolveStage>(sim); }

}  // namespace sinew
