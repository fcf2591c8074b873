// rigid_tool.cpp — integrating a rigid tool over one frame from the force
// and torque applied to it and the tissue's reaction (the coupling and its
// limits: rigid_tool.h).
#include "runtime/rigid_tool.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "compiler/device_ranges.h"
#include "math/mat3.h"
#include "math/vec3.h"
#include "runtime/trocar.h"

namespace sinew {
namespace {

using math::Quat;
using V3 = math::Vec3;

using M3 = math::Mat3;
using math::solve3;

// One Newton step of implicit Euler on I (w' - w) + dt w' x (I w') = 0 from
// w' = w, in the body frame: w' = w - J^-1 dt w x (I w) with
// J = I + dt (skew(w) I - skew(I w)).
V3 gyroscopic_step(const V3& inertia, const V3& w, double dt) {
  const V3 iw{inertia[0] * w[0], inertia[1] * w[1], inertia[2] * w[2]};
  const V3 f = math::mul(math::cross(w, iw), dt);
  auto skew = [](const V3& v) { return M3{V3{0.0, -v[2], v[1]}, V3{v[2], 0.0, -v[0]}, V3{-v[1], v[0], 0.0}}; };
  const M3 sw = skew(w), siw = skew(iw);
  M3 j;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) j[r][c] = (r == c ? inertia[r] : 0.0) + dt * (sw[r][c] * inertia[c] - siw[r][c]);
  V3 step{0.0, 0.0, 0.0};
  if (!solve3(j, f, step)) return w;
  return math::sub(w, step);
}

// The tool's world inertia R I R^T plus the touching particles' scaled
// inertia about its centre (see integrate_tool).
M3 world_inertia(const ToolBody& b, double stiffness) {
  M3 a;
  for (int c = 0; c < 3; ++c) {
    V3 e{0.0, 0.0, 0.0};
    e[c] = 1.0;
    V3 local = math::rotate(math::conj(b.rotation), e);
    for (int k = 0; k < 3; ++k) local[k] *= b.inertia[k];
    const V3 column = math::rotate(b.rotation, local);
    for (int r = 0; r < 3; ++r) a[r][c] = column[r] + stiffness * b.touching_inertia[3 * r + c];
  }
  return a;
}

// The tool's mass, raised where needed to the least mass that keeps
// explicit Euler inside its stability bound against K (see integrate_tool).
double effective_mass(const ToolBody& b, double stiffness) {
  return std::max(b.mass, 0.25 * stiffness * b.touching_mass);
}

// The trocar's impulse on the tool's velocities at its current pose, added
// to what the port pushed over the frame.
void apply_trocar_impulse(ToolBody& b, double mass, const M3& inverse_inertia, double dt) {
  const V3 u = math::rotate(b.rotation, b.shaft_axis);
  const TrocarImpulse j =
      hold_trocar_velocity(b.pivot, u, b.position, mass, inverse_inertia, b.velocity, b.angular_velocity);
  b.trocar_force = math::add(b.trocar_force, math::mul(j.linear, 1.0 / dt));
  b.trocar_torque = math::add(b.trocar_torque, math::mul(j.angular, 1.0 / dt));
}

}  // namespace

void hold_trocar(ToolBody& b, double dt, double stiffness) {
  if (!b.trocar) return;
  // The shaft straight across onto the pivot (the drift of the rotation's
  // integration, or a collider's push): the axis is kept, so the distance
  // from the pivot to the shaft line is zero to rounding afterwards.
  b.position = math::add(b.position, trocar_offset(b.pivot, math::rotate(b.rotation, b.shaft_axis), b.position));
  M3 inverse;
  if (math::invert3(world_inertia(b, stiffness), inverse))
    apply_trocar_impulse(b, effective_mass(b, stiffness), inverse, dt);
}

