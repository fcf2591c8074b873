// sutures_stage.cpp — needles and sutures as a stage (runtime/sutures.h):
// the tips' paths tested and the rows uploaded before the frame, punctures
// made and ended after the solve; FrameStats::suture_ms is both.
#include <chrono>

#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class SuturesStage final : public FrameStage {
 public:
  explicit SuturesStage(Simulation::Impl& sim) : sim_(sim) {}
  std::string_view name() const override { return "sutures"; }

  Status before_frame(FrameContext& frame) override {
    const auto start = std::chrono::steady_clock::now();
    if (Status s = sim_.sutures->before_frame(frame.device, sim_.buffers); !s) return s;
    frame.stats.suture_ms = host_ms_ = ms_since(start);
    return {};
  }

  Status after_solve(FrameContext& frame) override {
    const auto start = std::chrono::steady_clock::now();
    if (Status s = sim_.sutures->after_frame(frame.device, sim_.buffers, sim_.time_step / sim_.substeps,
                                             sim_.time_step);
        !s)
      return s;
    host_ms_ += ms_since(start);
    frame.stats.suture_ms = host_ms_;
    return {};
  }

  // A thread runs through its punctures: the remade contacts may not push it out there.
  Status topology_changed(Device&, TopologyChange&) override {
    if (sim_.mesh_collision && sim_.collision_scene) sim_.mesh_collision->set_suture_exemption(sim_.sutures->exemption());
    return {};
  }

  void report(StageProfile& profile) const override { profile.set("host_ms", host_ms_); }


 private:
  Simulation::Impl& sim_;
  double host_ms_ = 0.0;  // reading back, testing the tips, making and ending punctures
};

}  // namespace

std::unique_ptr<FrameStage> make_sutures_stage(Simulation::Impl& sim) { return std::make_unique<SuturesStage>(sim); }

}  // namespace sinew
