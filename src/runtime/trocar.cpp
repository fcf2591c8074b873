// trocar.cpp — a rigid tool's shaft held through a fixed pivot: the
// constraint's error and its velocity impulse (formulas and reference, Cline
// and Pai, ICRA 2003: trocar.h).
#include "runtime/trocar.h"

#include <cmath>

namespace sinew {

using V3 = math::Vec3;

V3 trocar_offset(const V3& pivot, const V3& world_axis, const V3& centre) {
  const V3 to_pivot = math::sub(pivot, centre);
  return math::sub(to_pivot, math::mul(world_axis, math::dot(world_axis, to_pivot)));
}

TrocarImpulse hold_trocar_velocity(const V3& pivot, const V3& u, const V3& centre, double mass,
                                   const math::Mat3& inverse_inertia, V3& velocity, V3& angular_velocity) {
  const auto apply_inverse = [&](const V3& x) { return math::mul3(inverse_inertia, x); };
  // The tool's point on its shaft at the pivot, from its centre.
  const V3 r = math::mul(u, math::dot(u, math::sub(pivot, centre)));
  const V3 vp = math::add(velocity, math::cross(angular_velocity, r));
  // Two directions across the shaft: t1 from the axis least aligned with u.
  const int least = std::abs(u[0]) <= std::abs(u[1]) ? (std::abs(u[0]) <= std::abs(u[2]) ? 0 : 2)
                                                     : (std::abs(u[1]) <= std::abs(u[2]) ? 1 : 2);
  V3 e{0.0, 0.0, 0.0};
  e[least] = 1.0;
  V3 t1 = math::cross(u, e);
  t1 = math::mul(t1, 1.0 / std::sqrt(math::dot(t1, t1)));
  const V3 t2 = math::cross(u, t1);
  // K t_j: the point's velocity change for a unit impulse along t_j.
  const auto response = [&](const V3& j) {
    return math::add(math::mul(j, 1.0 / mass), math::cross(apply_inverse(math::cross(r, j)), r));
  };
  const V3 k1 = response(t1), k2 = response(t2);
  const double a = math::dot(t1, k1), b = math::dot(t1, k2), c = math::dot(t2, k1), d = math::dot(t2, k2);
  const double det = a * d - b * c;
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return {};
  const double f1 = -math::dot(t1, vp), f2 = -math::dot(t2, vp);
  const double l1 = (d * f1 - b * f2) / det, l2 = (a * f2 - c * f1) / det;
  const V3 j = math::add(math::mul(t1, l1), math::mul(t2, l2));
  const V3 moment = math::cross(r, j);
  velocity = math::add(velocity, math::mul(j, 1.0 / mass));
  angular_velocity = math::add(angular_velocity, apply_inverse(moment));
  return {j, moment};
}

}  // namespace sinew
