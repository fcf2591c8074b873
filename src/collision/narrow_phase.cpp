// narrow_phase.cpp — contacts of candidate triangle, segment and
// segment-triangle pairs (see narrow_phase.h): per pair, vertex-triangle
// and edge-edge closest points (kernels/math/proximity_math.h), after a box
// reject; pairs in chunks on TBB's threads, joined and deduplicated.
#include "collision/narrow_phase.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>


#include "math/proximity_math.h"
#include "math/triangle_separation.h"
#include "hooks/hooks_internal.h"

namespace sinew::collision {
namespace {

using kernels::float4;
namespace px = kernels::proximity;
using kernels::separation::separated;
using kernels::separation::worth_separating;

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

Status check_thickness(float thickness) {
  if (!(thickness > 0.0f) || !std::isfinite(thickness))
    return Error(ErrorCode::bad_parameter,
                 "the collision thickness must be finite and > 0 [m] (got " + std::to_string(thickness) + ")");
  return {};
}

// Reads primitive `t` (arity 2 or 3) of `indices`: its vertex indices and
// positions, checked; triangles must have an area (a normal).
Status corners(std::span<const float> positions, std::span<const std::uint32_t> indices, int arity, const char* kind,
               std::uint32_t t, std::uint32_t (&v)[3], float4 (&p)[3]) {
  const std::size_t vertices = positions.size() / 4, count = indices.size() / std::size_t(arity);
  if (t >= count)
    return Error(ErrorCode::bad_parameter, std::string("candidate pair names ") + kind + " " + std::to_string(t) +
                                               " of " + std::to_string(count));
  for (int k = 0; k < arity; ++k) {
    v[k] = indices[std::size_t(arity) * t + std::size_t(k)];
    if (v[k] >= vertices)
      return Error(ErrorCode::bad_parameter, std::string(kind) + " " + std::to_string(t) + " names vertex " +
                                                 std::to_string(v[k]) + " of " + std::to_string(vertices));
    p[k] = vertex(positions, v[k]);
    if (!std::isfinite(p[k].x) || !std::isfinite(p[k].y) || !std::isfinite(p[k].z))
      return Error(ErrorCode::bad_parameter, std::string(kind) + " " + std::to_string(t) + ": vertex " +
                                                 std::to_string(v[k]) + " has a non-finite position");
  }
  if (arity == 3 && length3(kernels::cross3(p[1] - p[0], p[2] - p[0])) <= 0.0f)
    return Error(ErrorCode::bad_parameter,
                 "triangle " + std::to_string(t) + " has zero area: a colliding triangle needs a normal");
  return {};
}

// Vertex `vertex_id` at `p` against triangle (tv, tp): a contact if closer
// than the thickness.
// Whether p is farther than `gap` from the box of the points along an axis
// (then it is farther than `gap` from anything they span): a quick reject
// before the closest-point queries.
bool outside_box(float4 p, const float4* q, int n, float gap) {
  const float c[3] = {p.x, p.y, p.z};
  for (int a = 0; a < 3; ++a) {
    float lo = (&q[0].x)[a], hi = lo;
    for (int k = 1; k < n; ++k) lo = std::min(lo, (&q[k].x)[a]), hi = std::max(hi, (&q[k].x)[a]);
    if (c[a] < lo - gap || c[a] > hi + gap) return true;
  }
  return false;
}

// Whether the boxes of two segments are farther apart than `gap` along an axis.
bool apart(float4 p1, float4 q1, float4 p2, float4 q2, float gap) {
  for (int a = 0; a < 3; ++a) {
    const float a0 = (&p1.x)[a], a1 = (&q1.x)[a], b0 = (&p2.x)[a], b1 = (&q2.x)[a];
    if (std::max(a0, a1) + gap < std::min(b0, b1) || std::max(b0, b1) + gap < std::min(a0, a1)) return true;
  }
  return false;
}

void vertex_triangle(std::uint32_t vertex_id, float4 p, const std::uint32_t (&tv)[3], const float4 (&tp)[3],
                     float thickness, std::vector<Contact>& contacts) {
  if (outside_box(p, tp, 3, thickness)) return;
  const auto w = px::closest_on_triangle(p, tp[0], tp[1], tp[2]);
  const float4 q = px::at(w, tp[0], tp[1], tp[2]);
  const float d = length3(p - q);
  if (d >= thickness) return;
  Contact c;
  c.kind = Contact::Kind::vertex_triangle;
  c.v = {vertex_id, tv[0], tv[1], tv[2]};
  c.w = {1.0f, w.wa, w.wb, w.wc};
  c.normal = direction(q, p, face_normal(tp[0], tp[1], tp[2]));
  c.distance = d;
  contacts.push_back(c);
}

// Edge (e0, e1) at (p1, q1) against edge (e2, e3) at (p2, q2): a contact if
// closer than the thickness and sharing no vertex. face() gives the normal to
// fall back on when the edges are parallel (zero for none: then touching
// edges make no contact, there is no direction to push along); it is called
// only then.
template <class Face>
void edge_edge(std::uint32_t e0, std::uint32_t e1, float4 p1, float4 q1, std::uint32_t e2, std::uint32_t e3,
               float4 p2, float4 q2, const Face& face, float thickness, std::vector<Contact>& contacts) {
  if (e0 == e2 || e0 == e3 || e1 == e2 || e1 == e3) return;
  if (apart(p1, q1, p2, q2, thickness)) return;
  // One orientation per edge (lower vertex first), so every primitive
  // naming an edge names it alike and duplicates collapse.
  if (e0 > e1) std::swap(e0, e1), std::swap(p1, q1);
  if (e2 > e3) std::swap(e2, e3), std::swap(p2, q2);
  const auto st = px::closest_between_segments(p1, q1, p2, q2);
  const float4 c1 = px::lerp3(p1, q1, st.s), c2 = px::lerp3(p2, q2, st.t);
  const float d = length3(c1 - c2);
  if (d >= thickness) return;
  float4 fallback = kernels::cross3(q1 - p1, q2 - p2);  // touching edges: their common normal
  const float fl = length3(fallback);
  fallback = fl > 0.0f ? (1.0f / fl) * fallback : face();
  if (d <= 0.0f && length3(fallback) <= 0.0f) return;
  Contact c;
  c.kind = Contact::Kind::edge_edge;
  c.v = {e0, e1, e2, e3};
  c.w = {1.0f - st.s, st.s, 1.0f - st.t, st.t};
  c.normal = direction(c2, c1, fallback);
  c.distance = d;
  contacts.push_back(c);
}

// Two edges of one set (a surface or a thread against itself): ordered by
// their vertices first, so (a, b) and (b, a) make the same contact; the
// fallback normal is face_a() or face_b(), that of the edge that goes second.
template <class FaceA, class FaceB>
void edge_edge_within_one_set(std::uint32_t a0, std::uint32_t a1, float4 pa0, float4 pa1, const FaceA& face_a,
                              std::uint32_t b0, std::uint32_t b1, float4 pb0, float4 pb1, const FaceB& face_b,
                              float thickness, std::vector<Contact>& contacts) {
  const bool b_first = std::min(b0, b1) < std::min(a0, a1) ||
                       (std::min(b0, b1) == std::min(a0, a1) && std::max(b0, b1) < std::max(a0, a1));
  if (b_first)
    edge_edge(b0, b1, pb0, pb1, a0, a1, pa0, pa1, face_a, thickness, contacts);
  else
    edge_edge(a0, a1, pa0, pa1, b0, b1, pb0, pb1, face_b, thickness, contacts);
}


bool contains(const std::uint32_t* v, int n, std::uint32_t x) {
  for (int k = 0; k < n; ++k)
    if (v[k] == x) return true;
  return false;
}

// The pairs in chunks of kChunk on TBB's threads, each chunk's contacts in
// its own list; joined and deduplicated, so the result is the same on any
// thread count; the first error in pair order is returned. (The liver
// surface's 105,000 candidate pairs: ~85 ms on one thread.)
constexpr std::size_t kChunk = 1024;

// `keep` (when set) drops a pair's contacts as they are made, before the
// join and the sort.
template <class PerPair>
Status in_chunks(std::size_t pairs, std::vector<Contact>& contacts, const ContactFilter& keep, PerPair per_pair) {
  const std::size_t chunks = (pairs + kChunk - 1) / kChunk;
  std::vector<std::vector<Contact>> found(chunks);
  std::vector<Status> errors(chunks);
  hooks::parallel_for(chunks, 1, [&](std::size_t first_chunk, std::size_t end_chunk) {
    for (std::size_t c = first_chunk; c < end_chunk; ++c)
      for (std::size_t k = c * kChunk; k < std::min(pairs, (c + 1) * kChunk); ++k) {
        const std::size_t before = found[c].size();
        if (Status s = per_pair(k, found[c]); !s) {
          errors[c] = s;
          break;
        }
        if (keep)
          found[c].erase(std::remove_if(found[c].begin() + std::ptrdiff_t(before), found[c].end(),
                                        [&](const Contact& x) { return !keep(x); }),
                         found[c].end());
      }
  });
  for (const Status& e : errors)
    if (!e) return e;
  std::size_t total = 0;
  for (const auto& f : found) total += f.size();
  contacts.reserve(total);
  for (const auto& f : found) contacts.insert(contacts.end(), f.begin(), f.end());
  sort_unique_contacts(contacts);
  return {};
}

}  // namespace

void sort_unique_contacts(std::vector<Contact>& contacts) {
  const auto key = [](const Contact& c) { return std::tuple(c.kind, c.v[0], c.v[1], c.v[2], c.v[3]); };
  std::stable_sort(contacts.begin(), contacts.end(), [&](const Contact& a, const Contact& b) { return key(a) < key(b); });
  contacts.erase(
      std::unique(contacts.begin(), contacts.end(), [&](const Contact& a, const Contact& b) { return key(a) == key(b); }),
      contacts.end());
}

float triangle_distance(std::span<const float> positions, const std::uint32_t* a, const std::uint32_t* b) {
  float4 pa[3], pb[3];
  for (int k = 0; k < 3; ++k) pa[k] = vertex(positions, a[k]), pb[k] = vertex(positions, b[k]);
  // The nearest points of two triangles lie on an edge of one of them (or
  // the triangles cross, and an edge of one crosses the other): every edge
  // against the other triangle covers both.
  float best = INFINITY;
  for (int side = 0; side < 2; ++side) {
    const float4* e = side == 0 ? pa : pb;
    const float4* t = side == 0 ? pb : pa;
    for (int k = 0; k < 3; ++k) {
      const auto c = px::closest_segment_triangle(e[k], e[(k + 1) % 3], t[0], t[1], t[2]);
      best = std::min(best, length3(px::lerp3(e[k], e[(k + 1) % 3], c.s) - px::at(c.w, t[0], t[1], t[2])));
    }
  }
  return best;
}

bool triangles_apart(std::span<const float> positions, const std::uint32_t* a, const std::uint32_t* b, float gap) {
  float4 pa[3], pb[3];
  for (int k = 0; k < 3; ++k) pa[k] = vertex(positions, a[k]), pb[k] = vertex(positions, b[k]);
  return separated(pa, pb, gap);
}

bool facing(const Contact& c, std::span<const float> positions) {
  const auto point = [&](std::uint32_t v) {
    return kernels::float4{positions[4 * std::size_t{v}], positions[4 * std::size_t{v} + 1],
                           positions[4 * std::size_t{v} + 2], 0.0f};
  };
  const kernels::float4 axis = c.kind == Contact::Kind::vertex_triangle
                                   ? kernels::cross3(point(c.v[2]) - point(c.v[1]), point(c.v[3]) - point(c.v[1]))
                                   : kernels::cross3(point(c.v[1]) - point(c.v[0]), point(c.v[3]) - point(c.v[2]));
  const float along = axis.x * c.normal[0] + axis.y * c.normal[1] + axis.z * c.normal[2];
  const float squared = kernels::dot3(axis, axis);
  return squared > 0.0f && along * along >= kFacingCos * kFacingCos * squared;
}

// The owners from the triangles around each vertex (a counting sort, so
// ascending): a vertex's owner is the first around it, an edge's the first
// around its lower vertex that has the edge. Linear in the triangles, where
// sorting the 3n edges took 1.4 ms on a 5,000-triangle surface, paid again
// at every topology change (MeshCollision::update_topology).
TriangleOwnership triangle_ownership(std::span<const std::uint32_t> triangles) {
  const std::size_t n = triangles.size() / 3;
  TriangleOwnership o;
  o.owner.resize(n);
  std::uint32_t vertices = 0;
  for (std::uint32_t v : triangles) vertices = std::max(vertices, v + 1);
  std::vector<std::uint32_t> first(std::size_t{vertices} + 1, 0), around(3 * n);
  for (std::size_t k = 0; k < 3 * n; ++k) ++first[std::size_t{triangles[k]} + 1];
  for (std::size_t v = 0; v < vertices; ++v) first[v + 1] += first[v];
  std::vector<std::uint32_t> next(first.begin(), first.end() - 1);
  for (std::uint32_t t = 0; t < n; ++t)
    for (std::uint32_t c = 0; c < 3; ++c) around[next[triangles[3 * std::size_t{t} + c]]++] = t;
  // Whether triangle u has the edge {lo, hi} (a degenerate triangle's
  // repeated vertex makes an edge {v, v}, matched only by such an edge).
  const auto has_edge = [&](std::uint32_t u, std::uint32_t lo, std::uint32_t hi) {
    const std::uint32_t* x = &triangles[3 * std::size_t{u}];
    for (int e = 0; e < 3; ++e)
      if (std::min(x[e], x[(e + 1) % 3]) == lo && std::max(x[e], x[(e + 1) % 3]) == hi) return true;
    return false;
  };
  for (std::uint32_t t = 0; t < n; ++t)
    for (std::uint32_t c = 0; c < 3; ++c) {
      const std::uint32_t v = triangles[3 * std::size_t{t} + c], w = triangles[3 * std::size_t{t} + (c + 1) % 3];
      o.owner[t][c] = around[first[v]];
      const std::uint32_t lo = std::min(v, w), hi = std::max(v, w);
      std::uint32_t k = first[lo];
      while (!has_edge(around[k], lo, hi)) ++k;  // ends at t itself at the latest
      o.owner[t][3 + c] = around[k];
    }
  return o;
}

Status triangle_contacts(std::span<const float> positions, std::span<const std::uint32_t> triangles,
                         std::span<const Pair> pairs, float thickness, std::vector<Contact>& contacts) {
  return triangle_contacts(positions, triangles, triangle_ownership(triangles), pairs, thickness, contacts);
}

Status triangle_contacts(std::span<const float> positions, std::span<const std::uint32_t> triangles,
                         const TriangleOwnership& ownership, std::span<const Pair> pairs, float thickness,
                         std::vector<Contact>& contacts, const ContactFilter& keep) {
  contacts.clear();
  if (Status s = check_thickness(thickness); !s) return s;
  if (ownership.owner.size() != triangles.size() / 3)
    return Error(ErrorCode::bad_parameter, "triangle_contacts: the ownership is of another triangle list");
  const std::size_t count = triangles.size() / 3;
  return in_chunks(pairs.size(), contacts, keep, [&](std::size_t k, std::vector<Contact>& out) -> Status {
    const auto [ti, tj] = pairs[k];
    if (ti >= count || tj >= count) {  // corners() names the bad index
      std::uint32_t v[3];
      float4 p[3];
      return corners(positions, triangles, 3, "triangle", std::max(ti, tj), v, p);
    }
    const std::uint32_t* vi = &triangles[3 * std::size_t{ti}];
    const std::uint32_t* vj = &triangles[3 * std::size_t{tj}];
    const auto& oi = ownership.owner[ti];
    const auto& oj = ownership.owner[tj];
    // Whether this pair tests a feature of ti (owned by `owner`) against tj
    // (or the other way round): yes if it is its owner, or if its owner
    // shares a vertex with the other triangle (that pair is never a
    // candidate, so every pair around the feature tests it).
    const auto shares = [&](std::uint32_t t, const std::uint32_t* v) {
      for (int c = 0; c < 3; ++c)
        if (contains(v, 3, triangles[3 * std::size_t{t} + c])) return true;
      return false;
    };
    const auto tests = [&](std::uint32_t owner, std::uint32_t self, const std::uint32_t* other) {
      return owner == self || shares(owner, other);
    };
    std::uint32_t ui[3], uj[3];
    float4 pi[3], pj[3];
    if (Status s = corners(positions, triangles, 3, "triangle", ti, ui, pi); !s) return s;
    if (Status s = corners(positions, triangles, 3, "triangle", tj, uj, pj); !s) return s;
    // The reject pays where the gap is small beside the triangles (a
    // surface's neighbours within a thin contact distance: 89% of the
    // liver's self pairs in bench_broad_phase); against a gap as long as
    // their edges it rejects almost nothing (the organ example's pressed
    // kidney: 0.3% of 12M pairs, 0% of 1.1M without self-collision) and only
    // costs, so it runs when the gap is under half the longest edge.
    if (worth_separating(pi, pj, thickness) && separated(pi, pj, thickness)) return {};
    // Decide from the indices alone; most pairs test nothing of their own.
    bool vertex_i[3], vertex_j[3], edges[3][3], any = false, any_edge = false;
    for (int c = 0; c < 3; ++c) {
      vertex_i[c] = !contains(vj, 3, vi[c]) && tests(oi[c], ti, vj);
      vertex_j[c] = !contains(vi, 3, vj[c]) && tests(oj[c], tj, vi);
      any |= vertex_i[c] || vertex_j[c];
    }
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        // The pair of the two edges' owners, unless those share a vertex.
        const std::uint32_t ea = oi[3 + a], eb = oj[3 + b];
        edges[a][b] = (ea == ti && eb == tj) || ea == eb || shares(ea, &triangles[3 * std::size_t{eb}]);
        any_edge |= edges[a][b];
      }
    if (!any && !any_edge) return {};
    for (int c = 0; c < 3; ++c) {
      if (vertex_i[c]) vertex_triangle(ui[c], pi[c], uj, pj, thickness, out);
      if (vertex_j[c]) vertex_triangle(uj[c], pj[c], ui, pi, thickness, out);
    }
    if (!any_edge) return {};
    // The fallback normal of two parallel edges: the face of the second
    // edge's owner triangle, the same whichever candidate pair tests the two
    // edges (each pair's own triangle would make the duplicates differ, and
    // which one is kept depend on the pairs' order).
    const auto owner_face = [&](std::uint32_t owner) {
      const std::uint32_t* v = &triangles[3 * std::size_t{owner}];
      return face_normal(vertex(positions, v[0]), vertex(positions, v[1]), vertex(positions, v[2]));
    };
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (edges[a][b])
          edge_edge_within_one_set(
              ui[a], ui[(a + 1) % 3], pi[a], pi[(a + 1) % 3], [&] { return owner_face(oi[3 + a]); }, uj[b],
              uj[(b + 1) % 3], pj[b], pj[(b + 1) % 3], [&] { return owner_face(oj[3 + b]); }, thickness, out);
    return {};
  });
}

