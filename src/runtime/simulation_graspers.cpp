// simulation_graspers.cpp — Simulation's graspers: close, move and open
// (runtime/graspers.h holds them; the program is rebuilt when what they
// hold changes, and their targets ride in the target buffer, uploaded
// before the next frame).
#include <string>

#include "runtime/call_checks.h"
#include "runtime/simulation_impl.h"

namespace sinew {

namespace {

Status check_grasper(const GrasperHolds* graspers, const char* call, std::size_t index) {
  return call_checks::check_index(call, "grasper", index, graspers ? graspers->count() : 0);
}

Status check_pose(const char* call, const Pose& pose) {
  if (Status s = call_checks::check_finite(call, "pose.position", pose.position); !s) return s;
  return call_checks::check_rotation(call, pose.rotation);
}

}  // namespace

Result<std::vector<std::uint32_t>> Simulation::close_grasper(std::size_t index, const Pose& pose,
                                                             const std::array<double, 3>& half_extents) {
  constexpr const char* call = "close_grasper";
  if (Status s = check_grasper(impl_->graspers.get(), call, index); !s) return s.error();
  if (Status s = check_pose(call, pose); !s) return s.error();
  for (int k = 0; k < 3; ++k)
    if (!(half_extents[k] > 0.0) || !std::isfinite(half_extents[k]))
      return Error(ErrorCode::bad_parameter, std::string(call) + ": half_extents[" + std::to_string(k) +
                                                 "] must be > 0 [m] (got " + call_checks::str(half_extents[k]) + ")");
  std::vector<float> x;  // the device's copy: positions and inverse masses, user order
  if (Status s = impl_->read_in_user_order(impl_->buffers.position, x); !s) return s.error();
  GrasperHolds& graspers = *impl_->graspers;
  auto held = graspers.close(*impl_->device, impl_->buffers, impl_->program_shape, impl_->targets, impl_->order,
                             index, pose, half_extents, x, graspers.surface(impl_->topology.get()));
  if (!held) return held.error();
  impl_->contacts.targets_dirty = true;
  if (Status s = impl_->rebuild_program(); !s) return s.error();
  return held;
}

Result<std::vector<HeldPoint>> Simulation::held_points(std::size_t index) const {
  if (Status s = check_grasper(impl_->graspers.get(), "held_points", index); !s) return s.error();
  return impl_->graspers->points(index);
}

Status Simulation::move_grasper(std::size_t index, const Pose& pose) {
  constexpr const char* call = "move_grasper";
  if (Status s = check_grasper(impl_->graspers.get(), call, index); !s) return s;
  if (Status s = check_pose(call, pose); !s) return s;
  impl_->graspers->move(impl_->targets, index, pose);
  impl_->contacts.targets_dirty = true;
  return {};
}

Result<std::vector<std::uint32_t>> Simulation::open_grasper(std::size_t index) {
  if (Status s = check_grasper(impl_->graspers.get(), "open_grasper", index); !s) return s.error();
  const bool was_closed = impl_->graspers->closed(index);
  auto released = impl_->graspers->open(*impl_->device, impl_->buffers, impl_->program_shape, index);
  if (!released) return released.error();
  if (was_closed)
    if (Status s = impl_->rebuild_program(); !s) return s.error();
  return released;
}

}  // namespace sinew
