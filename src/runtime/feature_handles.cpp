// feature_handles.cpp — the handles of sinew/tools.h, graspers.h,
// needles.h and topology.h: each call checks its typed id (not null, of
// this Simulation, in range) and then does what the Simulation's
// index-based call does. Those calls are deprecated for users and kept for
// one release; until they go, their bodies (simulation_contacts.cpp,
// simulation_graspers.cpp, simulation_topology.cpp) are the one
// implementation, so their error messages name them.
#include <string>

#include "runtime/simulation_impl.h"

// The deprecated calls are this file's implementation (above).
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"

namespace sinew {
namespace {

// An id handed to `call`: not null, from this Simulation, one of its
// `count` objects of the kind.
template <class Tag>
Status check_id(const char* call, const char* type, Id<Tag> id, const Simulation::Impl& im, std::size_t count) {
  if (id.is_null())
    return Error(ErrorCode::bad_parameter,
                 std::string(call) + ": a null " + type + " (take ids from the handle, e.g. tools().tool(0))");
  if (id.scene != im.serial)
    return Error(ErrorCode::bad_parameter, std::string(call) + ": the " + type + " belongs to another Simulation (" +
                                               std::to_string(id.scene) + "; this one is " +
                                               std::to_string(im.serial) + ")");
  if (id.index >= count)
    return Error(ErrorCode::bad_parameter, std::string(call) + ": " + type + " " + std::to_string(id.index) +
                                               " is not one of the scene's " + std::to_string(count));
  return {};
}

// The id of object `index` of a kind the scene has `count` of.
template <class Tag>
Result<Id<Tag>> make_id(const char* call, const char* what, std::size_t index, const Simulation::Impl& im,
                        std::size_t count) {
  if (index >= count)
    return Error(ErrorCode::bad_parameter, std::string(call) + ": index " + std::to_string(index) + " is not a " +
                                               what + " (the scene has " + std::to_string(count) + ")");
  return Id<Tag>{static_cast<std::uint32_t>(index), im.serial};
}

std::size_t tool_count(const Simulation::Impl& im) { return im.contacts.tools.size(); }
std::size_t collider_count(const Simulation::Impl& im) { return im.contacts.colliders; }
std::size_t grasper_count(const Simulation::Impl& im) { return im.graspers ? im.graspers->count() : 0; }
std::size_t needle_count(const Simulation::Impl& im) { return im.sutures ? im.sutures->needles() : 0; }
std::size_t tet_bodies(const Simulation::Impl& im) { return im.info.tet_body_first_particle.size(); }
std::size_t tri_bodies(const Simulation::Impl& im) { return im.info.tri_body_first_particle.size(); }
std::size_t line_bodies(const Simulation::Impl& im) { return im.info.line_body_first_particle.size(); }

}  // namespace

Tools Simulation::tools() { return Tools(this); }
Graspers Simulation::graspers() { return Graspers(this); }
Needles Simulation::needles() { return Needles(this); }
Topology Simulation::topology() { return Topology(this); }

// ---- Tools, colliders, targets

Result<ToolId> Tools::tool(std::size_t index) const {
  return make_id<ToolTag>("tools().tool", "tool", index, *sim_->impl_, tool_count(*sim_->impl_));
}
Result<ColliderId> Tools::collider(std::size_t index) const {
  return make_id<ColliderTag>("tools().collider", "collider", index, *sim_->impl_, collider_count(*sim_->impl_));
}
Result<TargetId> Tools::target(std::size_t index) const {
  return make_id<TargetTag>("tools().target", "target", index, *sim_->impl_, sim_->impl_->scene_targets);
}
Status Tools::apply_force(ToolId tool, const std::array<double, 3>& force, const std::array<double, 3>& torque) {
  if (Status s = check_id("tools().apply_force", "ToolId", tool, *sim_->impl_, tool_count(*sim_->impl_)); !s) return s;
  return sim_->apply_tool_force(tool.index, force, torque);
}
Result<ToolState> Tools::state(ToolId tool) const {
  if (Status s = check_id("tools().state", "ToolId", tool, *sim_->impl_, tool_count(*sim_->impl_)); !s)
    return s.error();
  return sim_->tool_state(tool.index);
}
Status Tools::set_pose(ColliderId collider, const std::array<double, 3>& position,
                       const std::array<double, 4>& rotation) {
  if (Status s = check_id("tools().set_pose", "ColliderId", collider, *sim_->impl_, collider_count(*sim_->impl_)); !s)
    return s;
  return sim_->set_collider_pose(collider.index, position, rotation);
}
Result<CutReport> Tools::cut(ColliderId collider, const CutterShape& shape, const Pose& from, const Pose& to) {
  if (Status s = check_id("tools().cut", "ColliderId", collider, *sim_->impl_, collider_count(*sim_->impl_)); !s)
    return s.error();
  return sim_->cut_collider(collider.index, shape, from, to);
}
Status Tools::set_position(TargetId target, const std::array<double, 3>& position) {
  if (Status s = check_id("tools().set_position", "TargetId", target, *sim_->impl_, sim_->impl_->scene_targets); !s)
    return s;
  return sim_->set_target(target.index, position);
}

// ---- Graspers

Result<GrasperId> Graspers::grasper(std::size_t index) const {
  return make_id<GrasperTag>("graspers().grasper", "grasper", index, *sim_->impl_, grasper_count(*sim_->impl_));
}
std::size_t Graspers::count() const { return grasper_count(*sim_->impl_); }
Result<std::vector<std::uint32_t>> Graspers::close(GrasperId grasper, const Pose& pose,
                                                   const std::array<double, 3>& half_extents) {
  if (Status s = check_id("graspers().close", "GrasperId", grasper, *sim_->impl_, count()); !s) return s.error();
  return sim_->close_grasper(grasper.index, pose, half_extents);
}
Status Graspers::move(GrasperId grasper, const Pose& pose) {
  if (Status s = check_id("graspers().move", "GrasperId", grasper, *sim_->impl_, count()); !s) return s;
  return sim_->move_grasper(grasper.index, pose);
}
Result<std::vector<std::uint32_t>> Graspers::open(GrasperId grasper) {
  if (Status s = check_id("graspers().open", "GrasperId", grasper, *sim_->impl_, count()); !s) return s.error();
  return sim_->open_grasper(grasper.index);
}
Result<std::vector<HeldPoint>> Graspers::held_points(GrasperId grasper) const {
  if (Status s = check_id("graspers().held_points", "GrasperId", grasper, *sim_->impl_, count()); !s)
    return s.error();
  return sim_->held_points(grasper.index);
}

// ---- Needles

Result<NeedleId> Needles::needle(std::size_t index) const {
  return make_id<NeedleTag>("needles().needle", "needle", index, *sim_->impl_, needle_count(*sim_->impl_));
}
std::size_t Needles::count() const { return needle_count(*sim_->impl_); }
Status Needles::set_pose(NeedleId needle, const std::array<double, 3>& position,
                         const std::array<double, 4>& rotation) {
  if (Status s = check_id("needles().set_pose", "NeedleId", needle, *sim_->impl_, count()); !s) return s;
  return sim_->set_needle_pose(needle.index, position, rotation);
}
Status Needles::apply_force(NeedleId needle, const std::array<double, 3>& force, const std::array<double, 3>& torque) {
  if (Status s = check_id("needles().apply_force", "NeedleId", needle, *sim_->impl_, count()); !s) return s;
  return sim_->apply_needle_force(needle.index, force, torque);
}
Result<NeedleState> Needles::state(NeedleId needle) const {
  if (Status s = check_id("needles().state", "NeedleId", needle, *sim_->impl_, count()); !s) return s.error();
  return sim_->needle_state(needle.index);
}

// ---- Topology

Result<TetBodyId> Topology::tet_body(std::size_t index) const {
  return make_id<TetBodyTag>("topology().tet_body", "tet body", index, *sim_->impl_, tet_bodies(*sim_->impl_));
}
Result<TriBodyId> Topology::tri_body(std::size_t index) const {
  return make_id<TriBodyTag>("topology().tri_body", "tri body", index, *sim_->impl_, tri_bodies(*sim_->impl_));
}
Result<LineBodyId> Topology::line_body(std::size_t index) const {
  return make_id<LineBodyTag>("topology().line_body", "line body", index, *sim_->impl_, line_bodies(*sim_->impl_));
}
Result<TopologyEvent> Topology::remove_tets(TetBodyId body, std::span<const std::uint32_t> tets) {
  if (Status s = check_id("topology().remove_tets", "TetBodyId", body, *sim_->impl_, tet_bodies(*sim_->impl_)); !s)
    return s.error();
  return sim_->remove_tets(body.index, tets);
}
Result<TopologyEvent> Topology::remove_triangles(TriBodyId body, std::span<const std::uint32_t> triangles) {
  if (Status s = check_id("topology().remove_triangles", "TriBodyId", body, *sim_->impl_, tri_bodies(*sim_->impl_));
      !s)
    return s.error();
  return sim_->remove_triangles(body.index, triangles);
}
Result<TopologyEvent> Topology::remove_segments(LineBodyId body, std::span<const std::uint32_t> segments) {
  if (Status s = check_id("topology().remove_segments", "LineBodyId", body, *sim_->impl_, line_bodies(*sim_->impl_));
      !s)
    return s.error();
  return sim_->remove_segments(body.index, segments);
}
Result<TopologyEvent> Topology::cut(TetBodyId body, const Blade& from, const Blade& to) {
  if (Status s = check_id("topology().cut", "TetBodyId", body, *sim_->impl_, tet_bodies(*sim_->impl_)); !s)
    return s.error();
  return sim_->cut_body(BodyKind::tet, body.index, from, to);
}
Result<TopologyEvent> Topology::cut(TriBodyId body, const Blade& from, const Blade& to) {
  if (Status s = check_id("topology().cut", "TriBodyId", body, *sim_->impl_, tri_bodies(*sim_->impl_)); !s)
    return s.error();
  return sim_->cut_body(BodyKind::tri, body.index, from, to);
}
Result<TopologyEvent> Topology::cauterize(TetBodyId body, const std::array<double, 3>& centre, double radius,
                                          double seconds, double dwell_time) {
  if (Status s = check_id("topology().cauterize", "TetBodyId", body, *sim_->impl_, tet_bodies(*sim_->impl_)); !s)
    return s.error();
  return sim_->cauterize(BodyKind::tet, body.index, centre, radius, seconds, dwell_time);
}
Result<TopologyEvent> Topology::cauterize(TriBodyId body, const std::array<double, 3>& centre, double radius,
                                          double seconds, double dwell_time) {
  if (Status s = check_id("topology().cauterize", "TriBodyId", body, *sim_->impl_, tri_bodies(*sim_->impl_)); !s)
    return s.error();
  return sim_->cauterize(BodyKind::tri, body.index, centre, radius, seconds, dwell_time);
}
const std::vector<TopologyEvent>& Topology::last_tears() const { return sim_->impl_->tears; }
Result<std::vector<std::array<std::uint32_t, 4>>> Topology::current_tets(TetBodyId body) const {
  if (Status s = check_id("topology().current_tets", "TetBodyId", body, *sim_->impl_, tet_bodies(*sim_->impl_)); !s)
    return s.error();
  return sim_->current_tets(body.index);
}
Result<std::vector<std::array<std::uint32_t, 3>>> Topology::current_triangles(TriBodyId body) const {
  if (Status s = check_id("topology().current_triangles", "TriBodyId", body, *sim_->impl_, tri_bodies(*sim_->impl_));
      !s)
    return s.error();
  return sim_->current_triangles(body.index);
}

}  // namespace sinew
