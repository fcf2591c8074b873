// tool_fields.h — a rigid body's state that changes while the scene runs
// (rigid_tool.h's ToolBody: a rigid tool's, a force-driven needle's),
// visited field by field in one order: a saved state writes and reads it
// with the same visit (simulation_state.cpp, sutures_state.cpp).
#pragma once

#include "runtime/rigid_tool.h"

namespace sinew {

template <class Tool, class Visit>
void tool_fields(Tool& t, Visit visit) {
  for (auto* v : {&t.position, &t.velocity, &t.angular_velocity, &t.force, &t.torque, &t.contact_force,
                  &t.contact_torque, &t.coupling_force, &t.coupling_torque, &t.penalty_force, &t.penalty_torque})
    visit(*v);
  visit(t.rotation);
  visit(t.touching_mass);
  visit(t.touching_inertia);
  visit(t.penalty_points);
  visit(t.penalty_depth);
}

}  // namespace sinew
