// sinew/haptics/snapshot_channel.h — what the physics thread and the haptic
// thread hand each other, through lock-free SeqlockChannels:
//   physics -> haptics: a HapticSnapshot after every frame (SnapshotChannel);
//   haptics -> physics: a CouplingFeedback after every tick (FeedbackChannel).
// Both are fixed-size plain structs of 8-byte fields (no pointers, no
// allocation), so publishing or reading one is a bounded copy.
// Header-only (the ThreadSanitizer test uses it without libsinew).
//
// Sign convention (used by every haptics header): `force` and `torque` in
// CouplingFeedback and in the device commands are what the virtual coupling
// applies to the *device* (the surgeon's hand). The simulated tool receives
// the opposite: the physics thread calls
//   Simulation::apply_tool_force(tool, -average force, -average torque).
#pragma once

#include <array>
#include <cstdint>

#include "sinew/haptics/local_contacts.h"
#include "sinew/haptics/seqlock_channel.h"

namespace sinew::haptics {

using Vec3 = std::array<double, 3>;  ///< [m], [m/s], [N], ... in the simulation's world frame
using Quat = std::array<double, 4>;  ///< unit quaternion (w, x, y, z)

/// The tool's state at the end of one physics frame (physics -> haptics).
struct HapticSnapshot {
  std::uint64_t sequence = 0;  ///< 1, 2, 3, ... one per publication
  std::int64_t stamp_ns = 0;   ///< when it was published, on the haptic loop's clock [ns]
  double sim_time = 0.0;       ///< simulated time at the end of the frame [s]
  std::uint64_t frame = 0;     ///< frames done
  Vec3 position{};             ///< tool centre [m]
  Quat rotation{1.0, 0.0, 0.0, 0.0};  ///< tool orientation (w, x, y, z)
  Vec3 velocity{};             ///< [m/s]
  Vec3 angular_velocity{};     ///< world frame [rad/s]
  /// Local contact for force rendering: what the tissue pushed the tool
  /// with over the frame (average) [N], its torque about the tool centre
  /// [N m], and the contact normal (unit, the direction of contact_force,
  /// pointing from the tissue to the tool; zero when not in contact).
  ///@{
  Vec3 contact_force{};
  Vec3 contact_torque{};
  Vec3 contact_normal{};
  ///@}
  std::uint64_t in_contact = 0;  ///< 1 when |contact_force| > 0
  /// The contacts near the tool as planes for the haptic thread to solve
  /// at every tick (local_contacts.h; HapticLoopSettings::local_contacts);
  /// count 0 when the bridge publishes none.
  LocalContactModel local_contacts{};
};

/// What the haptic loop produced (haptics -> physics), published every tick.
/// The physics thread averages the device force over its frame from two
/// readings a and b: (b.impulse - a.impulse) / (b.time - a.time), which is
/// exact (zero-order hold) however many ticks fell between the readings,
/// provided both come from the same loop (same `loop`): each HapticLoop
/// integrates from its own zero.
struct CouplingFeedback {
  std::uint64_t loop = 0;       ///< which HapticLoop published it: 1, 2, ... one per loop created in the process
  std::uint64_t ticks = 0;      ///< ticks done (the newest tick's number)
  std::int64_t time_ns = 0;     ///< start of the newest tick, on the loop's clock [ns]
  Vec3 impulse{};               ///< integral of the coupling force (`force`) up to time_ns [N s]
  Vec3 angular_impulse{};       ///< integral of the coupling torque up to time_ns [N m s]
  /// The newest tick's coupling force between the device and the tool [N]
  /// (held until the next), whose opposite the tool gets; the device was
  /// commanded it too, unless the loop renders local contacts
  /// (HapticLoopSettings::local_contacts: the device then gets
  /// rendered_force). `impulse` integrates this force.
  Vec3 force{};
  Vec3 torque{};                ///< the coupling's torque of the newest tick [N m]
  Vec3 rendered_force{};        ///< what the device was commanded in the newest tick [N]
  Vec3 device_position{};       ///< newest device sample [m]
  Quat device_rotation{1.0, 0.0, 0.0, 0.0};  ///< newest device sample's orientation
  double gain = 0.0;            ///< watchdog gain of the newest tick, in [0, 1]
  std::uint64_t flags = 0;      ///< TickFlags of the newest tick
};

using SnapshotChannel = SeqlockChannel<HapticSnapshot>;
using FeedbackChannel = SeqlockChannel<CouplingFeedback>;

}  // namespace sinew::haptics
