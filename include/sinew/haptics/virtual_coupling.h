// sinew/haptics/virtual_coupling.h — the spring-damper between the haptic
// device and the simulated tool, evaluated every tick.
//
// Virtual coupling: J. E. Colgate, M. C. Stanley, J. M. Brown, "Issues in
// the haptic display of tool use", IROS 1995. The device is never connected
// to the environment directly but through a spring-damper to a simulated
// tool; a passive environment plus a coupling chosen for the device keeps
// the whole loop passive. Sampling matters: a spring held for a period T
// delivers about (K T / 2) * integral |v|^2 dt of energy per closed cycle
// (J. E. Colgate, G. Schenkel, "Passivity of a class of sampled-data
// systems", J. Robotic Systems 1997: with velocities from differences, the
// device's own damping b must exceed K T / 2 + |B|). With the device's
// velocity sampled, as here, the coupling's damper removes B * integral
// |v|^2 dt, so the coupling is passive when B > K T / 2 (0.25 N s/m with
// the defaults at 1 kHz); tests/haptics_coupling_test.cpp measures both terms.
//
// Force and torque on the DEVICE (the user's hand) [N, N m]:
//   F = K (x_tool - x_dev) + B (v_tool - v_dev)
//   T = K_r rotvec(q_tool q_dev^-1) + B_r (w_tool - w_dev)
// rotvec(q) = the rotation vector (axis * angle, angle in [0, pi]) of q.
// The tool receives -F, -T (snapshot_channel.h). Both go through the safety
// chain (force_safety.h). A 3-DOF device (the Touch) renders F only
// (HapticLoopSettings::degrees_of_freedom = 3: it is commanded zero
// torque); the torque still orients the simulated tool.
//
// Defaults for a 3D Systems Touch-class device (3D Systems, "Touch haptic
// device" specification sheet): max exertable force at nominal position
// 3.3 N (the clamp), continuous force 0.88 N (a thermal limit, left to the
// device driver); stiffness X 1.26, Y 2.31, Z 1.02 N/mm: K = 0.5 N/mm, half
// the softest axis.
#pragma once

#include <cstdint>

#include "sinew/haptics/force_safety.h"
#include "sinew/haptics/haptic_device.h"
#include "sinew/haptics/snapshot_interpolator.h"
#include "sinew/result.h"

namespace sinew::haptics {

/// The virtual coupling's spring and damper between the tool and the
/// device (Colgate et al. 1995), and its safety limits (docs/haptics.md).
struct CouplingParams {
  double stiffness = 500.0;               ///< K [N/m], >= 0 (0.5 N/mm)
  double damping = 1.0;                   ///< B [N s/m], >= 0
  double rotational_stiffness = 0.05;     ///< K_r [N m/rad], >= 0
  double rotational_damping = 5e-4;       ///< B_r [N m s/rad], >= 0
  double max_force = 3.3;                 ///< clamp on |F| [N], > 0 (the Touch's peak force)
  double max_force_change = 0.25;         ///< per tick [N], > 0 (250 N/s at 1 kHz)
  double max_torque = 0.5;                ///< clamp on |T| [N m], > 0
  double max_torque_change = 0.05;        ///< per tick [N m], > 0
};
/// Errors name the bad parameter (negative, NaN, zero limits).
Status check(const CouplingParams& params);

/// One tick's coupling.
struct CouplingOutput {
  Vec3 raw_force{};   ///< before the safety chain [N]
  Vec3 raw_torque{};  ///< [N m]
  Vec3 force{};       ///< to the device [N]; the tool gets -force
  Vec3 torque{};      ///< to the device [N m]; the tool gets -torque
  std::uint32_t flags = 0;  ///< TickFlags
};

/// Not thread-safe: owned by the haptic thread.
class VirtualCoupling {
 public:
  explicit VirtualCoupling(const CouplingParams& params)
      : p_(params), force_(params.max_force, params.max_force_change),
        torque_(params.max_torque, params.max_torque_change) {}
  /// The raw coupling, no safety: [in] device sample, [in] rendered tool state.
  [[nodiscard]] CouplingOutput raw(const DeviceSample& device, const RenderedTool& tool) const noexcept;
  /// The coupling through the safety chain. [in] gain: the watchdog's, in [0, 1].
  /// Without a tool state (tool.valid() false) the raw force is zero.
  CouplingOutput evaluate(const DeviceSample& device, const RenderedTool& tool, double gain) noexcept;
  void reset() noexcept { force_.reset(); torque_.reset(); }
  [[nodiscard]] const CouplingParams& params() const { return p_; }

 private:
  CouplingParams p_;
  SafetyFilter force_, torque_;
};

}  // namespace sinew::haptics
