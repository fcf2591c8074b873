// proximity_math.h — closest points between a point and a triangle and
// between two segments: the narrow phase of mesh collision (issue 12),
// templated on the scalar: float in the CPU narrow phase
// (src/collision/narrow_phase.cpp) and the narrow phase kernel's CPU
// reference (kernels/cpu/narrow_phase_kernels.cpp), double in the tests.
// The GPU kernels' twin, kernels/gpu/proximity_math.h, rounds like this
// code: change both together.
//
// Ericson, "Real-Time Collision Detection", Morgan Kaufmann 2005:
// section 5.1.5 (closest point on a triangle by Voronoi regions, the
// barycentric form that needs no normal and no division until the end) and
// section 5.1.9 (closest points of two segments, clamped, with the
// parallel case). Degenerate inputs are handled, never divided by zero:
// a zero-area triangle is treated as its three edges; a zero-length
// segment acts as a point. Callers reject zero-area triangles where a
// normal is needed (collision/narrow_phase.h).
#pragma once

#include <limits>

#include "math/vec4.h"

namespace sinew::kernels::proximity {

/// The closest point of triangle (a, b, c) to p, as barycentric weights
/// (wa, wb, wc) summing to 1, each in [0, 1]. [in] positions (w ignored).
template <class T>
struct Barycentric {
  T wa, wb, wc;
};

/// Parameter t in [0, 1] of the point a + t (b - a) closest to p (0 for a
/// zero-length segment).
template <class T>
inline T closest_on_segment(vec4<T> p, vec4<T> a, vec4<T> b) {
  const vec4<T> d = b - a;
  const T len2 = dot3(d, d);
  if (!(len2 > T(0))) return T(0);
  const T t = dot3(p - a, d) / len2;
  return t < T(0) ? T(0) : (t > T(1) ? T(1) : t);
}

template <class T>
inline T distance2(vec4<T> a, vec4<T> b) {
  const vec4<T> d = a - b;
  return dot3(d, d);
}

template <class T>
inline Barycentric<T> closest_on_triangle(vec4<T> p, vec4<T> a, vec4<T> b, vec4<T> c) {
  const vec4<T> ab = b - a, ac = c - a, ap = p - a;
  // A (nearly) zero-area triangle is a segment or a point: Ericson's regions
  // assume a proper triangle (with b = a they answer a where the closest
  // point is inside ac), so take the nearest of its three edges. Threshold:
  // sin^2 of the angle at a below the type's epsilon.
  const vec4<T> n = cross3(ab, ac);
  const T ab2 = dot3(ab, ab), ac2 = dot3(ac, ac);
  if (dot3(n, n) <= std::numeric_limits<T>::epsilon() * ab2 * ac2) {
    const T t0 = closest_on_segment(p, a, b), t1 = closest_on_segment(p, b, c), t2 = closest_on_segment(p, c, a);
    const T e0 = distance2(p, add_scaled3(a, t0, b - a)), e1 = distance2(p, add_scaled3(b, t1, c - b));
    const T e2 = distance2(p, add_scaled3(c, t2, a - c));
    if (e0 <= e1 && e0 <= e2) return {T(1) - t0, t0, T(0)};
    if (e1 <= e2) return {T(0), T(1) - t1, t1};
    return {t2, T(0), T(1) - t2};
  }
  const T d1 = dot3(ab, ap), d2 = dot3(ac, ap);
  if (d1 <= T(0) && d2 <= T(0)) return {T(1), T(0), T(0)};  // vertex region a
  const vec4<T> bp = p - b;
  const T d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  if (d3 >= T(0) && d4 <= d3) return {T(0), T(1), T(0)};  // vertex region b
  const T vc = d1 * d4 - d3 * d2;
  if (vc <= T(0) && d1 >= T(0) && d3 <= T(0)) {  // edge region ab
    const T v = d1 - d3 > T(0) ? d1 / (d1 - d3) : T(0);
    return {T(1) - v, v, T(0)};
  }
  const vec4<T> cp = p - c;
  const T d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d6 >= T(0) && d5 <= d6) return {T(0), T(0), T(1)};  // vertex region c
  const T vb = d5 * d2 - d1 * d6;
  if (vb <= T(0) && d2 >= T(0) && d6 <= T(0)) {  // edge region ac
    const T w = d2 - d6 > T(0) ? d2 / (d2 - d6) : T(0);
    return {T(1) - w, T(0), w};
  }
  const T va = d3 * d6 - d5 * d4;
  if (va <= T(0) && (d4 - d3) >= T(0) && (d5 - d6) >= T(0)) {  // edge region bc
    const T den = (d4 - d3) + (d5 - d6);
    const T w = den > T(0) ? (d4 - d3) / den : T(0);
    return {T(0), T(1) - w, w};
  }
  // Inside the face. A zero-area triangle cannot get here with a positive
  // denominator; fall back to vertex a rather than divide by zero.
  const T den = va + vb + vc;
  if (!(den > T(0))) return {T(1), T(0), T(0)};
  const T v = vb / den, w = vc / den;
  return {T(1) - v - w, v, w};
}

