// statistics_stage.cpp — the frame's statistics as a stage: the device's
// reductions (program/stats_program.h), which come back with the solve's
// last wait, taken after the solve (the tools' reactions among them, which
// the tools stage takes after it), the errors combined after the frame. FrameStats::measure_ms is this stage's time.
#include <chrono>

#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class StatisticsStage final : public FrameStage {
 public:
  explicit StatisticsStage(Simulation::Impl& sim) : sim_(sim) {}
  std::string_view name() const override { return "statistics"; }

  Status after_solve(FrameContext& frame) override {
    const auto start = std::chrono::steady_clock::now();
    // The results came back with the wait that ended the solve's last
    // program (its end read): no round trip of their own.
    if (Status s = collect_stats(frame.device, sim_.stats_plan); !s) return s;
    if (Status s = read_stats(sim_.stats_plan, sim_.device_stats); !s) return s;
    frame.stats.measure_ms = ms_since(start);
    return {};
  }

  // The measured volume is the live tets' (Simulation::Impl::refresh_volume).
  Status topology_changed(Device&, TopologyChange& change) override {
    if (!sim_.measure_errors || change.event.body_kind != BodyKind::tet) return {};
    return sim_.refresh_volume(change.event);
  }

  Status after_frame(FrameContext& frame) override {
    const auto start = std::chrono::steady_clock::now();
    if (sim_.measure_errors) sim_.measure(frame.stats);
    frame.stats.measure_ms += ms_since(start);
    return {};
  }


 private:
  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_statistics_stage(Simulation::Impl& sim) {
  return std::make_unique<StatisticsStage>(sim);
}

}  // namespace sinew
