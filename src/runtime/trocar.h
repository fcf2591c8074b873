// trocar.h — a rigid tool's shaft held through a fixed pivot (a
// laparoscopic port): the geometry of the constraint and the impulse that
// removes the shaft's sideways velocity at the pivot.
//
// The constraint: the shaft line c + u s (u = R axis, world frame) passes
// through the pivot p. Its error is the part of p - c across the shaft,
// d = (p - c) - u (u . (p - c)), zero when held. Its velocity is the
// sideways velocity of the tool's point on the shaft at the pivot,
// r = u (u . (p - c)) from the centre: v_p = v + w x r, less its part along
// u (sliding through the port is free). An impulse J across the shaft at
// that point changes v by J / m and w by A^-1 (r x J) (A the world inertia);
// J solves the 2x2 system K J = -v_p across the shaft, with
// K J = J / m + (A^-1 (r x J)) x r (the point's generalised inverse mass),
// so v_p is zero afterwards. Post-stabilisation: Cline and Pai,
// "Post-stabilization for rigid body simulation with contact and
// constraints", ICRA 2003 (velocity held by an impulse, position projected).
#pragma once

#include "math/mat3.h"
#include "math/vec3.h"

namespace sinew {

/// The impulse a trocar applied: on the tool's centre [N s] and its moment about it [N m s].
struct TrocarImpulse {
  math::Vec3 linear{}, angular{};
};

/// The constraint error d = (p - c) - u (u . (p - c)) [m] for the pivot p,
/// the shaft's world direction u = R axis (unit) and the tool's centre c;
/// |d| is the distance from the pivot to the shaft line.
math::Vec3 trocar_offset(const math::Vec3& pivot, const math::Vec3& world_axis, const math::Vec3& centre);

/// Removes the sideways velocity at the pivot of a body at `centre` with
/// shaft direction `world_axis` (unit): [in,out] velocity, angular_velocity;
/// [in] mass [kg]; [in] inverse_inertia: A^-1, world frame, row-major.
/// Returns the impulse applied (zero when K is singular: never for m, A > 0).
TrocarImpulse hold_trocar_velocity(const math::Vec3& pivot, const math::Vec3& world_axis, const math::Vec3& centre,
                                   double mass, const math::Mat3& inverse_inertia,
                                   math::Vec3& velocity, math::Vec3& angular_velocity);

}  // namespace sinew