/// Parameters (s, t) in [0, 1] of the closest points p1 + s (q1 - p1) and
/// p2 + t (q2 - p2) of two segments. Parallel segments: one of the closest
/// pairs (s chosen at the first segment's clamped start).
template <class T>
struct SegmentParams {
  T s, t;
};

template <class T>
inline T clamp01(T x) {
  return x < T(0) ? T(0) : (x > T(1) ? T(1) : x);
}

template <class T>
inline SegmentParams<T> closest_between_segments(vec4<T> p1, vec4<T> q1, vec4<T> p2, vec4<T> q2) {
  const vec4<T> d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const T a = dot3(d1, d1), e = dot3(d2, d2), f = dot3(d2, r);
  if (a <= T(0) && e <= T(0)) return {T(0), T(0)};  // two points
  if (a <= T(0)) return {T(0), clamp01(f / e)};      // first segment is a point
  const T c = dot3(d1, r);
  if (e <= T(0)) return {clamp01(-c / a), T(0)};  // second segment is a point
  const T b = dot3(d1, d2);
  const T denom = a * e - b * b;  // >= 0; 0 when parallel
  T s = denom > T(0) ? clamp01((b * f - c * e) / denom) : T(0);
  T t = (b * s + f) / e;
  if (t < T(0)) {
    t = T(0);
    s = clamp01(-c / a);
  } else if (t > T(1)) {
    t = T(1);
    s = clamp01((b - c) / a);
  }
  return {s, t};
}

/// a + s (b - a) on xyz.
template <class T>
inline vec4<T> lerp3(vec4<T> a, vec4<T> b, T s) {
  return add_scaled3(a, s, b - a);
}

/// wa a + wb b + wc c on xyz.
template <class T>
inline vec4<T> at(const Barycentric<T>& w, vec4<T> a, vec4<T> b, vec4<T> c) {
  return {w.wa * a.x + w.wb * b.x + w.wc * c.x, w.wa * a.y + w.wb * b.y + w.wc * c.y,
          w.wa * a.z + w.wb * b.z + w.wc * c.z, T(0)};
}

/// The closest points of segment (p, q) and triangle (a, b, c): the
/// parameter s on the segment and the triangle's barycentric weights.
/// Candidates (Ericson 5.1.10's approach): the segment's ends against the
/// triangle, the segment against the triangle's three edges, and the
/// point where the segment crosses the triangle (distance 0), if it does.
template <class T>
struct SegmentTriangle {
  T s;
  Barycentric<T> w;
};

template <class T>
inline SegmentTriangle<T> closest_segment_triangle(vec4<T> p, vec4<T> q, vec4<T> a, vec4<T> b, vec4<T> c) {
  // The crossing: p + s (q - p) on the triangle's plane, inside it.
  const vec4<T> n = cross3(b - a, c - a), d = q - p;
  const T nd = dot3(n, d);
  if (nd != T(0)) {
    const T s = dot3(n, a - p) / nd;
    if (s >= T(0) && s <= T(1)) {  // inside the triangle: barycentric weights by signed areas
      const vec4<T> x = add_scaled3(p, s, d);
      const T n2 = dot3(n, n);
      const T u = dot3(cross3(c - b, x - b), n) / n2, v = dot3(cross3(a - c, x - c), n) / n2;
      const T w = T(1) - u - v;
      if (u >= T(0) && v >= T(0) && w >= T(0)) return {s, {u, v, w}};
    }
  }
  SegmentTriangle<T> best{T(0), closest_on_triangle(p, a, b, c)};
  T best_d2 = distance2(p, at(best.w, a, b, c));
  const auto wq = closest_on_triangle(q, a, b, c);
  if (const T d2 = distance2(q, at(wq, a, b, c)); d2 < best_d2) best = {T(1), wq}, best_d2 = d2;
  const vec4<T> corner[3] = {a, b, c};
  for (int e = 0; e < 3; ++e) {
    const vec4<T> e0 = corner[e], e1 = corner[(e + 1) % 3];
    const auto st = closest_between_segments(p, q, e0, e1);
    const T d2 = distance2(add_scaled3(p, st.s, d), add_scaled3(e0, st.t, e1 - e0));
    if (d2 < best_d2) {
      Barycentric<T> w{T(0), T(0), T(0)};
      T* weights[3] = {&w.wa, &w.wb, &w.wc};
      *weights[e] = T(1) - st.t;
      *weights[(e + 1) % 3] = st.t;
      best = {st.s, w};
      best_d2 = d2;
    }
  }
  return best;
}

}  // namespace sinew::kernels::proximity
