// contact_kernels.h — CPU reference kernels of attachments and contacts with
// analytic colliders, and the geometry they share with the tests: collider
// poses interpolated across a frame and the signed distance of each shape.
// The layouts and the formulation are documented in
// kernels/shared/contact_params.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cpu/cpu_kernels.h"  // the kernel entry points, declared from the registry
#include "contact_params.h"
#include "math/vec4.h"

namespace sinew::kernels {

/// A rigid pose: position p [m] (w unused) and unit quaternion q stored as
/// (x, y, z, w) in the lanes of a float4 (w the scalar part).
struct Pose {
  float4 p;
  float4 q;
};

/// Rotates v (xyz) by the unit quaternion q: v + 2 w (u x v) + 2 u x (u x v), u = q.xyz.
inline float4 rotate(float4 q, float4 v) {
  const float4 t = 2.0f * cross3(q, v);
  const float4 r = v + q.w * t + cross3(q, t);
  return {r.x, r.y, r.z, 0.0f};
}

/// Rotates v by the inverse of the unit quaternion q.
inline float4 rotate_inverse(float4 q, float4 v) { return rotate(float4{-q.x, -q.y, -q.z, q.w}, v); }

/// The collider's pose at fraction t in [0, 1] of the frame: positions
/// lerped, rotations nlerped on the shorter arc.
Pose collider_pose(const ColliderEntry& e, float t);

/// Signed distance [m] of a point given in the collider's frame (negative
/// inside), and the outward unit normal there, in the collider's frame.
/// Box inside: the distance to the nearest face (normal of that face);
/// outside: the distance to the box. Points on a sphere's centre or a
/// capsule's axis, where the normal is undefined, get +y (sphere) or +x.
struct SignedDistance {
  float distance;
  float4 normal;
};
/// `nodes`: the collider buffer's ImplicitEntry array (after the last
/// ColliderEntry), read only by implicit colliders; `grids`: the level-set
/// grids buffer, read only by level-set colliders.
SignedDistance collider_distance(const ColliderEntry& e, float4 local, const ImplicitEntry* nodes,
                                 std::uint32_t* grids);

/// The signed distance and normal of an implicit shape's `count` nodes
/// (postfix CSG, kernels/shared/contact_params.h) at a point in the
/// collider's frame. The nodes were checked on the host (a well-formed
/// expression within SINEW_IMPLICIT_STACK).
SignedDistance implicit_distance(const ImplicitEntry* nodes, std::uint32_t count, float4 local);

}  // namespace sinew::kernels
