// mesh_collision_stage.cpp — contacts between meshes as a stage
// (runtime/mesh_collision.h): found, coloured and uploaded before the frame
// (the program made again when they outgrow it), their violation measured
// after the solve.
#include <chrono>

#include "runtime/stages/stages.h"

namespace sinew {
namespace {

class MeshCollisionStage final : public FrameStage {
 public:
  explicit MeshCollisionStage(Simulation::Impl& sim) : sim_(sim) {}
  std::string_view name() const override { return "mesh collision"; }

  Status before_frame(FrameContext& frame) override {
    const auto start = std::chrono::steady_clock::now();
    MeshCollision& collision = *sim_.mesh_collision;
    bool grew = false;
    if (Status s = collision.before_frame(frame.device, sim_.buffers, sim_.collider_shapes(), sim_.tool_shapes(true),
                                          sim_.tool_shapes(false), grew);
        !s)
      return s;
    if (grew)
      if (Status s = sim_.rebuild_program(); !s) return s;
    frame.stats.mesh_contacts = collision.contacts();
    frame.stats.mesh_contact_colors = collision.colors();
    frame.stats.collision_margin = collision.margin();
    frame.stats.collision_ms = ms_since(start);
    return {};
  }

  Status after_solve(FrameContext& frame) override {
    if (Status s = sim_.mesh_collision->after_frame(frame.device, sim_.buffers); !s) return s;
    frame.stats.contact_violation = sim_.mesh_collision->violation();
    return {};
  }

  void report(StageProfile& profile) const override {
    const MeshCollision& collision = *sim_.mesh_collision;
    profile.set("contacts", collision.contacts());
    profile.set("colors", collision.colors());
    profile.set("margin_m", collision.margin());
    profile.set("violation_m", collision.violation());
  }

  std::uint64_t read_back_bytes() const override { return sim_.mesh_collision->read_back_bytes(); }

 private:
  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_mesh_collision_stage(Simulation::Impl& sim) {
  return std::make_unique<MeshCollisionStage>(sim);
}

}  // namespace sinew
