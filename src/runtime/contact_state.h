// contact_state.h — the host side of contacts that Simulation::Impl keeps
// between frames (simulation_contacts.cpp): which device buffers need an
// upload, the rigid tools' state in double precision and the read-back of
// the contact impulses. Everything is sized in init_contacts; nothing here
// grows per frame.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace sinew {

/// A tool's rigid state.
struct ToolBody {
  using V3 = std::array<double, 3>;
  V3 position{}, velocity{}, angular_velocity{};  ///< [m], [m/s], world [rad/s]
  std::array<double, 4> rotation{1, 0, 0, 0};     ///< unit (w, x, y, z)
  V3 force{}, torque{};                           ///< applied during the next frame [N], [N m]
  V3 contact_force{}, contact_torque{};           ///< the tissue's reaction, last frame's average
  V3 coupling_force{}, coupling_torque{};         ///< the reaction in the last frame's last substep
  /// The particles touching it at the end of the last frame: their mass
  /// [kg] and their inertia about its centre, sum m (|r|^2 I - r r^T)
  /// [kg m^2], world frame, row-major.
  double touching_mass = 0.0;
  std::array<double, 9> touching_inertia{};
  V3 gravity{};  ///< [m/s^2], zero when ToolDesc::gravity is off
  V3 inertia{};  ///< principal moments, body frame [kg m^2]
  double mass = 0.0;  ///< [kg]
};

struct ContactState {
  std::uint32_t colliders = 0;  ///< scene colliders; the tools' entries follow them in the collider buffer
  std::uint32_t substeps = 1, iterations = 1;
  bool colliders_dirty = false;  ///< the collider buffer changed since its last upload
  bool targets_dirty = false;    ///< the target buffer changed since its last upload
  std::vector<ToolBody> tools;
  std::vector<float> impulses;  ///< the contact impulse buffer as read back after each frame
};

}  // namespace sinew
