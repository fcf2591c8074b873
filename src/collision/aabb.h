// aabb.h — axis-aligned bounding boxes of collision primitives (triangles,
// segments, points), inflated by a contact distance: the broad phase's
// input (issue 12). Float, like the positions they bound; the brute-force
// oracle and every BVH compare the same boxes with the same closed-interval
// test, so their pair sets must be equal, not merely close.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "sinew/result.h"

namespace sinew::collision {

struct Aabb {
  std::array<float, 3> lo{}, hi{};  ///< corners [m], lo <= hi on every axis
};

/// Whether two boxes touch or overlap (closed intervals on every axis).
inline bool overlap(const Aabb& a, const Aabb& b) {
  return a.lo[0] <= b.hi[0] && b.lo[0] <= a.hi[0] && a.lo[1] <= b.hi[1] && b.lo[1] <= a.hi[1] &&
         a.lo[2] <= b.hi[2] && b.lo[2] <= a.hi[2];
}

/// The smallest box holding both.
inline Aabb merge(const Aabb& a, const Aabb& b) {
  Aabb m;
  for (int k = 0; k < 3; ++k) {
    m.lo[k] = a.lo[k] < b.lo[k] ? a.lo[k] : b.lo[k];
    m.hi[k] = a.hi[k] > b.hi[k] ? a.hi[k] : b.hi[k];
  }
  return m;
}

/// Half the surface area of a box [m^2] (the SAH's measure of it).
inline float half_area(const Aabb& a) {
  const float dx = a.hi[0] - a.lo[0], dy = a.hi[1] - a.lo[1], dz = a.hi[2] - a.lo[2];
  return dx * dy + dy * dz + dz * dx;
}

/// Boxes of primitives whose corners are given by `arity` indices each
/// (3: triangles, 2: segments, 1: points) into `positions` (xyzw float4 per
/// vertex, w ignored), each grown by `inflate` [m] (>= 0, finite) on every
/// side. [out] boxes, one per primitive. Errors name the first primitive
/// with a non-finite corner or an index past the positions.
Status primitive_boxes(std::span<const float> positions, std::span<const std::uint32_t> indices, int arity,
                       float inflate, std::vector<Aabb>& boxes);

}  // namespace sinew::collision
