// src/haptics/virtual_coupling.cpp — the virtual coupling of Colgate,
// Stanley and Brown, "Issues in the haptic display of tool use", IROS 1995:
// a spring-damper between device and simulated tool, evaluated each tick.
// Formulas and sign convention in sinew/haptics/virtual_coupling.h.
#include "sinew/haptics/virtual_coupling.h"

#include <cmath>
#include <string>

#include "math/vec3.h"

namespace sinew::haptics {

namespace {
// v must be finite and >= 0 (or > 0 when strict).
Status at_least(const char* name, double v, double lo, bool strict, const char* unit) {
  const bool ok = std::isfinite(v) && (strict ? v > lo : v >= lo);
  if (!ok)
    return Error(ErrorCode::bad_parameter,
                 std::string("coupling.") + name + " must be finite and " + (strict ? "> 0" : ">= 0") + " [" + unit +
                 "] (got " + std::to_string(v) + ")");
  return {};
}
}  // namespace

Status check(const CouplingParams& p) {
  if (auto s = at_least("stiffness", p.stiffness, 0, false, "N/m"); !s) return s;
  if (auto s = at_least("damping", p.damping, 0, false, "N s/m"); !s) return s;
  if (auto s = at_least("rotational_stiffness", p.rotational_stiffness, 0, false, "N m/rad"); !s) return s;
  if (auto s = at_least("rotational_damping", p.rotational_damping, 0, false, "N m s/rad"); !s) return s;
  if (auto s = at_least("max_force", p.max_force, 0, true, "N"); !s) return s;
  if (auto s = at_least("max_force_change", p.max_force_change, 0, true, "N per tick"); !s) return s;
  if (auto s = at_least("max_torque", p.max_torque, 0, true, "N m"); !s) return s;
  return at_least("max_torque_change", p.max_torque_change, 0, true, "N m per tick");
}

CouplingOutput VirtualCoupling::raw(const DeviceSample& device, const RenderedTool& tool) const noexcept {
  CouplingOutput out;
  if (!tool.valid()) return out;
  // Force on the device: the spring pulls the hand towards the tool, the
  // damper resists their relative velocity. The tool gets the opposite.
  out.raw_force = math::add(math::mul(math::sub(tool.position, device.position), p_.stiffness),
                          math::mul(math::sub(tool.velocity, device.velocity), p_.damping));
  const Vec3 twist = math::rotation_vector(math::qmul(tool.rotation, math::conj(device.rotation)));
  out.raw_torque = math::add(math::mul(twist, p_.rotational_stiffness),
                           math::mul(math::sub(tool.angular_velocity, device.angular_velocity), p_.rotational_damping));
  // A NaN quaternion gives a NaN twist; make sure the chain sees it.
  if (!math::finite(device.rotation) || !math::finite(tool.rotation)) out.raw_torque[0] = std::nan("");
  return out;
}

CouplingOutput VirtualCoupling::evaluate(const DeviceSample& device, const RenderedTool& tool, double gain) noexcept {
  CouplingOutput out = raw(device, tool);
  // A NaN/Inf anywhere (device, snapshot, parameters) zeroes force and torque alike.
  if (!math::finite(out.raw_force) || !math::finite(out.raw_torque)) {
    const double nan = std::nan("");
    const Vec3 bad{nan, nan, nan};
    out.force = force_.apply(bad, gain, out.flags);
    out.torque = torque_.apply(bad, gain, out.flags);
    return out;
  }
  out.force = force_.apply(out.raw_force, gain, out.flags);
  out.torque = torque_.apply(out.raw_torque, gain, out.flags);
  return out;
}

}  // namespace sinew::haptics
