// narrow_phase_kernels.cpp — CPU reference of the narrow phase kernel
// (kernels/shared/narrow_phase_params.h): one item per candidate pair of
// triangles, its vertex-triangle and edge-edge contacts (Ericson, "Real-Time
// Collision Detection", 2005, 5.1.5 and 5.1.9: kernels/math/proximity_math.h)
// appended through an atomic counter. Written in the GPU twin's order
// (kernels/gpu/narrow_triangle_pairs.gpu), which is the host narrow phase's
// (src/collision/narrow_phase.cpp: triangle_contacts), so all three agree
// bit for bit.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <utility>

#include "cpu/cpu_kernels.h"
#include "math/proximity_math.h"
#include "math/triangle_separation.h"
#include "narrow_phase_params.h"

namespace sinew::kernels {
namespace {

namespace px = proximity;

float length3(float4 d) { return std::sqrt(dot3(d, d)); }

float4 direction(float4 from, float4 to, float4 fallback) {
  const float4 d = to - from;
  const float len = length3(d);
  return len > 0.0f ? (1.0f / len) * d : fallback;
}

float4 face_normal(float4 a, float4 b, float4 c) {
  const float4 n = cross3(b - a, c - a);
  const float len = length3(n);
  return len > 0.0f ? (1.0f / len) * n : float4{0.0f, 0.0f, 0.0f, 0.0f};
}

float min2(float a, float b) { return b < a ? b : a; }
float max2(float a, float b) { return a < b ? b : a; }

struct Hit {
  bool hit = false;
  float w[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  float4 normal{};
  float distance = 0.0f;
};

Hit vertex_triangle(float4 p, float4 a, float4 b, float4 c, float thickness) {
  Hit r;
  const float pc[3] = {p.x, p.y, p.z}, ac[3] = {a.x, a.y, a.z}, bc[3] = {b.x, b.y, b.z}, cc[3] = {c.x, c.y, c.z};
  for (int k = 0; k < 3; ++k) {
    const float lo = min2(min2(ac[k], bc[k]), cc[k]), hi = max2(max2(ac[k], bc[k]), cc[k]);
    if (pc[k] < lo - thickness || pc[k] > hi + thickness) return r;
  }
  const auto w = px::closest_on_triangle(p, a, b, c);
  const float4 q = px::at(w, a, b, c);
  const float d = length3(p - q);
  if (d >= thickness) return r;
  r.hit = true;
  r.w[0] = 1.0f, r.w[1] = w.wa, r.w[2] = w.wb, r.w[3] = w.wc;
  r.normal = direction(q, p, face_normal(a, b, c));
  r.distance = d;
  return r;
}

// face(): the fallback normal of parallel edges, called only then.
template <class Face>
Hit edge_edge(float4 p1, float4 q1, float4 p2, float4 q2, const Face& face, float thickness) {
  Hit r;
  const auto st = px::closest_between_segments(p1, q1, p2, q2);
  const float4 c1 = px::lerp3(p1, q1, st.s), c2 = px::lerp3(p2, q2, st.t);
  const float d = length3(c1 - c2);
  if (d >= thickness) return r;
  float4 fallback = cross3(q1 - p1, q2 - p2);  // touching edges: their common normal
  const float fl = length3(fallback);
  fallback = fl > 0.0f ? (1.0f / fl) * fallback : face();
  if (d <= 0.0f && length3(fallback) <= 0.0f) return r;
  r.hit = true;
  r.w[0] = 1.0f - st.s, r.w[1] = st.s, r.w[2] = 1.0f - st.t, r.w[3] = st.t;
  r.normal = direction(c2, c1, fallback);
  r.distance = d;
  return r;
}

bool segments_apart(float4 p1, float4 q1, float4 p2, float4 q2, float gap) {
  const float a0[3] = {p1.x, p1.y, p1.z}, a1[3] = {q1.x, q1.y, q1.z};
  const float b0[3] = {p2.x, p2.y, p2.z}, b1[3] = {q2.x, q2.y, q2.z};
  for (int k = 0; k < 3; ++k)
    if (max2(a0[k], a1[k]) + gap < min2(b0[k], b1[k]) || max2(b0[k], b1[k]) + gap < min2(a0[k], a1[k])) return true;
  return false;
}

void append(std::uint32_t* contacts, std::uint32_t* counts, const TrianglePairsParams& p, std::uint32_t kind,
            const std::uint32_t (&v)[4], const Hit& h) {
  const std::uint32_t slot =
      std::atomic_ref<std::uint32_t>(counts[p.contact_count_word]).fetch_add(1u, std::memory_order_relaxed);
  if (slot >= p.contact_capacity) return;
  std::uint32_t* c = contacts + std::size_t{SINEW_CONTACT_WORDS} * slot;
  c[0] = kind;
  for (int k = 0; k < 4; ++k) c[1 + k] = v[k], c[5 + k] = std::bit_cast<std::uint32_t>(h.w[k]);
  c[9] = std::bit_cast<std::uint32_t>(h.normal.x);
  c[10] = std::bit_cast<std::uint32_t>(h.normal.y);
  c[11] = std::bit_cast<std::uint32_t>(h.normal.z);
  c[12] = std::bit_cast<std::uint32_t>(h.distance);
  c[13] = c[14] = c[15] = 0u;
}

}  // namespace

void narrow_triangle_pairs(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const TrianglePairsParams*>(params);
  const auto* positions = reinterpret_cast<const float*>(bindings[0]);
  const auto* triangles = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* owners = reinterpret_cast<const std::uint32_t*>(bindings[2]);
  const auto* pairs = reinterpret_cast<const std::uint32_t*>(bindings[3]);
  auto* counts = reinterpret_cast<std::uint32_t*>(bindings[4]);
  auto* contacts = reinterpret_cast<std::uint32_t*>(bindings[5]);
  const std::uint32_t found = std::atomic_ref<std::uint32_t>(counts[p.pair_count_word]).load(std::memory_order_relaxed);
  const std::uint32_t n = found < p.pair_capacity ? found : p.pair_capacity;
  for (std::uint32_t k = begin; k < end && k < n; ++k) {
    const std::uint32_t t[2] = {pairs[2 * std::size_t{k}], pairs[2 * std::size_t{k} + 1]};
    std::uint32_t v[2][3];
    float4 x[2][3];
    for (int side = 0; side < 2; ++side)
      for (int c = 0; c < 3; ++c) {
        v[side][c] = triangles[3 * std::size_t{t[side]} + std::size_t(c)];
        const float* q = positions + 4 * std::size_t{v[side][c]};
        x[side][c] = {q[0], q[1], q[2], 0.0f};
      }
    bool degenerate = false;  // zero area, or a non-finite position (NaN fails the test too)
    for (int side = 0; side < 2; ++side)
      degenerate = degenerate || !(length3(cross3(x[side][1] - x[side][0], x[side][2] - x[side][0])) > 0.0f);
    if (degenerate) {
      std::atomic_ref<std::uint32_t>(counts[p.bad_word]).fetch_add(1u, std::memory_order_relaxed);
      continue;
    }
    if (separation::worth_separating(x[0], x[1], p.thickness) && separation::separated(x[0], x[1], p.thickness))
      continue;
    // The ownership rule (narrow_phase_params.h).
    bool vertex_test[2][3], edge_test[3][3], any = false, any_edge = false;
    for (int side = 0; side < 2; ++side) {
      const int other = 1 - side;
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t owner = owners[6 * std::size_t{t[side]} + std::size_t(c)];
        bool of_other = false, owner_shares = false;
        for (int m = 0; m < 3; ++m) {
          of_other = of_other || v[other][m] == v[side][c];
          for (int o = 0; o < 3; ++o)
            owner_shares = owner_shares || triangles[3 * std::size_t{owner} + std::size_t(o)] == v[other][m];
        }
        vertex_test[side][c] = !of_other && (owner == t[side] || owner_shares);
        any = any || vertex_test[side][c];
      }
    }
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        const std::uint32_t ea = owners[6 * std::size_t{t[0]} + 3 + std::size_t(a)];
        const std::uint32_t eb = owners[6 * std::size_t{t[1]} + 3 + std::size_t(b)];
        bool owners_share = false;
        for (int m = 0; m < 3; ++m)
          for (int o = 0; o < 3; ++o)
            owners_share = owners_share || triangles[3 * std::size_t{ea} + std::size_t(m)] ==
                                               triangles[3 * std::size_t{eb} + std::size_t(o)];
        edge_test[a][b] = (ea == t[0] && eb == t[1]) || ea == eb || owners_share;
        any_edge = any_edge || edge_test[a][b];
      }
    if (!any && !any_edge) continue;
    for (int c = 0; c < 3; ++c)
      for (int side = 0; side < 2; ++side) {
        if (!vertex_test[side][c]) continue;
        const int other = 1 - side;
        const Hit h = vertex_triangle(x[side][c], x[other][0], x[other][1], x[other][2], p.thickness);
        if (h.hit) append(contacts, counts, p, 0u, {v[side][c], v[other][0], v[other][1], v[other][2]}, h);
      }
    if (!any_edge) continue;
    // The fallback normal of parallel edges: the face of the second edge's
    // owner triangle (the host's, narrow_phase.cpp).
    const auto owner_face = [&](std::uint32_t owner) {
      float4 c[3];
      for (int m = 0; m < 3; ++m) {
        const float* q = positions + 4 * std::size_t{triangles[3 * std::size_t{owner} + std::size_t(m)]};
        c[m] = {q[0], q[1], q[2], 0.0f};
      }
      return face_normal(c[0], c[1], c[2]);
    };
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        if (!edge_test[a][b]) continue;
        std::uint32_t e[2][2] = {{v[0][a], v[0][(a + 1) % 3]}, {v[1][b], v[1][(b + 1) % 3]}};
        float4 y[2][2] = {{x[0][a], x[0][(a + 1) % 3]}, {x[1][b], x[1][(b + 1) % 3]}};
        if (e[0][0] == e[1][0] || e[0][0] == e[1][1] || e[0][1] == e[1][0] || e[0][1] == e[1][1]) continue;
        const std::uint32_t lo0 = std::min(e[0][0], e[0][1]), hi0 = std::max(e[0][0], e[0][1]);
        const std::uint32_t lo1 = std::min(e[1][0], e[1][1]), hi1 = std::max(e[1][0], e[1][1]);
        const int first = (lo1 < lo0 || (lo1 == lo0 && hi1 < hi0)) ? 1 : 0, second = 1 - first;
        if (segments_apart(y[first][0], y[first][1], y[second][0], y[second][1], p.thickness)) continue;
        // Each edge with its lower vertex first.
        for (const int side : {first, second})
          if (e[side][0] > e[side][1]) std::swap(e[side][0], e[side][1]), std::swap(y[side][0], y[side][1]);
        const std::uint32_t second_owner =
            owners[6 * std::size_t{t[second]} + 3 + std::size_t(second == 0 ? a : b)];
        const Hit h = edge_edge(y[first][0], y[first][1], y[second][0], y[second][1],
                                [&] { return owner_face(second_owner); }, p.thickness);
        if (h.hit) append(contacts, counts, p, 1u, {e[first][0], e[first][1], e[second][0], e[second][1]}, h);
      }
  }
}

}  // namespace sinew::kernels