// One semi-implicit Euler step of the tool over dt.
//
// The explicit coupling is stable while (omega dt)^2 = k dt^2 / M < 4 for
// the contact's stiffness k. A bound on k: within a substep of length h, a
// touching particle of mass m_i passes on at most about m_i / h^2 per unit
// of the tool's displacement per iteration, so k <= K = n_it sum_i m_i / h^2
// and dt^2 K = n_it n_sub^2 sum_i m_i (and likewise for rotation, with the
// particles' inertia sum_i m_i (|r_i|^2 I - r_i r_i^T) about the tool's
// centre). So:
//  - translation uses the tool's mass M, or dt^2 K / 4 where that is more:
//    a tool heavy enough for the bound is integrated as it is (the tests'
//    10^4 mass ratio is); a lighter one is slowed down (over-damped) rather
//    than thrown off. (Adding dt^2 K to M always, as for rotation, would
//    also let a heavy tool sink deeper before the tissue stops it.)
//  - rotation solves (I_tool + dt^2 K) dw = dt tau: (omega dt)^2 < 1 however
//    small the tool's inertia. That matters for a slender tool, whose
//    inertia about its own axis (m r^2 / 2) is tiny: without it, friction
//    spins the tool up until it rolls away. Rotation while touching is
//    slower than it would be.
// Equilibria are unchanged (no velocity change where the force and torque
// vanish). `stiffness` is n_it n_sub^2.
void integrate_tool(ToolBody& b, double dt, double stiffness) {
  const V3 force = math::add(math::add(b.force, b.coupling_force), math::mul(b.gravity, b.mass));
  const V3 torque = math::add(b.torque, b.coupling_torque);
  // Translation: the tool's own mass, raised where needed to the least
  // mass that keeps explicit Euler inside its stability bound against K:
  // dt^2 K / M <= 4 with dt^2 K = n_it n_sub^2 sum m_i (see above).
  const double mass = effective_mass(b, stiffness);
  for (int k = 0; k < 3; ++k) b.velocity[k] += dt * force[k] / mass;
  // The tool's inertia in the world frame, R I R^T, plus the touching
  // particles' scaled inertia about its centre.
  const M3 a = world_inertia(b, stiffness);
  V3 dw{0.0, 0.0, 0.0};
  if (solve3(a, math::mul(torque, dt), dw))  // a is symmetric positive definite: inertia > 0
    b.angular_velocity = math::add(b.angular_velocity, dw);
  // The gyroscopic term of Euler's equations, I dw/dt = -w x (I w) in the
  // body frame, implicitly by one Newton step (Catto, "Numerical Methods",
  // GDC 2015): explicitly, a free tumbling tool would gain energy.
  b.angular_velocity = math::rotate(
      b.rotation, gyroscopic_step(b.inertia, math::rotate(math::conj(b.rotation), b.angular_velocity), dt));
  // A trocar: the shaft's sideways velocity at the pivot is removed before
  // the pose moves (the velocity half of Cline and Pai's post-stabilisation;
  // trocar.h), so a sideways force turns the tool about the port.
  if (b.trocar) {
    b.trocar_force = b.trocar_torque = V3{0.0, 0.0, 0.0};
    M3 inverse;
    if (math::invert3(a, inverse)) apply_trocar_impulse(b, mass, inverse, dt);
  }

  b.position = math::add(b.position, math::mul(b.velocity, dt));
  // q += dt/2 (0, omega) q, then |q| = 1 again.
  const Quat& q = b.rotation;
  const Quat dq = math::pure_mul(b.angular_velocity, q);
  Quat r;
  for (int k = 0; k < 4; ++k) r[k] = q[k] + 0.5 * dt * dq[k];
  const double norm = math::qnorm(r);
  for (double& c : r) c /= norm;
  b.rotation = r;
  b.force = b.torque = V3{0.0, 0.0, 0.0};
  // The position half: the drift the first-order rotation left, projected
  // out, and the velocity held again at the new pose.
  hold_trocar(b, dt, stiffness);
}

Status add_frame_force(ToolBody& b, const math::Vec3& force, const math::Vec3& torque, double dt, const std::string& who) {
  math::Vec3 total_force{}, total_torque{};
  for (int k = 0; k < 3; ++k) {
    total_force[k] = b.force[k] + force[k];
    total_torque[k] = b.torque[k] + torque[k];
  }
  const double f = std::sqrt(math::dot(total_force, total_force));
  const double t = std::sqrt(math::dot(total_torque, total_torque));
  const double move = dt * dt * f / b.mass;
  const double turn = dt * dt * t / std::min({b.inertia[0], b.inertia[1], b.inertia[2]});
  if (!(move <= kMaxFrameMove) || !(turn <= kMaxFrameMove)) {
    char text[320];
    std::snprintf(text, sizeof text,
                  ": this frame's force %.6g N and torque %.6g N m would move it time_step^2 F / m = %.6g m and turn "
                  "it time_step^2 T / I = %.6g rad in one frame; each must be at most %.6g for the device's float32 "
                  "pose (the forces set before stay)",
                  f, t, move, turn, kMaxFrameMove);
    return Error(ErrorCode::bad_parameter, who + text);
  }
  b.force = total_force;
  b.torque = total_torque;
  return {};
}

}  // namespace sinew
