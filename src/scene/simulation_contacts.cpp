// simulation_contacts.cpp — moving colliders and targets between frames,
// and the tools' rigid-body state. (Stage in progress.)
#include "scene/simulation_impl.h"

namespace sinew {

Status Simulation::Impl::init_contacts(const SceneDesc&, const CompiledScene& compiled) {
  colliders = compiled.colliders;
  targets = compiled.targets;
  return {};
}

Status Simulation::Impl::before_frame() { return {}; }
Status Simulation::Impl::after_frame() { return {}; }

Status Simulation::set_collider_pose(std::size_t index, const std::array<double, 3>&, const std::array<double, 4>&) {
  return Error("set_collider_pose: collider " + std::to_string(index) + " does not exist");
}

Status Simulation::set_target(std::size_t index, const std::array<double, 3>&) {
  return Error("set_target: target " + std::to_string(index) + " does not exist");
}

Status Simulation::apply_tool_force(std::size_t index, const std::array<double, 3>&, const std::array<double, 3>&) {
  return Error("apply_tool_force: tool " + std::to_string(index) + " does not exist");
}

Result<Simulation::ToolState> Simulation::tool_state(std::size_t index) const {
  return Error("tool_state: tool " + std::to_string(index) + " does not exist");
}

}  // namespace sinew
