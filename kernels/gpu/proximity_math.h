/* proximity_math.h — closest points between a point and a triangle and
 * between two segments in the GPU kernels: the twin of
 * kernels/math/proximity_math.h (float), every operation in its order and
 * PRECISE, so the device narrow phase rounds like the host's and the
 * backends agree bitwise. Ericson, "Real-Time Collision Detection",
 * Morgan Kaufmann 2005: 5.1.5 (closest point on a triangle by Voronoi
 * regions) and 5.1.9 (closest points of two segments). */
#ifndef SINEW_PROXIMITY_MATH_H
#define SINEW_PROXIMITY_MATH_H

#include "vec_math.h"

/* Barycentric weights of a point of a triangle (sum 1, each in [0, 1]). */
SINEW_STRUCT_BEGIN(PxBarycentric)
  float wa;
  float wb;
  float wc;
SINEW_STRUCT_END(PxBarycentric)

PxBarycentric px_barycentric(float wa, float wb, float wc) {
  PxBarycentric r;
  r.wa = wa;
  r.wb = wb;
  r.wc = wc;
  return r;
}

/* Parameters (s, t) of the closest points of two segments. */
SINEW_STRUCT_BEGIN(PxSegmentParams)
  float s;
  float t;
SINEW_STRUCT_END(PxSegmentParams)

PxSegmentParams px_segment_params(float s, float t) {
  PxSegmentParams r;
  r.s = s;
  r.t = t;
  return r;
}

float px_clamp01(float x) { return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x); }

/* a + s d, per component. */
PRECISE float3 px_add_scaled3(float3 a, float s, float3 d) {
  return make_float3(a.x + s * d.x, a.y + s * d.y, a.z + s * d.z);
}

PRECISE float px_distance2(float3 a, float3 b) {
  PRECISE float3 d = a - b;
  return dot3(d, d);
}

/* Parameter in [0, 1] of the point of segment (a, b) closest to p (0 for a
 * zero-length segment). */
float px_closest_on_segment(float3 p, float3 a, float3 b) {
  PRECISE float3 d = b - a;
  PRECISE float len2 = dot3(d, d);
  if (!(len2 > 0.0f)) return 0.0f;
  PRECISE float t = dot3(p - a, d) / len2;
  return t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
}

/* The closest point of triangle (a, b, c) to p; a (nearly) zero-area
 * triangle is taken as its three edges (sin^2 of the angle at a below the
 * float epsilon, 2^-23). */
PxBarycentric px_closest_on_triangle(float3 p, float3 a, float3 b, float3 c) {
  PRECISE float3 ab = b - a;
  PRECISE float3 ac = c - a;
  PRECISE float3 ap = p - a;
  PRECISE float3 n = cross3(ab, ac);
  PRECISE float ab2 = dot3(ab, ab);
  PRECISE float ac2 = dot3(ac, ac);
  PRECISE float flat_limit = 1.1920928955078125e-7f * ab2 * ac2;
  if (dot3(n, n) <= flat_limit) {
    const float t0 = px_closest_on_segment(p, a, b);
    const float t1 = px_closest_on_segment(p, b, c);
    const float t2 = px_closest_on_segment(p, c, a);
    const float e0 = px_distance2(p, px_add_scaled3(a, t0, b - a));
    const float e1 = px_distance2(p, px_add_scaled3(b, t1, c - b));
    const float e2 = px_distance2(p, px_add_scaled3(c, t2, a - c));
    if (e0 <= e1 && e0 <= e2) return px_barycentric(1.0f - t0, t0, 0.0f);
    if (e1 <= e2) return px_barycentric(0.0f, 1.0f - t1, t1);
    return px_barycentric(t2, 0.0f, 1.0f - t2);
  }
  PRECISE float d1 = dot3(ab, ap);
  PRECISE float d2 = dot3(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return px_barycentric(1.0f, 0.0f, 0.0f); /* vertex region a */
  PRECISE float3 bp = p - b;
  PRECISE float d3 = dot3(ab, bp);
  PRECISE float d4 = dot3(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return px_barycentric(0.0f, 1.0f, 0.0f); /* vertex region b */
  PRECISE float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) { /* edge region ab */
    PRECISE float v = d1 - d3 > 0.0f ? d1 / (d1 - d3) : 0.0f;
    return px_barycentric(1.0f - v, v, 0.0f);
  }
  PRECISE float3 cp = p - c;
  PRECISE float d5 = dot3(ab, cp);
  PRECISE float d6 = dot3(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return px_barycentric(0.0f, 0.0f, 1.0f); /* vertex region c */
  PRECISE float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) { /* edge region ac */
    PRECISE float w = d2 - d6 > 0.0f ? d2 / (d2 - d6) : 0.0f;
    return px_barycentric(1.0f - w, 0.0f, w);
  }
  PRECISE float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) { /* edge region bc */
    PRECISE float den = (d4 - d3) + (d5 - d6);
    PRECISE float w = den > 0.0f ? (d4 - d3) / den : 0.0f;
    return px_barycentric(0.0f, 1.0f - w, w);
  }
  PRECISE float den = va + vb + vc; /* inside the face */
  if (!(den > 0.0f)) return px_barycentric(1.0f, 0.0f, 0.0f);
  PRECISE float v = vb / den;
  PRECISE float w = vc / den;
  PRECISE float u = 1.0f - v - w;
  return px_barycentric(u, v, w);
}

/* Parameters (s, t) of the closest points p1 + s (q1 - p1) and p2 + t
 * (q2 - p2); parallel segments: s at the first one's clamped start. */
PxSegmentParams px_closest_between_segments(float3 p1, float3 q1, float3 p2, float3 q2) {
  PRECISE float3 d1 = q1 - p1;
  PRECISE float3 d2 = q2 - p2;
  PRECISE float3 r = p1 - p2;
  PRECISE float a = dot3(d1, d1);
  PRECISE float e = dot3(d2, d2);
  PRECISE float f = dot3(d2, r);
  if (a <= 0.0f && e <= 0.0f) return px_segment_params(0.0f, 0.0f); /* two points */
  if (a <= 0.0f) return px_segment_params(0.0f, px_clamp01(f / e)); /* the first is a point */
  PRECISE float c = dot3(d1, r);
  if (e <= 0.0f) return px_segment_params(px_clamp01(-c / a), 0.0f); /* the second is a point */
  PRECISE float b = dot3(d1, d2);
  PRECISE float denom = a * e - b * b; /* >= 0; 0 when parallel */
  PRECISE float s = denom > 0.0f ? px_clamp01((b * f - c * e) / denom) : 0.0f;
  PRECISE float t = (b * s + f) / e;
  if (t < 0.0f) {
    t = 0.0f;
    s = px_clamp01(-c / a);
  } else if (t > 1.0f) {
    t = 1.0f;
    s = px_clamp01((b - c) / a);
  }
  return px_segment_params(s, t);
}

/* wa a + wb b + wc c. */
PRECISE float3 px_at(PxBarycentric w, float3 a, float3 b, float3 c) {
  return make_float3(w.wa * a.x + w.wb * b.x + w.wc * c.x, w.wa * a.y + w.wb * b.y + w.wc * c.y,
                     w.wa * a.z + w.wb * b.z + w.wc * c.z);
}

#endif /* SINEW_PROXIMITY_MATH_H */
