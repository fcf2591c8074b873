// sinew/haptics/passivity_observer.h — the energy that flows through the
// haptic device's port, tick by tick, and whether the rendered environment
// (coupling, tool, tissue, safety chain, sampling) gave out more than it
// was given.
//
// B. Hannaford, J.-H. Ryu, "Time-domain passivity control of haptic
// interfaces", IEEE Trans. Robotics and Automation 18(1), 2002. A one-port
// is passive when the energy put into it, integrated from the start, never
// goes negative: E(n) = sum_k -(F_{k-1} . dx_k + T_{k-1} . dtheta_k) >= 0,
// where F_{k-1}, T_{k-1} are the force and torque the device was commanded
// at tick k-1 and held until tick k (zero-order hold) [N, N m], and dx_k,
// dtheta_k the device's displacement and rotation vector
// (rotvec(q_k q_{k-1}^-1), world frame) over that interval [m, rad].
// -F . dx is the work the hand does against the device: positive when the
// user pushes energy into the environment (compressing a spring), negative
// when the environment pushes the hand (the spring giving it back).
//
// What counts as "energy created". A conservative spring hands back what it
// stored, so the energy of a window of ticks alone may well be negative
// (the spring relaxing) without anything being created. What a passive
// environment can never do is give out more than it was ever given: the
// criterion is on the cumulative observer since the loop started,
//   violation at tick n  <=>  E(n) < -tolerance,
// and every tick for which it holds is counted. The window energy
// W(n) = E(n) - E(n - window) (the energy put in over the last `window`
// ticks; E before the first tick is 0) and its minimum since the start are
// reported alongside: how much the environment handed back in any
// `window` ticks, i.e. how fast stored energy came out.
//
// What it sees and does not see:
//  - Sampling: a spring K held between ticks of period T is itself active by
//    K/2 sum |dx|^2 per closed cycle (about K T/2 integral |v|^2 dt; Colgate
//    and Schenkel 1997); the observer counts exactly that. The coupling's
//    damper B removes B integral |v|^2 dt, so with B > K T / 2 (the default
//    coupling at 1 kHz) the observer stays positive.
//  - Energy held before the loop started (the device started away from the
//    tool) was never seen going in: its release reads as created energy.
//    So does the watchdog's ramp of the gain on a stretched coupling. Start
//    with the device at the tool.
//  - Energy dissipated earlier is credit: a later active phase is flagged
//    only once it has used that credit up (a property of the cumulative
//    observer of Hannaford and Ryu).
//  - A 3-DOF device (HapticLoopSettings::degrees_of_freedom = 3) is
//    commanded no torque: its rotation exchanges no energy with the port.
//
// The passivity controller (off by default; PassivityParams::controller),
// Hannaford and Ryu's variable damper at the device: before a tick's
// command, the energy including the interval just ended, E(n), and that of
// the coming interval if the device kept its velocity, -T (F . v + T . w),
// are added up; when the sum P is negative, a damper -alpha v (then
// -alpha_r w for what is left) is added to the device's command, with
// alpha |v|^2 T (+ alpha_r |w|^2 T) = -P, each damping at most its
// max_damping. It acts on the device only (the tool's feedback is the
// coupling's), is clamped with the coupling's force to max_force and
// max_torque, but is not slew-limited: it engages at once, as in the paper.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sinew/haptics/snapshot_channel.h"
#include "sinew/result.h"

namespace sinew::haptics {

/// The largest PassivityParams::window: 2^20 ticks (17 min at 1 kHz).
inline constexpr std::size_t kMaxPassivityWindow = std::size_t{1} << 20;

/// How the passivity observer judges and reports (docs/haptics.md).
struct PassivityParams {
  /// Ticks of the sliding window whose energy is reported (TickRecord::window_energy), 1..kMaxPassivityWindow.
  std::size_t window = 100;
  /// [J], finite, >= 0: how far below zero the cumulative energy may go
  /// before a tick counts as a violation (room for rounding and for a
  /// loop that starts slightly stretched).
  double tolerance = 1e-3;
  /// Run the passivity controller (see above): a damper at the device
  /// that dissipates the energy the observer finds missing.
  bool controller = false;
  double max_damping = 5.0;              ///< its largest alpha [N s/m], finite, >= 0
  double max_rotational_damping = 5e-3;  ///< its largest alpha_r [N m s/rad], finite, >= 0
};
/// Errors name the bad parameter.
Status check(const PassivityParams& params);

/// One tick's reading.
struct PassivityReading {
  double energy = 0.0;         ///< E(n): cumulative energy put into the environment [J]
  double window_energy = 0.0;  ///< W(n) = E(n) - E(n - window) [J]
  bool violation = false;      ///< E(n) < -tolerance
};

/// The observer; not thread-safe (owned by the haptic thread). observe()
/// allocates nothing: the window is allocated by the constructor.
class PassivityObserver {
 public:
  /// [in] params: checked by the caller (check()). Throws std::bad_alloc
  /// when the window cannot be allocated (HapticLoop::create catches it).
  explicit PassivityObserver(const PassivityParams& params);

  /// One tick. [in] position [m], rotation (unit quaternion w, x, y, z):
  /// the device's pose now; [in] force [N], torque [N m]: what the device
  /// is commanded now (held until the next tick). The first tick after
  /// construction or reset() only records the pose (no interval yet).
  PassivityReading observe(const Vec3& position, const Quat& rotation, const Vec3& force,
                           const Vec3& torque) noexcept;
  /// The passivity controller (see above), before this tick's observe():
  /// [in] position, rotation, velocity [m/s], angular_velocity [rad/s]: the
  /// device now; [in] period: the tick period T [s]; [in,out] force [N],
  /// torque [N m]: the command, with the damper added; [in] max_force,
  /// max_torque: their clamps; [in] render_torque: false for a 3-DOF
  /// device (no rotational damper). Returns whether a damper was added
  /// (never before the first observe(), never with a zero velocity).
  bool control(const Vec3& position, const Quat& rotation, const Vec3& velocity, const Vec3& angular_velocity,
               double period, double max_force, double max_torque, bool render_torque, Vec3& force,
               Vec3& torque) const noexcept;
  /// Starts over: E = 0, empty window, no previous pose (HapticLoop::stop()).
  void reset() noexcept;

  [[nodiscard]] double energy() const { return energy_; }                  ///< E(n) [J]
  [[nodiscard]] double min_window_energy() const { return min_window_; }   ///< least W(n) so far [J]
  [[nodiscard]] std::uint64_t violations() const { return violations_; }   ///< ticks with E(n) < -tolerance
  [[nodiscard]] const PassivityParams& params() const { return p_; }

 private:
  PassivityParams p_;
  std::vector<double> ring_;  // E(n) of the last `window` ticks, E(n) at n % window
  std::uint64_t n_ = 0;       // ticks observed
  bool have_prev_ = false;
  Vec3 prev_position_{}, prev_force_{}, prev_torque_{};
  Quat prev_rotation_{1.0, 0.0, 0.0, 0.0};
  double energy_ = 0.0, min_window_ = 0.0;
  std::uint64_t violations_ = 0;
};

}  // namespace sinew::haptics
