// narrow_phase.cpp — triangle-pair contacts (see narrow_phase.h).
#include "collision/narrow_phase.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "math/proximity_math.h"

namespace sinew::collision {
namespace {

using kernels::float4;
namespace px = kernels::proximity;

float4 vertex(std::span<const float> x, std::uint32_t v) { return {x[4 * v], x[4 * v + 1], x[4 * v + 2], 0.0f}; }

float length3(float4 d) { return std::sqrt(kernels::dot3(d, d)); }

// The unit normal of a triangle, or a zero vector when its area is zero.
float4 face_normal(float4 a, float4 b, float4 c) {
  const float4 n = kernels::cross3(b - a, c - a);
  const float len = length3(n);
  return len > 0.0f ? (1.0f / len) * n : float4{0, 0, 0, 0};
}

// A unit direction from `from` to `to`, or `fallback` when they coincide
// (closer than a float rounding of their size can tell apart).
std::array<float, 3> direction(float4 from, float4 to, float4 fallback) {
  const float4 d = to - from;
  const float len = length3(d);
  const float4 n = len > 0.0f ? (1.0f / len) * d : fallback;
  return {n.x, n.y, n.z};
}

}  // namespace

Status triangle_contacts(std::span<const float> positions, std::span<const std::uint32_t> triangles,
                         std::span<const Pair> pairs, float thickness, std::vector<Contact>& contacts) {
  contacts.clear();
  if (!(thickness > 0.0f) || !std::isfinite(thickness))
    return Error(ErrorCode::bad_parameter,
                 "the collision thickness must be finite and > 0 [m] (got " + std::to_string(thickness) + ")");
  const std::size_t vertices = positions.size() / 4, count = triangles.size() / 3;
  const auto corners = [&](std::uint32_t t, std::array<std::uint32_t, 3>& v, float4 (&p)[3]) -> Status {
    if (t >= count) return Error(ErrorCode::bad_parameter, "candidate pair names triangle " + std::to_string(t) + " of " + std::to_string(count));
    for (int k = 0; k < 3; ++k) {
      v[std::size_t(k)] = triangles[3 * std::size_t{t} + std::size_t(k)];
      if (v[std::size_t(k)] >= vertices)
        return Error(ErrorCode::bad_parameter, "triangle " + std::to_string(t) + " names vertex " + std::to_string(v[std::size_t(k)]) + " of " + std::to_string(vertices));
      p[k] = vertex(positions, v[std::size_t(k)]);
      if (!std::isfinite(p[k].x) || !std::isfinite(p[k].y) || !std::isfinite(p[k].z))
        return Error(ErrorCode::bad_parameter, "triangle " + std::to_string(t) + ": vertex " + std::to_string(v[std::size_t(k)]) + " has a non-finite position");
    }
    if (length3(kernels::cross3(p[1] - p[0], p[2] - p[0])) <= 0.0f)
      return Error(ErrorCode::bad_parameter, "triangle " + std::to_string(t) + " has zero area: a colliding triangle needs a normal");
    return {};
  };
  for (const auto& [ti, tj] : pairs) {
    std::array<std::uint32_t, 3> vi, vj;
    float4 pi[3], pj[3];
    if (Status s = corners(ti, vi, pi); !s) return s;
    if (Status s = corners(tj, vj, pj); !s) return s;
    // Vertices of each triangle against the other.
    for (int side = 0; side < 2; ++side) {
      const auto& va = side == 0 ? vi : vj;
      const auto& vb = side == 0 ? vj : vi;
      const float4* pa = side == 0 ? pi : pj;
      const float4* pb = side == 0 ? pj : pi;
      const float4 nb = face_normal(pb[0], pb[1], pb[2]);
      for (int k = 0; k < 3; ++k) {
        if (std::find(vb.begin(), vb.end(), va[std::size_t(k)]) != vb.end()) continue;
        const auto w = px::closest_on_triangle(pa[k], pb[0], pb[1], pb[2]);
        const float4 q = px::at(w, pb[0], pb[1], pb[2]);
        const float d = length3(pa[k] - q);
        if (d >= thickness) continue;
        Contact c;
        c.kind = Contact::Kind::vertex_triangle;
        c.v = {va[std::size_t(k)], vb[0], vb[1], vb[2]};
        c.w = {1.0f, w.wa, w.wb, w.wc};
        c.normal = direction(q, pa[k], nb);
        c.distance = d;
        contacts.push_back(c);
      }
    }
    // Edges against edges.
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        std::uint32_t e[4] = {vi[std::size_t(a)], vi[std::size_t((a + 1) % 3)], vj[std::size_t(b)], vj[std::size_t((b + 1) % 3)]};
        if (e[0] == e[2] || e[0] == e[3] || e[1] == e[2] || e[1] == e[3]) continue;
        // One orientation per edge (lower vertex first), so both triangles
        // sharing an edge name it alike and duplicates collapse.
        float4 p1 = pi[a], q1 = pi[(a + 1) % 3], p2 = pj[b], q2 = pj[(b + 1) % 3];
        if (e[0] > e[1]) std::swap(e[0], e[1]), std::swap(p1, q1);
        if (e[2] > e[3]) std::swap(e[2], e[3]), std::swap(p2, q2);
        bool flip = false;  // the edge with the lower first vertex goes first
        if (e[2] < e[0] || (e[2] == e[0] && e[3] < e[1])) {
          std::swap(e[0], e[2]), std::swap(e[1], e[3]), std::swap(p1, p2), std::swap(q1, q2);
          flip = true;
        }
        const auto st = px::closest_between_segments(p1, q1, p2, q2);
        const float4 c1 = px::lerp3(p1, q1, st.s), c2 = px::lerp3(p2, q2, st.t);
        const float d = length3(c1 - c2);
        if (d >= thickness) continue;
        float4 fallback = kernels::cross3(q1 - p1, q2 - p2);
        const float fl = length3(fallback);
        // Touching edges: their common normal; parallel and touching: the
        // second edge's triangle's face normal.
        fallback = fl > 0.0f ? (1.0f / fl) * fallback : face_normal(flip ? pi[0] : pj[0], flip ? pi[1] : pj[1], flip ? pi[2] : pj[2]);
        Contact c;
        c.kind = Contact::Kind::edge_edge;
        c.v = {e[0], e[1], e[2], e[3]};
        c.w = {1.0f - st.s, st.s, 1.0f - st.t, st.t};
        c.normal = direction(c2, c1, fallback);
        c.distance = d;
        contacts.push_back(c);
      }
  }
  // One contact per (vertex, triangle) and per pair of edges.
  const auto key = [](const Contact& c) { return std::tuple(c.kind, c.v[0], c.v[1], c.v[2], c.v[3]); };
  std::stable_sort(contacts.begin(), contacts.end(), [&](const Contact& a, const Contact& b) { return key(a) < key(b); });
  contacts.erase(std::unique(contacts.begin(), contacts.end(), [&](const Contact& a, const Contact& b) { return key(a) == key(b); }),
                 contacts.end());
  return {};
}

}  // namespace sinew::collision
