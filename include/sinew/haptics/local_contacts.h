// sinew/haptics/local_contacts.h — a local model of the contacts near a
// tool, published by the physics with every frame and solved by the haptic
// thread at every tick, so that contact stiffness is felt at 1 kHz and
// updated at the physics rate.
//
// The intermediate representation of Adachi, Kumano and Ogino ("Intermediate
// representation for stiff virtual objects", IEEE VRAIS 1995) and Mark et
// al. ("Adding force feedback to graphics systems: issues and solutions",
// SIGGRAPH 1996): the physics hands the haptic thread a few planes with a
// stiffness each; the haptic thread solves the tool against them. As in
// SOFA's LCPForceFeedback (Saupin, Duriez, Cotin, "Contact model for haptic
// medical simulations", ISBMS 2008) the planes are compliant: each carries
// the force the physics found and the tissue's stiffness there, so the
// model reproduces the physics at the frame's pose and extrapolates it
// linearly for the hand's motion until the next frame.
//
// The model. At publication the tool's centre is at x0. Contact i is a
// plane through `point` with unit `normal` n_i (from the tissue towards the
// tool), a signed `gap` g_i (how far the tool's surface is from the plane
// along n_i at x0; negative: pressed in) and a stiffness k_i [N/m]. With the
// tool's centre at x the tissue pushes along n_i with
//   lambda_i(x) = max(0, -k_i (g_i + n_i . (x - x0)))            [N]
// A contact the physics reports a force f_i > 0 on has g_i = -f_i / k_i, so
// lambda_i(x0) = f_i. The haptic tick places the tool's proxy x where the
// virtual coupling's spring K to the device position a balances the
// contacts, the minimum of the convex energy
//   E(x) = K/2 |x - a|^2 + sum_i k_i/2 max(0, -(g_i + n_i . (x - x0)))^2
// and renders the spring's force on the device, F = K (x - a) = sum_i
// lambda_i n_i: in free space x = a (nothing rendered), against one plane
// the force rises at K k / (K + k) per metre the hand moves in. F = -dV/da
// with V(a) = min_x E(x): within one frame the rendering is conservative
// (a potential), so the hand can take out only what it put in.
//
// Header-only data (the snapshot channel carries it); the solver is in
// src/haptics/local_contacts.cpp and allocates nothing (tick-safe).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace sinew::haptics {

/// The most contacts a LocalContactModel holds.
inline constexpr std::size_t kMaxLocalContacts = 8;

/// One contact plane near a tool (8-byte fields: it travels through a SeqlockChannel).
struct LocalContact {
  std::array<double, 3> point{};   ///< on the tissue's surface at publication [m]
  std::array<double, 3> normal{};  ///< unit, from the tissue towards the tool
  double gap = 0.0;                ///< of the tool's surface from the plane at x0, along normal [m]; < 0: pressed in
  double stiffness = 0.0;          ///< of the tissue there [N/m], > 0
  double force = 0.0;              ///< the physics' push along normal at publication [N], >= 0
  double friction = 0.0;           ///< Coulomb coefficient of the tool's contacts (published, not rendered by solve_local_contacts)
  std::uint64_t body = 0;          ///< the tet body it lies on (SceneDesc::tet_bodies index)
};

/// The contacts near one tool at the end of one physics frame.
struct LocalContactModel {
  std::uint64_t count = 0;                ///< contacts used, <= kMaxLocalContacts
  std::array<double, 3> tool_position{};  ///< the tool's centre x0 the gaps are measured at [m]
  std::array<LocalContact, kMaxLocalContacts> contacts{};
};

/// The proxy a tick renders (solve_local_contacts).
struct LocalContactSolution {
  std::array<double, 3> proxy{};   ///< the tool's centre x where coupling and contacts balance [m]
  std::array<double, 3> force{};   ///< sum_i lambda_i n_i: the tissue's push on the tool = the device force [N]
  /// dx/da: how the proxy moves with the device (row-major 3x3); the
  /// identity in free space. proxy velocity = sensitivity * device velocity.
  std::array<double, 9> sensitivity{1, 0, 0, 0, 1, 0, 0, 0, 1};
  double energy = 0.0;             ///< V(a) = E(proxy): the energy stored in coupling and contacts [J]
  std::uint32_t active = 0;        ///< contacts pushing (lambda_i > 0)
  std::uint32_t iterations = 0;    ///< active-set Newton steps taken
  bool converged = true;           ///< false: the active set still changed at the step cap (the last iterate is returned)
};

/// Minimises E(x) (above) by Newton's method on the active set (each step
/// a 3x3 solve; at most 2 kMaxLocalContacts + 2 steps). [in] model: count
/// <= kMaxLocalContacts, normals unit, stiffness > 0 (a contact that is
/// not is skipped); [in] device: a [m]; [in] coupling_stiffness: K [N/m], > 0;
/// [in] gap_offset: added to every contact's gap [m] (LocalContactRenderer).
/// Non-finite input gives non-finite output (the safety chain zeroes it).
/// noexcept and allocation-free: called inside the haptic tick.
LocalContactSolution solve_local_contacts(const LocalContactModel& model, const std::array<double, 3>& device,
                                          double coupling_stiffness, double gap_offset = 0.0) noexcept;

/// The haptic tick's side of the model over time: adopts each new frame's
/// model and keeps the rendering passive across the switches.
///
/// Why: within one model the rendering is a potential V(a), but a new
/// frame's model can store more energy at the same device position than
/// the old one did (the tissue stiffer than the plane's k, or the solver
/// still converging while the hand holds still): handed to the hand, that
/// energy would be created. So, as in the time-domain passivity of
/// Hannaford and Ryu ("Time-domain passivity control of haptic
/// interfaces", IEEE Trans. Robotics and Automation 18(1), 2002), each tick
/// keeps the energy account: the stored energy may rise by no more than the
/// hand put in over the tick, V_k <= V_{k-1} - F_{k-1} . (a_k - a_{k-1})
/// with F_{k-1} the force commanded over the tick. A model that would store
/// more is backed off by a gap offset (every plane moved away from the tool
/// by the same distance, found by bisection); the offset shrinks again as
/// the hand's motion and the coupling's damping leave room. Every tick thus
/// creates no energy, so no window of ticks does. The price: while the
/// hand holds still the rendered force may stay below a model that grew
/// (by what the last switches would have created).
class LocalContactRenderer {
 public:
  /// [in] newest: the newest snapshot's model and its sequence number (a
  /// new sequence adopts the model); [in] device: a [m]; [in] commanded:
  /// the force commanded to the device since the previous call [N];
  /// [in] coupling_stiffness: K [N/m]. The solution at the offset used.
  LocalContactSolution render(const LocalContactModel& newest, std::uint64_t sequence,
                              const std::array<double, 3>& device, const std::array<double, 3>& commanded,
                              double coupling_stiffness) noexcept;
  /// Forgets the model and the energy account (the loop restarts).
  void reset() noexcept { *this = LocalContactRenderer{}; }
  /// The gap offset in use [m], >= 0.
  [[nodiscard]] double gap_offset() const { return offset_; }

 private:
  LocalContactModel model_{};
  std::uint64_t sequence_ = 0;
  double offset_ = 0.0;
  double energy_ = 0.0;  // V at the previous call
  std::array<double, 3> device_{};
  bool started_ = false;
};

}  // namespace sinew::haptics
