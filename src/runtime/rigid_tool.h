// rigid_tool.h — the rigid tools' state and their integration from the
// tissue's reaction, in double precision on the host.
//
// A tool is a capsule or level-set collider whose motion the host
// integrates, here; the tissue's side (its collider entry, the contact
// impulses and their reduction to the tool's reaction) is in
// simulation_contacts.cpp, a level-set tool's penalty against colliders and
// tools in tool_penalty.h. The
// coupling with the tissue is explicit and one frame long:
//  1. before frame n (Simulation::Impl::before_frame calls integrate_tool):
//     semi-implicit Euler over the frame with the applied force and torque
//     (apply_tool_force), gravity, and the tissue's reaction measured in
//     frame n-1: v += dt F / M, x += dt v; the angular velocity likewise
//     from the torque (inertia in the body frame, the gyroscopic term
//     implicit), q += dt/2 (0, omega) q. The tool's collider then moves
//     from its old to its new pose across frame n's substeps. A tool
//     through a trocar is held through its pivot after that motion and
//     again after its contacts with the colliders (hold_trocar; trocar.h).
//  2. during frame n the tool is an infinitely heavy kinematic collider: the
//     particles it touches are pushed out and dragged by friction, and each
//     correction's impulse (with its moment about the tool's centre) is
//     summed per particle and tool in the contact-impulse buffer.
//  3. at the end of frame n the sums are reduced on the device in a fixed
//     order, in double-float precision (program/stats_program.h), and read
//     back after it (Simulation::Impl::after_frame) as the frame's average
//     contact force and torque (reported by tool_state) and the force and
//     torque of the frame's last substep, which step 1 uses: that one
//     belongs to the pose the tool has at the end of the frame, so the
//     scheme is symplectic Euler on the tool. (Coupling with the frame
//     average, which belongs to the middle of the frame, lags half a frame
//     and pumps energy into the tool at any mass:
//     x_{n+1} - 2 x_n + x_{n-1} = -(omega dt)^2 (x_n + x_{n-1}) / 2 has
//     roots of modulus sqrt(1 + (omega dt)^2 / 2) > 1.)
// Limits.
//  - Stability: explicit Euler on a contact of stiffness k is stable while
//    sqrt(k / M) dt < 2. That holds for a tool much heavier than the
//    particles it touches. A slender tool's tiny inertia about its own axis
//    would break it in rotation, so rotation is stabilised by the touching
//    particles' inertia; a light tool would break it in translation, so its
//    mass is floored at what the bound needs (see integrate_tool()). Neither
//    makes a light tool right: the tissue is pushed by the tool's full
//    motion as if the tool were immovable and answers a frame later. In the
//    tests' scene (20 substeps at 60 Hz) a tool 10^4 times as heavy as a
//    particle rests; one 3 10^3 times or lighter is not held: it drifts
//    sideways and slides off the block within a few seconds (without the
//    mass floor, one 10^2 times as heavy was thrown off at 1.8 m/s). Drive a
//    light or hand-held tool through a virtual coupling (a spring-damper
//    from the user's pose, via apply_tool_force, stiff no more than the
//    bound allows) or use a shorter time step.
//  - Tunnelling: without mesh collision, contacts are between particles
//    (mesh vertices) and the tool's surface, not the tissue's faces. A tool
//    M times as heavy as the N particles of mass m it rests on pushes them
//    about (M / (N m)) g h^2 / iterations deep per substep before the
//    tissue's response reaches them; when that nears the vertex spacing, or
//    a tool is narrower than it, the tool pushes vertices apart and passes
//    between them. More substeps (smaller h) or a finer surface mesh cure
//    it. With mesh collision on (SceneDesc::mesh_collision) the tissue's
//    triangles and thread segments meet the tool too, and their reaction
//    joins the particles' (runtime/mesh_collision.h, add_tool_reactions),
//    read back per contact after the frame.
//  - A resting tool keeps a small jitter (no damping is added); compare
//    averages of tool_state over a few frames.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "math/vec3.h"
#include "sinew/result.h"

namespace sinew {

/// A tool's rigid state.
struct ToolBody {
  using V3 = math::Vec3;
  V3 position{}, velocity{}, angular_velocity{};  ///< [m], [m/s], world [rad/s]
  math::Quat rotation{1, 0, 0, 0};                ///< unit (w, x, y, z)
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
  double radius = 0.0, half_height = 0.0;  ///< its capsule [m] (the segment +-half_height along its y)
  double dynamic_friction = 0.0;          ///< against colliders and other tools (tool_contacts.h)

  // A level-set tool (ToolShape::level_set): its penalty against the
  // colliders and the other tools (tool_penalty.h).
  bool level_set = false;
  std::vector<V3> points;      ///< its surface points in its frame [m]
  std::vector<double> areas;   ///< the area each stands for [m^2]
  double penalty_stiffness = 0.0, penalty_damping = 0.0;  ///< [N/m^3], [N s/m^3]
  V3 penalty_force{}, penalty_torque{};  ///< at the start of the last frame [N], about its centre [N m]
  std::uint32_t penalty_points = 0;      ///< its points inside another shape then
  double penalty_depth = 0.0;            ///< the deepest one's depth [m]

  // A tool through a trocar (ToolDesc::trocar; trocar.h).
  bool trocar = false;
  V3 pivot{};                  ///< world [m]
  V3 shaft_axis{0.0, 1.0, 0.0};  ///< unit, tool frame
  V3 trocar_force{}, trocar_torque{};  ///< the port's push over the last frame [N], about its centre [N m]

  double cut_volume = 0.0;  ///< a cutting tool's (ToolDesc::cuts) removed volume in the last frame [m^3]
};

/// One semi-implicit Euler step of the tool over dt [s] from the applied
/// force and torque (then reset to zero), gravity and the last frame's
/// coupling force and torque, stabilised by the touching particles' mass and
/// inertia (see rigid_tool.cpp). `stiffness` is n_it n_sub^2 (iterations
/// times substeps squared).
/// A tool with a trocar is then held through its pivot (hold_trocar).
void integrate_tool(ToolBody& b, double dt, double stiffness);

/// A tool with a trocar (b.trocar): moves it straight across its shaft so
/// the shaft line passes through the pivot, then removes the sideways
/// velocity of its point at the pivot by an impulse there, through the
/// mass and inertia integrate_tool uses (trocar.h); the impulse over [in]
/// dt [s] is added to b.trocar_force and b.trocar_torque. Nothing without a trocar.
void hold_trocar(ToolBody& b, double dt, double stiffness);

/// Adds [in] force [N] and torque [N m] to what acts on `b` during the
/// next frame of [in] dt [s] (calls before one frame add up). Errors
/// (bad_parameter, "<who>: ...", b unchanged): a total that would move the
/// body more than kMaxFrameMove in the frame (dt^2 |F| / m) or turn it more
/// than that many radians (dt^2 |T| / I, the least moment): the device
/// holds its pose in float32.
Status add_frame_force(ToolBody& b, const math::Vec3& force, const math::Vec3& torque, double dt, const std::string& who);

}  // namespace sinew
