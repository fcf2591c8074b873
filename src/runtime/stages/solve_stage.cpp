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
    if (Status s = run(frame); !s) return s;
    // The contacts' device colours came back with the last program's wait
    // (its counters): taken now, before a later stage runs another program.
    if (sim_.mesh_collision) return sim_.mesh_collision->take_counters(frame.device.counters());
    return {};
  }


 private:
  Status run(FrameContext& frame) {
    if (sim_.stepper) return sim_.stepper->run_frame(frame.device, frame.stats, sim_.continuous.get());
    if (Status s = frame.device.run_program(sim_.prepared); !s) return s;
    if (Status s = frame.device.last_run_times(frame.stats.device); !s) return s;
    frame.stats.sweeps = std::uint64_t(sim_.substeps) * std::uint64_t(sim_.iterations);
    return {};
  }

  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_solve_stage(Simulation::Impl& sim) { return std::make_unique<SolveStage>(sim); }

}  // namespace sinew
