// tool_penalty.cpp — a level-set tool's surface points pressed into the
// colliders and the other tools (the model and its limits: tool_penalty.h).
#include "runtime/tool_penalty.h"

#include <algorithm>
#include <cstddef>

#include "collision/shape_distance.h"
#include "math/vec3.h"

namespace sinew {
namespace {

using V3 = math::Vec3;

struct Sum {
  V3 force{}, torque{};  // on the point shell's tool, about its centre
  std::uint32_t points = 0;
  double depth = 0.0;
};

// Tool a's points against `shape` at (position, rotation), moving with body
// b (nullptr: a collider, at rest). Returns a's sum; b gets the opposite.
Sum press(const ToolBody& a, const ToolBody* b, const ColliderDesc& shape, const V3& position,
          const math::Quat& rotation) {
  Sum s;
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    const V3 r = math::rotate(a.rotation, a.points[i]);
    const V3 p = math::add(a.position, r);
    // A level set: its value first (most points are outside), the gradient only inside.
    if (shape.shape == ColliderShape::level_set &&
        !(shape.level_set->value(math::rotate(math::conj(rotation), math::sub(p, position))) < 0.0))
      continue;
    const collision::ShapeDistance d = collision::shape_distance(shape, position, rotation, p);
    if (!(d.distance < 0.0)) continue;
    const double depth = -d.distance;
    // The point's speed into the shape: -(v_a(p) - v_b(p)) . n.
    V3 v = math::add(a.velocity, math::cross(a.angular_velocity, r));
    if (b) v = math::sub(v, math::add(b->velocity, math::cross(b->angular_velocity, math::sub(p, b->position))));
    const double into = -math::dot(v, d.normal);
    const double pressure = std::max(0.0, a.penalty_stiffness * depth + a.penalty_damping * into);
    // The normal is zero beyond a level set's interior band: nothing pushes there.
    const V3 f = math::mul(d.normal, a.areas[i] * pressure);
    s.force = math::add(s.force, f);
    s.torque = math::add(s.torque, math::cross(r, f));
    ++s.points;
    s.depth = std::max(s.depth, depth);
  }
  return s;
}

void apply(ToolBody& t, const V3& force, const V3& torque) {
  t.force = math::add(t.force, force);
  t.torque = math::add(t.torque, torque);
  t.penalty_force = math::add(t.penalty_force, force);
  t.penalty_torque = math::add(t.penalty_torque, torque);
}

void record(ToolBody& t, const Sum& s) {
  apply(t, s.force, s.torque);
  t.penalty_points += s.points;
  t.penalty_depth = std::max(t.penalty_depth, s.depth);
}

// Body b's share of a sum on a: the opposite force, its moment about b's centre.
void oppose(ToolBody& b, const ToolBody& a, const Sum& s) {
  // a's torque about its centre is sum r_a x f; about b's, sum (r_a + a - b) x f.
  const V3 about_b = math::add(s.torque, math::cross(math::sub(a.position, b.position), s.force));
  apply(b, math::mul(s.force, -1.0), math::mul(about_b, -1.0));
}

}  // namespace

void add_tool_penalties(std::vector<ToolBody>& tools, const std::vector<ColliderDesc>& tool_shapes,
                        const std::vector<PosedShape>& colliders) {
  for (ToolBody& t : tools) {
    t.penalty_force = t.penalty_torque = V3{0.0, 0.0, 0.0};
    t.penalty_points = 0;
    t.penalty_depth = 0.0;
  }
  for (std::size_t i = 0; i < tools.size(); ++i) {
    ToolBody& a = tools[i];
    if (a.level_set)
      for (const PosedShape& c : colliders) record(a, press(a, nullptr, *c.shape, c.position, c.rotation));
    for (std::size_t j = i + 1; j < tools.size(); ++j) {
      ToolBody& b = tools[j];
      if (a.level_set) {
        const Sum s = press(a, &b, tool_shapes[j], b.position, b.rotation);
        record(a, s);
        oppose(b, a, s);
      } else if (b.level_set) {
        const Sum s = press(b, &a, tool_shapes[i], a.position, a.rotation);
        record(b, s);
        oppose(a, b, s);
      }
    }
  }
}

}  // namespace sinew
