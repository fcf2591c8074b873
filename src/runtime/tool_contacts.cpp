// tool_contacts.cpp — a tool's capsule against the colliders and the other
// tools (see tool_contacts.h for the method and its paper).
#include "runtime/tool_contacts.h"

#include <algorithm>
#include <cmath>

#include "collision/shape_distance.h"

namespace sinew {
namespace {

using V3 = math::Vec3;

// The world inverse inertia applied to v: R diag(1 / I) R^T v.
V3 inverse_inertia(const ToolBody& b, const V3& v) {
  V3 l = math::rotate(math::conj(b.rotation), v);
  for (int k = 0; k < 3; ++k) l[k] /= b.inertia[k];
  return math::rotate(b.rotation, l);
}

// Generalised inverse mass of a body at offset r along direction n.
double inverse_mass(const ToolBody& b, const V3& r, const V3& n) {
  const V3 rn = math::cross(r, n);
  return 1.0 / b.mass + math::dot(rn, inverse_inertia(b, rn));
}

// Moves the body by the positional "impulse" p [kg m] at offset r.
void move(ToolBody& b, const V3& r, const V3& p) {
  b.position = math::add(b.position, math::mul(p, 1.0 / b.mass));
  const V3 turn = inverse_inertia(b, math::cross(r, p));
  const math::Quat dq = math::pure_mul(turn, b.rotation);
  math::Quat q = b.rotation;
  for (int k = 0; k < 4; ++k) q[k] += 0.5 * dq[k];
  b.rotation = math::normalize(q);
}

void push(ToolBody& b, const V3& r, const V3& j) {
  b.velocity = math::add(b.velocity, math::mul(j, 1.0 / b.mass));
  b.angular_velocity = math::add(b.angular_velocity, inverse_inertia(b, math::cross(r, j)));
}

V3 point_velocity(const ToolBody& b, const V3& r) { return math::add(b.velocity, math::cross(b.angular_velocity, r)); }


// One contact between tool `a` and either a collider (b == nullptr) or tool b.
struct Contact {
  ToolBody* a;
  ToolBody* b;
  V3 point;   // on a's surface, deepest in the other [m]
  V3 normal;  // out of the other, towards a
  double depth;
  double mu;
  double normal_impulse = 0.0;  // accumulated positional corrections / dt [N s]
  // The contact's points in the bodies' frames at detection (a's at
  // `point`, b's at `surface`, on the other's surface), so that its depth
  // follows the corrections of the others.
  V3 ra{}, rb{}, surface{};
};

// The contacts of tool a's capsule against a shape: its segment's deepest
// point and its two ends, where they are inside it or less than a's radius
// outside (speculative, see below).
void contacts_against(ToolBody& a, ToolBody* b, const ColliderDesc& shape, const V3& position, const math::Quat& rotation,
                      double mu, std::vector<Contact>& out) {
  const V3 axis = math::rotate(a.rotation, V3{0.0, a.half_height, 0.0});
  const V3 p0 = math::sub(a.position, axis), p1 = math::add(a.position, axis);
  // Speculative: contacts up to a radius apart are kept too, since other
  // contacts' corrections may move the bodies into each other (a tool
  // resting on one that the floor pushes up); they act only once touching.
  const double reach = -a.radius;
  const collision::CapsuleContact deepest = collision::capsule_against(shape, position, rotation, p0, p1, a.radius);
  if (!(deepest.depth > reach)) return;
  out.push_back({&a, b, deepest.point, deepest.normal, deepest.depth, mu});
  for (const V3& end : {p0, p1}) {
    const collision::ShapeDistance d = collision::shape_distance(shape, position, rotation, end);
    const V3 segment_point = math::add(deepest.point, math::mul(deepest.normal, a.radius));
    if (a.radius - d.distance > reach && math::norm(math::sub(end, segment_point)) > 1e-9)  // not the deepest again
      out.push_back({&a, b, math::sub(end, math::mul(d.normal, a.radius)), d.normal, a.radius - d.distance, mu});
  }
}

// Anchors a new contact in its bodies' frames.
void anchor(Contact& c) {
  c.ra = math::rotate(math::conj(c.a->rotation), math::sub(c.point, c.a->position));
  c.surface = math::add(c.point, math::mul(c.normal, c.depth));
  if (c.b) c.rb = math::rotate(math::conj(c.b->rotation), math::sub(c.surface, c.b->position));
}

// The depth of a contact now (after earlier corrections moved the bodies):
// the contact point moves with a, the other surface with b.
double current_depth(const Contact& c) {
  const V3 ra = math::rotate(c.a->rotation, c.ra);
  double depth = c.depth - math::dot(math::sub(math::add(c.a->position, ra), c.point), c.normal);
  if (c.b) depth += math::dot(math::sub(math::add(c.b->position, math::rotate(c.b->rotation, c.rb)), c.surface), c.normal);
  return depth;
}

}  // namespace

ColliderDesc tool_capsule(const ToolBody& b) {
  ColliderDesc c;
  c.shape = ColliderShape::capsule;
  c.radius = b.radius;
  c.half_height = b.half_height;
  return c;
}

void resolve_tool_contacts(std::vector<ToolBody>& tools, const std::vector<PosedShape>& colliders, double dt) {
  std::vector<Contact> contacts;
  for (std::size_t i = 0; i < tools.size(); ++i) {
    ToolBody& a = tools[i];
    if (a.level_set) continue;  // a penalty instead (tool_penalty.h)
    for (const PosedShape& s : colliders)
      contacts_against(a, nullptr, *s.shape, s.position, s.rotation, std::min(s.shape->dynamic_friction, a.dynamic_friction), contacts);
    for (std::size_t j = i + 1; j < tools.size(); ++j)
      if (!tools[j].level_set)
        contacts_against(a, &tools[j], tool_capsule(tools[j]), tools[j].position, tools[j].rotation,
                       std::min(a.dynamic_friction, tools[j].dynamic_friction), contacts);
  }
  if (contacts.empty()) return;
  for (Contact& c : contacts) anchor(c);
  // Positions: Gauss-Seidel over the contacts, forwards and backwards
  // (stacked tools pass corrections both ways), until nothing is deeper
  // than a micrometre or 32 passes.
  for (int pass = 0; pass < 32; ++pass) {
    double worst = 0.0;
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      const std::size_t k = pass % 2 == 0 ? i : contacts.size() - 1 - i;
      Contact& c = contacts[k];
      const double depth = current_depth(c);
      if (!(depth > 0.0)) continue;
      worst = std::max(worst, depth);
      const V3 ra = math::rotate(c.a->rotation, c.ra);
      double w = inverse_mass(*c.a, ra, c.normal);
      V3 rb{};
      if (c.b) {
        rb = math::rotate(c.b->rotation, c.rb);
        w += inverse_mass(*c.b, rb, c.normal);
      }
      const double lambda = depth / w;
      move(*c.a, ra, math::mul(c.normal, lambda));
      if (c.b) move(*c.b, rb, math::mul(c.normal, -lambda));
      c.normal_impulse += lambda / dt;
    }
    if (worst < 1e-6) break;
  }
  // Velocities (sequential impulses, a few passes): no approach along the
  // normal (no bounce); dynamic friction bounded by the normal impulse of
  // both the positional and the velocity step. Accumulated impulses are
  // clamped, not each pass's.
  std::vector<double> jn_sum(contacts.size(), 0.0);
  std::vector<V3> jt_sum(contacts.size(), V3{0.0, 0.0, 0.0});
  for (int pass = 0; pass < 8; ++pass) {
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      Contact& c = contacts[k];
      if (current_depth(c) < -1e-6) continue;  // apart: no impulse
      const V3 ra = math::rotate(c.a->rotation, c.ra);
      const V3 rb = c.b ? math::rotate(c.b->rotation, c.rb) : V3{};
      auto relative = [&] {
        V3 v = point_velocity(*c.a, ra);
        return c.b ? math::sub(v, point_velocity(*c.b, rb)) : v;
      };
      auto apply = [&](const V3& j) {
        push(*c.a, ra, j);
        if (c.b) push(*c.b, rb, math::mul(j, -1.0));
      };
      double w = inverse_mass(*c.a, ra, c.normal);
      if (c.b) w += inverse_mass(*c.b, rb, c.normal);
      const double next = std::max(0.0, jn_sum[k] - math::dot(relative(), c.normal) / w);
      apply(math::mul(c.normal, next - jn_sum[k]));
      jn_sum[k] = next;
      const V3 v = relative();
      const V3 vt = math::sub(v, math::mul(c.normal, math::dot(v, c.normal)));
      const double speed = math::norm(vt);
      if (!(speed > 0.0)) continue;
      const V3 t = math::mul(vt, 1.0 / speed);
      double wt = inverse_mass(*c.a, ra, t);
      if (c.b) wt += inverse_mass(*c.b, rb, t);
      V3 total = math::sub(jt_sum[k], math::mul(t, speed / wt));
      const double bound = c.mu * (jn_sum[k] + c.normal_impulse), len = math::norm(total);
      if (len > bound) total = math::mul(total, bound / len);
      apply(math::sub(total, jt_sum[k]));
      jt_sum[k] = total;
    }
  }
}

}  // namespace sinew
