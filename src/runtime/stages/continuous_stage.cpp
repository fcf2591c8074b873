// continuous_stage.cpp — continuous collision detection as a stage
// (runtime/continuous_collision.h): the tools and capsule colliders over
// the coming frame are handed over before it; the tests themselves run
// inside the solve, after every substep's sweeps (the solve stage passes
// the detector as its SubstepHook), and are reported after it.
#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class ContinuousStage final : public FrameStage {
 public:
  explicit ContinuousStage(Simulation::Impl& sim) : sim_(sim) {}
  std::string_view name() const override { return "continuous collision"; }

  Status before_frame(FrameContext&) override {
    sim_.continuous->begin_frame(sim_.frame_capsules());  // after the tools stage integrated the tools
    return {};
  }

  Status after_solve(FrameContext& frame) override {
    const ContinuousCollision& c = *sim_.continuous;
    frame.stats.ccd_hits = c.hits();
    frame.stats.ccd_repairs = c.repairs();
    frame.stats.ccd_reverted = c.reverted();
    frame.stats.ccd_carried = c.carried();
    frame.stats.ccd_forced = c.forced();
    frame.stats.ccd_ms = c.wall_ms();
    return {};
  }

  // Its segments and triangles are the mesh collision's: made again when
  // that stage (registered before) changed them.
  Status topology_changed(Device&, TopologyChange& change) override {
    if (!change.collision_surface_changed) return {};
    const SceneDesc& scene = *sim_.collision_scene;
    MeshCollision& collision = *sim_.mesh_collision;
    sim_.continuous = std::make_unique<ContinuousCollision>(collision.segments(), collision.triangles(), collision,
                                                            sim_.buffers, scene.mesh_collision, scene.solver.substeps);
    if (sim_.sutures) sim_.continuous->set_suture_exemption(sim_.sutures->exemption());
    return {};
  }

  void report(StageProfile& profile) const override {
    const ContinuousCollision& c = *sim_.continuous;
    profile.set("hits", c.hits());
    profile.set("repairs", c.repairs());
    profile.set("reverted", c.reverted());
    profile.set("carried", c.carried());
    profile.set("forced", c.forced());
  }


 private:
  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_continuous_stage(Simulation::Impl& sim) {
  return std::make_unique<ContinuousStage>(sim);
}

}  // namespace sinew