Status segment_contacts(std::span<const float> positions, std::span<const std::uint32_t> segments,
                        std::span<const Pair> pairs, float thickness, std::vector<Contact>& contacts,
                        const ContactFilter& keep) {
  contacts.clear();
  if (Status s = check_thickness(thickness); !s) return s;
  return in_chunks(pairs.size(), contacts, keep, [&](std::size_t k, std::vector<Contact>& out) -> Status {
    const auto [si, sj] = pairs[k];
    std::uint32_t vi[3], vj[3];
    float4 pi[3], pj[3];
    if (Status s = corners(positions, segments, 2, "segment", si, vi, pi); !s) return s;
    if (Status s = corners(positions, segments, 2, "segment", sj, vj, pj); !s) return s;
    const auto none = [] { return float4{0, 0, 0, 0}; };  // segments have no face: touching parallel segments make no contact
    edge_edge_within_one_set(vi[0], vi[1], pi[0], pi[1], none, vj[0], vj[1], pj[0], pj[1], none, thickness, out);
    return {};
  });
}

Status segment_triangle_contacts(std::span<const float> positions, std::span<const std::uint32_t> segments,
                                 std::span<const std::uint32_t> triangles, std::span<const Pair> pairs,
                                 float thickness, std::vector<Contact>& contacts, const ContactFilter& keep) {
  contacts.clear();
  if (Status s = check_thickness(thickness); !s) return s;
  return in_chunks(pairs.size(), contacts, keep, [&](std::size_t k, std::vector<Contact>& out) -> Status {
    const auto [si, tj] = pairs[k];
    std::uint32_t vs[3], vt[3];
    float4 ps[3], pt[3];
    if (Status s = corners(positions, segments, 2, "segment", si, vs, ps); !s) return s;
    if (Status s = corners(positions, triangles, 3, "triangle", tj, vt, pt); !s) return s;
    for (int c = 0; c < 2; ++c)
      if (!contains(vt, 3, vs[c])) vertex_triangle(vs[c], ps[c], vt, pt, thickness, out);
    const auto face = [&] { return face_normal(pt[0], pt[1], pt[2]); };
    for (int b = 0; b < 3; ++b)
      edge_edge(vs[0], vs[1], ps[0], ps[1], vt[b], vt[(b + 1) % 3], pt[b], pt[(b + 1) % 3], face, thickness, out);
    return {};
  });
}

