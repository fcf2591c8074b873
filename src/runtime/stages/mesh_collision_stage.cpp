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
    // Coloured on the device, the colours are known after the solve (MeshCollision::take_counters).
    frame.stats.mesh_contact_colors = sim_.mesh_collision->colors();
    frame.stats.mesh_contact_overflow = sim_.mesh_collision->overflow();
    return {};
  }

  // The collision surface follows in place: each tet body's boundary from
  // the tets that died, the tri and line bodies that changed replaced (a
  // whole remake took 20 ms on a 50,400-tet block; MeshCollision::update_topology).
  Status topology_changed(Device& device, TopologyChange& change) override {
    if (!sim_.collision_scene) return {};  // made without topology changes
    const TopologyEditor& topology = *sim_.topology;
    SceneDesc& scene = *sim_.collision_scene;
    for (std::size_t b = 0; b < topology.sheets(); ++b)  // each tri body's live triangles
      scene.tri_bodies[b].mesh.triangles = topology.live_triangles(b);
    for (std::size_t b = 0; b < topology.line_bodies(); ++b) {  // and each line body's whole segments
      auto& segments = scene.line_bodies[b].segments;
      segments.clear();
      for (std::size_t s = 0; s < topology.whole(b).size(); ++s)
        if (topology.whole(b)[s]) segments.push_back(topology.line(b).segments[s]);
    }
    std::vector<const std::vector<std::uint8_t>*> alive;
    for (std::size_t b = 0; b < topology.bodies(); ++b) alive.push_back(&topology.alive(b));
    return sim_.mesh_collision->update_topology(device, scene, alive, change.collision_surface_changed);
  }

  void report(StageProfile& profile) const override {
    const MeshCollision& collision = *sim_.mesh_collision;
    profile.set("contacts", collision.contacts());
    profile.set("colors", collision.colors());
    profile.set("overflow", collision.overflow());
    profile.set("pairs", static_cast<double>(collision.candidate_pairs()));
    profile.set("pairs_capacity", static_cast<double>(MeshCollision::pair_capacity()));
    profile.set("margin_m", collision.margin());
    profile.set("violation_m", collision.violation());
    profile.set("self_violation_m", collision.self_violation());
    profile.set("tool_violation_m", collision.tool_violation());
  }


 private:
  Simulation::Impl& sim_;
};

}  // namespace

std::unique_ptr<FrameStage> make_mesh_collision_stage(Simulation::Impl& sim) {
  return std::make_unique<MeshCollisionStage>(sim);
}

}  // namespace sinew
