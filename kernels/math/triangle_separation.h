// triangle_separation.h — a quick, conservative reject of a triangle pair
// in the narrow phase (issue 12): a separating axis among the two
// triangles' normals and their edges' in-plane normals, and the gate that
// runs it only where it pays. Shared by the host narrow phase
// (src/collision/narrow_phase.cpp) and the narrow phase kernel's CPU
// reference (kernels/cpu/narrow_phase_kernels.cpp); its GPU twin,
// kernels/gpu/narrow_triangle_pairs.gpu, rounds alike: change them together.
// (Gottschalk, Lin, Manocha, "OBBTree", SIGGRAPH 1996, for separating axes.)
#pragma once

#include <algorithm>
#include <cmath>

#include "math/vec4.h"

namespace sinew::kernels::separation {

// Whether triangles p and q are farther apart than `gap` along one of eight
// axes (their normals and each edge's normal within its triangle's plane):
// if their projections on a line are more than `gap` apart, so are all
// their points, and the pair makes no contact. A subset of the separating
// axis theorem's axes (the edge-edge cross products are left out): enough
// for neighbours side by side on a surface, the pairs it is for.
// Conservative under rounding: the points are taken relative to p[0] (the
// error scales with the pair's extent, not its distance from the origin),
// and the gap is widened by a thousandth of itself and a millionth of that
// extent, far more than the float error of the projections (~1e-7 of the
// extent); a pair this keeps is tested exactly as before.
inline bool separated(const float4 (&p)[3], const float4 (&q)[3], float gap) {
  const float4 o = p[0];
  const float4 a[3] = {p[0] - o, p[1] - o, p[2] - o}, b[3] = {q[0] - o, q[1] - o, q[2] - o};
  float extent = 0.0f;
  for (int k = 0; k < 3; ++k)
    extent = std::max({extent, std::abs(a[k].x), std::abs(a[k].y), std::abs(a[k].z), std::abs(b[k].x),
                       std::abs(b[k].y), std::abs(b[k].z)});
  const float wide = 1.001f * gap + 1e-6f * extent;
  const auto apart_along = [&](float4 n) {
    const float squared = dot3(n, n);
    if (!(squared > 0.0f)) return false;
    float alo = INFINITY, ahi = -INFINITY, blo = INFINITY, bhi = -INFINITY;
    for (int k = 0; k < 3; ++k) {
      const float u = dot3(n, a[k]), v = dot3(n, b[k]);
      alo = std::min(alo, u), ahi = std::max(ahi, u), blo = std::min(blo, v), bhi = std::max(bhi, v);
    }
    const float s = std::max(blo - ahi, alo - bhi);  // the gap between the projections, times |n|
    return s > 0.0f && s > wide * std::sqrt(squared);  // (not squared: |n|^2 of a needle underflows)
  };
  const float4 na = cross3(a[1], a[2]), nb = cross3(b[1] - b[0], b[2] - b[0]);
  if (apart_along(na) || apart_along(nb)) return true;
  for (int k = 0; k < 3; ++k)
    if (apart_along(cross3(na, a[(k + 1) % 3] - a[k])) || apart_along(cross3(nb, b[(k + 1) % 3] - b[k])))
      return true;
  return false;
}

// The longest edge of two triangles, squared.
inline float longest_edge2(const float4 (&p)[3], const float4 (&q)[3]) {
  float longest = 0.0f;
  for (int k = 0; k < 3; ++k) {
    const float4 a = p[(k + 1) % 3] - p[k], b = q[(k + 1) % 3] - q[k];
    longest = std::max({longest, dot3(a, a), dot3(b, b)});
  }
  return longest;
}

/// Whether the reject is worth running on the pair: a gap under half the
/// pair's longest edge (against a gap as long as the edges it rejects almost
/// nothing; narrow_phase.cpp says what was measured).
inline bool worth_separating(const float4 (&p)[3], const float4 (&q)[3], float gap) {
  return gap * gap < 0.25f * longest_edge2(p, q);
}

}  // namespace sinew::kernels::separation