Status capsule_triangle_contacts(std::span<const float> positions, std::span<const std::uint32_t> triangles,
                                 std::span<const std::uint32_t> candidates, const std::array<float, 4>& p0,
                                 const std::array<float, 4>& p1, float radius, float thickness,
                                 std::vector<Contact>& contacts) {
  contacts.clear();
  if (Status s = check_thickness(thickness); !s) return s;
  if (!(radius > 0.0f) || !std::isfinite(radius))
    return Error(ErrorCode::bad_parameter, "the capsule's radius must be finite and > 0 [m] (got " + std::to_string(radius) + ")");
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(p0[std::size_t(k)]) || !std::isfinite(p1[std::size_t(k)]))
      return Error(ErrorCode::bad_parameter, "the capsule's axis has a non-finite coordinate");
  const float4 a{p0[0], p0[1], p0[2], 0.0f}, b{p1[0], p1[1], p1[2], 0.0f};
  return in_chunks(candidates.size(), contacts, {}, [&](std::size_t k, std::vector<Contact>& out) -> Status {
    const std::uint32_t t = candidates[k];
    std::uint32_t v[3];
    float4 p[3];
    if (Status s = corners(positions, triangles, 3, "triangle", t, v, p); !s) return s;
    const auto r = px::closest_segment_triangle(a, b, p[0], p[1], p[2]);
    const float4 on_axis = px::lerp3(a, b, r.s), on_triangle = px::at(r.w, p[0], p[1], p[2]);
    const float gap = length3(on_triangle - on_axis) - radius;
    if (gap >= thickness) return {};
    Contact c;
    c.kind = Contact::Kind::capsule_triangle;
    c.v = {0, v[0], v[1], v[2]};
    c.w = {r.s, r.w.wa, r.w.wb, r.w.wc};
    // The axis crossing the triangle: push along the face normal, to the
    // side the capsule's centre is not on.
    float4 face = face_normal(p[0], p[1], p[2]);
    if (kernels::dot3(face, px::lerp3(a, b, 0.5f) - p[0]) > 0.0f) face = -1.0f * face;
    c.normal = direction(on_axis, on_triangle, face);
    c.distance = gap;
    out.push_back(c);
    return {};
  });
}

}  // namespace sinew::collision
