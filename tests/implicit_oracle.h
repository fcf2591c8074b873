// implicit_oracle.h — the signed distance of an implicit shape
// (ColliderShape::implicit, include/sinew/scene.h) in double precision,
// written from the primitives' definitions and independently of the
// kernels (kernels/cpu/contact_kernels.cpp): the oracle of the tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "sinew/scene.h"

namespace sinew::test {

using D3 = std::array<double, 3>;

/// v rotated by the unit quaternion q (w, x, y, z), as a matrix product.
inline D3 oracle_rotate(const std::array<double, 4>& q, const D3& v) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double m[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2], m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

/// p in the frame of a pose (position, rotation).
inline D3 oracle_local(const D3& position, const std::array<double, 4>& rotation, const D3& p) {
  return oracle_rotate({rotation[0], -rotation[1], -rotation[2], -rotation[3]},
                       {p[0] - position[0], p[1] - position[1], p[2] - position[2]});
}

/// One primitive's signed distance at a point of its own frame.
inline double oracle_primitive(const ImplicitNode& n, const D3& l) {
  switch (n.op) {
    case ImplicitOp::half_space: return l[1];
    case ImplicitOp::sphere: return std::hypot(l[0], l[1], l[2]) - n.radius;
    case ImplicitOp::capsule:
      return std::hypot(l[0], l[1] - std::clamp(l[1], -n.half_height, n.half_height), l[2]) - n.radius;
    case ImplicitOp::box: {
      double outside = 0, inside = -1e30;
      for (int k = 0; k < 3; ++k) {
        const double q = std::abs(l[k]) - n.half_extents[k];
        outside += std::max(q, 0.0) * std::max(q, 0.0);
        inside = std::max(inside, q);
      }
      return outside > 0 ? std::sqrt(outside) : inside;
    }
    case ImplicitOp::cylinder: {
      const double dr = std::hypot(l[0], l[2]) - n.radius, dy = std::abs(l[1]) - n.half_height;
      return dr > 0 && dy > 0 ? std::hypot(dr, dy) : std::max(dr, dy);
    }
    case ImplicitOp::torus: return std::hypot(std::hypot(l[0], l[2]) - n.radius, l[1]) - n.minor_radius;
    default: return 0.0;
  }
}

/// The shape's signed distance at a point of the collider's frame [m].
inline double oracle_implicit(const std::vector<ImplicitNode>& nodes, const D3& p) {
  std::vector<double> stack;
  for (const ImplicitNode& n : nodes) {
    if (n.op != ImplicitOp::unite && n.op != ImplicitOp::intersect && n.op != ImplicitOp::subtract) {
      stack.push_back(oracle_primitive(n, oracle_local(n.position, n.rotation, p)) - n.rounding);
      continue;
    }
    const double b = stack.back();
    stack.pop_back();
    double& a = stack.back();
    a = n.op == ImplicitOp::unite ? std::min(a, b) : n.op == ImplicitOp::intersect ? std::max(a, b) : std::max(a, -b);
  }
  return stack.back();
}

}  // namespace sinew::test
