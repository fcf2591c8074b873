// tool_contacts.h — the rigid tools against the colliders and each other
// (the shape-shape cells of the collision table): after a tool's motion for
// the frame is integrated (rigid_tool.h), its capsule is pushed out of every
// collider (at the collider's pose at the end of the frame) and out of the
// other tools, and the velocity into the contact is removed with Coulomb
// friction along it. Contacts are found at the end of the frame's motion
// (speculatively up to a tool's radius apart, since one correction can push
// a tool into another): a tool moving more than about its radius per frame
// can pass through a thin shape.
// Müller, Macklin, Chentanez, Jeschke, Kim, "Detailed Rigid Body
// Simulation with Extended Position Based Dynamics", SCA 2020: positional
// corrections with generalised inverse masses w = 1/m + (r x n)^T I^-1
// (r x n), here in Gauss-Seidel passes over the contacts, and the
// restitution-free velocity update with dynamic friction.
#pragma once

#include <vector>

#include "math/vec3.h"
#include "runtime/rigid_tool.h"
#include "sinew/scene.h"

namespace sinew {

/// A collider's shape and its pose at the end of the coming frame.
struct PosedShape {
  const ColliderDesc* shape = nullptr;
  math::Vec3 position{};
  math::Quat rotation{1.0, 0.0, 0.0, 0.0};
};

/// A capsule tool's capsule as a collider shape (its pose is the tool's).
ColliderDesc tool_capsule(const ToolBody& b);

/// Moves the tools out of the colliders and out of each other and removes
/// their velocity into the contacts (see above); dt [s] is the frame's
/// length (it turns the positional corrections into the normal impulse
/// that bounds friction). Contact points: each end of a tool's segment and
/// its point deepest in the other shape (collision/shape_distance.h), each
/// with the tool's radius. A collider is infinitely heavy; two tools share
/// a correction by their generalised inverse masses. Friction: the lesser
/// of the two dynamic coefficients.
/// Level-set tools take no part (their penalty: tool_penalty.h).
void resolve_tool_contacts(std::vector<ToolBody>& tools, const std::vector<PosedShape>& colliders, double dt);

}  // namespace sinew
