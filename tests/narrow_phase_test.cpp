// narrow_phase_test.cpp — the closest-point queries of the narrow phase
// (kernels/math/proximity_math.h) against double-precision oracles built a
// different way, on random and degenerate configurations, and the triangle
// contacts (src/collision/narrow_phase.h) against every pair of a real
// surface: the broad phase with boxes inflated by thickness / 2 loses none.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "collision/narrow_phase.h"
#include "math/proximity_math.h"
#include "surface_support.h"

namespace sinew::collision {
namespace {

using kernels::double4;
using kernels::float4;
namespace px = kernels::proximity;

double norm(double4 d) { return std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z); }

// Oracle: distance from p to segment ab, by the projection clamped to it.
double point_segment(double4 p, double4 a, double4 b) {
  const double4 d = b - a;
  const double len2 = kernels::dot3(d, d);
  const double t = len2 > 0.0 ? std::clamp(kernels::dot3(p - a, d) / len2, 0.0, 1.0) : 0.0;
  return norm(p - kernels::add_scaled3(a, t, d));
}

// Oracle: distance from p to triangle abc: the plane projection when it
// falls inside (barycentric coordinates from areas), else the nearest edge.
double point_triangle(double4 p, double4 a, double4 b, double4 c) {
  const double4 n = kernels::cross3(b - a, c - a);
  const double n2 = kernels::dot3(n, n);
  double best = std::min({point_segment(p, a, b), point_segment(p, b, c), point_segment(p, c, a)});
  if (n2 > 1e-30) {
    const double h = kernels::dot3(p - a, n) / n2;
    const double4 q = p - h * n;
    const double u = kernels::dot3(kernels::cross3(c - b, q - b), n) / n2;
    const double v = kernels::dot3(kernels::cross3(a - c, q - c), n) / n2;
    const double w = 1.0 - u - v;
    if (u >= 0 && v >= 0 && w >= 0) best = std::min(best, norm(p - q));
  }
  return best;
}

// Oracle: distance between segments: the interior critical point where
// both parameters are inside, else the four endpoint-to-segment distances.
double segment_segment(double4 p1, double4 q1, double4 p2, double4 q2) {
  double best = std::min({point_segment(p1, p2, q2), point_segment(q1, p2, q2), point_segment(p2, p1, q1),
                          point_segment(q2, p1, q1)});
  const double4 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = kernels::dot3(d1, d1), b = kernels::dot3(d1, d2), e = kernels::dot3(d2, d2);
  const double c = kernels::dot3(d1, r), f = kernels::dot3(d2, r);
  const double den = a * e - b * b;
  if (den > 1e-14 * a * e) {
    const double s = (b * f - c * e) / den, t = (a * f - b * c) / den;
    if (s >= 0 && s <= 1 && t >= 0 && t <= 1) best = std::min(best, norm(kernels::add_scaled3(p1, s, d1) - kernels::add_scaled3(p2, t, d2)));
  }
  return best;
}

double4 random_point(std::mt19937& rng, double scale = 1.0) {
  std::normal_distribution<double> g(0.0, scale);
  return {g(rng), g(rng), g(rng), 0.0};
}

// A configuration generator with the degenerate cases the issue names.
enum class Shape { random, coplanar, coincident_points, collinear, parallel_edges, crossing, touching };

TEST(Proximity, PointTriangleMatchesTheOracle) {
  std::mt19937 rng(3);
  for (int n = 0; n < 20000; ++n) {
    double4 a = random_point(rng), b = random_point(rng), c = random_point(rng), p = random_point(rng, 2.0);
    switch (Shape(n % 5)) {
      case Shape::coplanar: p.z = a.z = b.z = c.z = 0.3; break;                  // p in the triangle's plane
      case Shape::coincident_points: b = a; break;                                // a degenerate triangle
      case Shape::collinear: c = kernels::add_scaled3(a, 0.7, b - a); break;      // zero area, distinct points
      case Shape::parallel_edges: p = px::at<double>({0.2, 0.3, 0.5}, a, b, c); break;  // on the face
      default: break;
    }
    const auto w = px::closest_on_triangle(p, a, b, c);
    ASSERT_NEAR(w.wa + w.wb + w.wc, 1.0, 1e-12);
    ASSERT_GE(std::min({w.wa, w.wb, w.wc}), -1e-12);
    const double got = norm(p - px::at(w, a, b, c)), want = point_triangle(p, a, b, c);
    ASSERT_NEAR(got, want, 1e-9 * (1.0 + want)) << "case " << n;
    // float: the same algorithm in float, within float rounding of the size.
    const float4 pf{float(p.x), float(p.y), float(p.z), 0}, af{float(a.x), float(a.y), float(a.z), 0},
        bf{float(b.x), float(b.y), float(b.z), 0}, cf{float(c.x), float(c.y), float(c.z), 0};
    const auto wf = px::closest_on_triangle(pf, af, bf, cf);
    const float4 qf = px::at(wf, af, bf, cf);
    const double gotf = std::sqrt(double(kernels::dot3(pf - qf, pf - qf)));
    ASSERT_NEAR(gotf, want, 2e-5 * (1.0 + norm(p) + norm(a) + norm(b) + norm(c))) << "float, case " << n;
  }
}

TEST(Proximity, SegmentSegmentMatchesTheOracle) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 20000; ++n) {
    double4 p1 = random_point(rng), q1 = random_point(rng), p2 = random_point(rng), q2 = random_point(rng);
    switch (Shape(n % 7)) {
      case Shape::parallel_edges: q2 = kernels::add_scaled3(p2, 0.5 + u(rng), q1 - p1); break;  // parallel
      case Shape::coincident_points: q1 = p1; break;                                             // a point
      case Shape::collinear: p2 = kernels::add_scaled3(p1, u(rng), q1 - p1), q2 = kernels::add_scaled3(p1, 1.0 + u(rng), q1 - p1); break;
      case Shape::crossing: {  // they cross: distance 0
        const double4 m = kernels::add_scaled3(p1, u(rng), q1 - p1);
        p2 = kernels::add_scaled3(m, -u(rng), q2 - p2);
        q2 = kernels::add_scaled3(p2, 1.0, m - p2);
        q2 = kernels::add_scaled3(q2, 1.0, m - p2);
        break;
      }
      case Shape::touching: p2 = q1; break;  // sharing an endpoint position
      case Shape::coplanar: q2 = p2; q1 = p1; break;  // two points
      default: break;
    }
    const auto st = px::closest_between_segments(p1, q1, p2, q2);
    ASSERT_GE(st.s, 0.0);
    ASSERT_LE(st.s, 1.0);
    ASSERT_GE(st.t, 0.0);
    ASSERT_LE(st.t, 1.0);
    const double got = norm(px::lerp3(p1, q1, st.s) - px::lerp3(p2, q2, st.t));
    const double want = segment_segment(p1, q1, p2, q2);
    ASSERT_NEAR(got, want, 1e-9 * (1.0 + want)) << "case " << n;
  }
}

// Segment against triangle: against an oracle that samples the segment
// (2,001 points, each against the triangle by the point oracle): the query
// is never farther than the samples' best and at most one sample spacing
// nearer; crossing segments give 0.
TEST(Proximity, SegmentTriangleMatchesTheOracle) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 3000; ++n) {
    double4 a = random_point(rng), b = random_point(rng), c = random_point(rng);
    double4 p = random_point(rng, 1.5), q = random_point(rng, 1.5);
    if (n % 4 == 1) {  // through the triangle
      const double w0 = 0.2 + 0.2 * u(rng);
      const double4 x = px::at<double>({w0, 0.3, 0.7 - w0}, a, b, c);
      const double4 dir = random_point(rng);
      p = kernels::add_scaled3(x, -u(rng), dir), q = kernels::add_scaled3(x, u(rng), dir);
    }
    if (n % 4 == 2) q = kernels::add_scaled3(p, 1.0, b - a);  // parallel to an edge
    const auto r = px::closest_segment_triangle(p, q, a, b, c);
    ASSERT_NEAR(r.w.wa + r.w.wb + r.w.wc, 1.0, 1e-12);
    const double got = norm(px::lerp3(p, q, r.s) - px::at(r.w, a, b, c));
    double sampled = 1e30;
    const int samples = 2000;
    for (int k = 0; k <= samples; ++k) sampled = std::min(sampled, point_triangle(px::lerp3(p, q, double(k) / samples), a, b, c));
    const double spacing = norm(q - p) / samples;
    ASSERT_LE(got, sampled + 1e-9) << "case " << n;
    ASSERT_GE(got, sampled - spacing - 1e-9) << "case " << n;
    if (n % 4 == 1) {
      ASSERT_LT(got, 1e-9) << "crossing, case " << n;
    }
  }
}

// Two triangles facing each other across a gap: vertex-triangle contacts
// at the gap, normals apart; zero area, bad thickness and NaN are errors.
TEST(NarrowPhase, TwoTrianglesAcrossAGapAndBadInput) {
  std::vector<float> x = {0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0,               // triangle 0 in z = 0
                          0.2f, 0.2f, 0.01f, 0, 0.3f, 0.2f, 0.01f, 0, 0.2f, 0.3f, 0.01f, 0};  // triangle 1 at z = 0.01
  std::vector<std::uint32_t> tris = {0, 1, 2, 3, 4, 5};
  const std::vector<Pair> pairs = {{0, 1}};
  std::vector<Contact> contacts;
  ASSERT_TRUE(triangle_contacts(x, tris, pairs, 0.02f, contacts).ok());
  int vt = 0;
  for (const Contact& c : contacts) {
    EXPECT_LT(c.distance, 0.02f);
    if (c.kind == Contact::Kind::vertex_triangle && c.v[0] >= 3) {  // triangle 1's vertices over triangle 0
      ++vt;
      EXPECT_NEAR(c.distance, 0.01f, 1e-6f);
      EXPECT_NEAR(c.normal[2], 1.0f, 1e-6f) << "from triangle 0 up to the vertex";
      EXPECT_NEAR(c.w[1] + c.w[2] + c.w[3], 1.0f, 1e-6f);
    }
  }
  EXPECT_EQ(vt, 3);
  ASSERT_TRUE(triangle_contacts(x, tris, pairs, 0.005f, contacts).ok());
  EXPECT_TRUE(contacts.empty()) << "a thinner thickness than the gap: no contact";

  EXPECT_FALSE(triangle_contacts(x, tris, pairs, 0.0f, contacts).ok());
  EXPECT_FALSE(triangle_contacts(x, tris, pairs, NAN, contacts).ok());
  std::vector<float> flat = x;
  flat[4 * 5 + 0] = 0.4f, flat[4 * 5 + 1] = 0.2f;  // vertex 5 on the line through 3 and 4
  const Status area = triangle_contacts(flat, tris, pairs, 0.02f, contacts);
  ASSERT_FALSE(area.ok());
  EXPECT_NE(area.error().message().find("triangle 1 has zero area"), std::string::npos) << area.error().message();
  std::vector<float> nan = x;
  nan[4 * 4 + 2] = NAN;
  const Status bad = triangle_contacts(nan, tris, pairs, 0.02f, contacts);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("vertex 4"), std::string::npos) << bad.error().message();
}

void expect_same_contacts(const std::vector<Contact>& fast, const std::vector<Contact>& slow, const char* what) {
  ASSERT_EQ(fast.size(), slow.size()) << what;
  for (std::size_t k = 0; k < fast.size(); ++k) {
    ASSERT_EQ(fast[k].kind, slow[k].kind) << what << " " << k;
    ASSERT_EQ(fast[k].v, slow[k].v) << what << " " << k;
    ASSERT_EQ(fast[k].distance, slow[k].distance) << what << " " << k;
  }
}

// The broad phase (boxes inflated by thickness / 2, shared-vertex pairs
// skipped) followed by the narrow phase, which tests each vertex and edge
// only from its owning triangle's pairs (TriangleOwnership), finds exactly
// the contacts of every vertex-triangle and edge-edge test on every pair of
// triangles (every triangle owning everything), on the armadillo's surface
// with a thickness of one mean edge (many near pairs).
TEST(NarrowPhase, BroadThenNarrowEqualsNarrowOnEveryPair) {
  const test::Surface surface = test::surface_of("meshes/tet/armadillo_4k.node");
  ASSERT_FALSE(surface.triangles.empty());
  const std::vector<float>& x = surface.positions;
  const std::vector<std::uint32_t>& tris = surface.triangles;
  const float thickness = surface.mean_edge;  // about one edge: many near pairs
  std::vector<Aabb> boxes;
  ASSERT_TRUE(primitive_boxes(x, tris, 3, 0.5f * thickness, boxes).ok());
  Bvh tree;
  tree.build(boxes);
  std::vector<Pair> candidates;
  self_overlapping_pairs(tree, SharesVertex{tris}, candidates);
  std::vector<Contact> fast;
  ASSERT_TRUE(triangle_contacts(x, tris, candidates, thickness, fast).ok());

  std::vector<Pair> every;
  const auto n = static_cast<std::uint32_t>(tris.size() / 3);
  const SharesVertex shares{tris};
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = i + 1; j < n; ++j)
      if (!shares(i, j)) every.push_back({i, j});
  TriangleOwnership everything;  // each triangle its own owner of everything: every pair tests all
  everything.owner.resize(n);
  for (std::uint32_t t = 0; t < n; ++t) everything.owner[t].fill(t);
  std::vector<Contact> slow;
  ASSERT_TRUE(triangle_contacts(x, tris, everything, every, thickness, slow).ok());
  expect_same_contacts(fast, slow, "armadillo surface");
  EXPECT_GT(fast.size(), 100u);
  std::printf("[ narrow ] armadillo surface, thickness %.3g: %zu candidate pairs of %zu, %zu contacts\n", thickness,
              candidates.size(), every.size(), fast.size());
}

// A thread: a random walk of `n` segments of ~1 cm that keeps turning back
// on itself, so parts of it pass within the thickness of others.
std::vector<float> random_thread(std::mt19937& rng, int n, std::array<float, 3> start, std::vector<std::uint32_t>& segments) {
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::vector<float> x = {start[0], start[1], start[2], 0.0f};
  float dir[3] = {1, 0, 0};
  for (int k = 0; k < n; ++k) {
    for (float& d : dir) d = 0.6f * d + 0.8f * g(rng);
    const float len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    const std::size_t last = x.size() - 4;
    for (int a = 0; a < 3; ++a) x.push_back(x[last + std::size_t(a)] + 0.01f * dir[a] / len);
    x.push_back(0.0f);
    segments.insert(segments.end(), {std::uint32_t(k), std::uint32_t(k + 1)});
  }
  return x;
}

// A thread against itself: segment boxes inflated by thickness / 2,
// neighbours (sharing a vertex) skipped, equal to every pair's contacts.
// triangle_distance against a sampled double oracle: the least distance
// between points on a fine barycentric grid of each triangle bounds the true
// distance from above, and from below by the grid's spacing (random pairs,
// half of them pushed through each other: distance 0).
TEST(NarrowPhase, TriangleDistanceMatchesASampledOracle) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  constexpr int kGrid = 24;
  const auto sample = [&](const float* t, int i, int j, double out[3]) {
    const double a = double(i) / kGrid, b = double(j) / kGrid;
    for (int k = 0; k < 3; ++k) out[k] = (1 - a - b) * t[k] + a * t[4 + k] + b * t[8 + k];
  };
  int crossing = 0;
  for (int n = 0; n < 200; ++n) {
    std::vector<float> x(24, 0.0f);
    for (int v = 0; v < 6; ++v)
      for (int k = 0; k < 3; ++k) x[4 * v + k] = u(rng) + (v >= 3 && n % 2 == 0 ? 1.5f : 0.0f);
    const std::uint32_t a[3] = {0, 1, 2}, b[3] = {3, 4, 5};
    const double got = triangle_distance(x, a, b);
    double sampled = INFINITY, longest = 0.0;
    for (int i = 0; i <= kGrid; ++i)
      for (int j = 0; i + j <= kGrid; ++j) {
        double p[3];
        sample(&x[0], i, j, p);
        for (int k = 0; k <= kGrid; ++k)
          for (int l = 0; k + l <= kGrid; ++l) {
            double q[3];
            sample(&x[12], k, l, q);
            sampled = std::min(sampled, std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                                  (p[2] - q[2]) * (p[2] - q[2])));
          }
      }
    for (int t = 0; t < 2; ++t)
      for (int e = 0; e < 3; ++e) {
        const float* p = &x[4 * (3 * t + e)];
        const float* q = &x[4 * (3 * t + (e + 1) % 3)];
        longest = std::max(longest, double(std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2])));
      }
    ASSERT_LE(got, sampled + 1e-5) << "pair " << n;
    ASSERT_GE(got, sampled - 2.0 * longest / kGrid - 1e-5) << "pair " << n;
    if (sampled < 1e-9 || got == 0.0f) ++crossing;
  }
  EXPECT_GT(crossing, 0);  // some pairs cross: the zero case is checked too
}

// Oracle: the distance between two triangles in double, the least of their
// six vertex-triangle and nine edge-edge distances.
double triangle_triangle(const double4 (&a)[3], const double4 (&b)[3]) {
  double best = INFINITY;
  for (int k = 0; k < 3; ++k) {
    best = std::min({best, point_triangle(a[k], b[0], b[1], b[2]), point_triangle(b[k], a[0], a[1], a[2])});
    for (int l = 0; l < 3; ++l) best = std::min(best, segment_segment(a[k], a[(k + 1) % 3], b[l], b[(l + 1) % 3]));
  }
  return best;
}

// The narrow phase's first reject (triangles_apart: a separating axis
// among the normals and in-plane edge normals) never calls a pair apart
// that the double oracle puts within the gap, and triangle_contacts, which
// rejects with it first, still finds every vertex-triangle and edge-edge
// pair within the thickness: random pairs side by side in one plane (a
// surface's neighbours), in parallel planes, near each other at random,
// and tiny against large, half of them far from the origin.
TEST(NarrowPhase, TheSeparatingAxisRejectNeverDropsAPairWithinTheThickness) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const float thickness = 0.1f;
  const std::uint32_t ia[3] = {0, 1, 2}, ib[3] = {3, 4, 5};
  const std::vector<Pair> pair = {{0, 1}};
  const std::vector<std::uint32_t> tris = {0, 1, 2, 3, 4, 5};
  TriangleOwnership both;  // each triangle owns its features: the pair tests all fifteen
  both.owner = {{0, 0, 0, 0, 0, 0}, {1, 1, 1, 1, 1, 1}};
  int rejected = 0, within = 0;
  std::vector<Contact> contacts;
  for (int n = 0; n < 20000; ++n) {
    double4 a[3], b[3];
    for (auto& p : a) p = random_point(rng);
    const double4 normal = kernels::cross3(a[1] - a[0], a[2] - a[0]);
    const double4 up = (1.0 / norm(normal)) * normal;
    double4 along = kernels::cross3(up, random_point(rng));  // a direction in a's plane
    along = (1.0 / norm(along)) * along;
    switch (n % 4) {
      case 0:  // side by side in one plane, slightly tilted
        for (int k = 0; k < 3; ++k)
          b[k] = kernels::add_scaled3(kernels::add_scaled3(a[k], 3.0 * u(rng), along), 0.02 * (u(rng) - 0.5), up);
        break;
      case 1:  // in a parallel plane about the thickness away
        for (int k = 0; k < 3; ++k)
          b[k] = kernels::add_scaled3(kernels::add_scaled3(a[(k + 1) % 3], 2.0 * u(rng), along), 0.2 * u(rng), up);
        break;
      case 2:  // at random nearby
        for (auto& p : b) p = kernels::add_scaled3(a[0], 1.0, random_point(rng, 1.0));
        break;
      default: {  // a tiny triangle near a random point of a's surface
        const double wa = 0.1 + 0.6 * u(rng), wb = (1.0 - wa) * u(rng);
        const double4 on = px::at<double>({wa, wb, 1.0 - wa - wb}, a[0], a[1], a[2]);
        const double4 p0 = kernels::add_scaled3(on, 0.15 * (u(rng) - 0.3), up);
        for (auto& p : b) p = kernels::add_scaled3(p0, 1.0, random_point(rng, 0.05));
        break;
      }
    }
    const double shift = n % 2 == 0 ? 100.0 : 0.0;  // far from the origin: the reject works relative to the pair
    std::vector<float> x(24, 0.0f);
    double4 fa[3], fb[3];  // the float positions, in double, for the oracle
    for (int k = 0; k < 3; ++k) {
      const double4* src[2] = {&a[k], &b[k]};
      for (int t = 0; t < 2; ++t) {
        float* v = &x[4 * std::size_t(3 * t + k)];
        v[0] = float(src[t]->x + shift), v[1] = float(src[t]->y), v[2] = float(src[t]->z);
        (t == 0 ? fa : fb)[k] = {double(v[0]), double(v[1]), double(v[2]), 0.0};
      }
    }
    const double distance = triangle_triangle(fa, fb);
    if (triangles_apart(x, ia, ib, thickness)) {
      ++rejected;
      ASSERT_GT(distance, double(thickness)) << "pair " << n << " called apart";
    }
    ASSERT_TRUE(triangle_contacts(x, tris, both, pair, thickness, contacts).ok()) << "pair " << n;
    const auto found = [&](Contact::Kind kind, std::array<std::uint32_t, 4> v) {
      return std::any_of(contacts.begin(), contacts.end(), [&](const Contact& c) {
        if (c.kind != kind) return false;
        if (kind == Contact::Kind::vertex_triangle)
          return c.v[0] == v[0] && std::is_permutation(c.v.begin() + 1, c.v.end(), v.begin() + 1);
        const auto edge = [](std::uint32_t p, std::uint32_t q) { return std::pair{std::min(p, q), std::max(p, q)}; };
        const auto e1 = edge(c.v[0], c.v[1]), e2 = edge(c.v[2], c.v[3]);
        const auto f1 = edge(v[0], v[1]), f2 = edge(v[2], v[3]);
        return (e1 == f1 && e2 == f2) || (e1 == f2 && e2 == f1);
      });
    };
    const double inside = double(thickness) * (1.0 - 1e-4);  // clear of the float rounding at the boundary
    for (int k = 0; k < 3; ++k) {
      if (point_triangle(fa[k], fb[0], fb[1], fb[2]) < inside) {
        ++within;
        ASSERT_TRUE(found(Contact::Kind::vertex_triangle, {std::uint32_t(k), 3, 4, 5})) << "pair " << n;
      }
      if (point_triangle(fb[k], fa[0], fa[1], fa[2]) < inside) {
        ++within;
        ASSERT_TRUE(found(Contact::Kind::vertex_triangle, {std::uint32_t(3 + k), 0, 1, 2})) << "pair " << n;
      }
      for (int l = 0; l < 3; ++l)
        if (segment_segment(fa[k], fa[(k + 1) % 3], fb[l], fb[(l + 1) % 3]) < inside) {
          ++within;
          ASSERT_TRUE(found(Contact::Kind::edge_edge, {std::uint32_t(k), std::uint32_t((k + 1) % 3),
                                                       std::uint32_t(3 + l), std::uint32_t(3 + (l + 1) % 3)}))
              << "pair " << n;
        }
    }
  }
  // Both branches are exercised: many pairs rejected, many features found.
  EXPECT_GT(rejected, 2000);
  EXPECT_GT(within, 2000);
  std::printf("[ narrow ] 20000 random pairs: %d called apart, %d features within the thickness, all found\n",
              rejected, within);
}

// A filter given to the narrow phase keeps exactly the contacts it would
// keep afterwards (the solver passes its own: facing, within each pair's
// reach), on the armadillo's surface.
TEST(NarrowPhase, AFilterKeepsWhatFilteringAfterwardsKeeps) {
  const test::Surface s = test::surface_of("meshes/tet/armadillo_4k.node");
  ASSERT_FALSE(s.triangles.empty());
  const float thickness = 0.2f * s.mean_edge;
  std::vector<Aabb> boxes;
  ASSERT_TRUE(primitive_boxes(s.positions, s.triangles, 3, 0.5f * thickness, boxes).ok());
  Bvh tree;
  tree.build(boxes);
  std::vector<Pair> candidates;
  self_overlapping_pairs(tree, SharesVertex{s.triangles}, candidates);
  const TriangleOwnership owners = triangle_ownership(s.triangles);
  const ContactFilter keep = [&](const Contact& c) { return facing(c, s.positions); };
  std::vector<Contact> all, filtered;
  ASSERT_TRUE(triangle_contacts(s.positions, s.triangles, owners, candidates, thickness, all).ok());
  ASSERT_TRUE(triangle_contacts(s.positions, s.triangles, owners, candidates, thickness, filtered, keep).ok());
  std::vector<Contact> want;
  for (const Contact& c : all)
    if (keep(c)) want.push_back(c);
  ASSERT_EQ(filtered.size(), want.size());
  for (std::size_t k = 0; k < want.size(); ++k) {
    EXPECT_EQ(filtered[k].v, want[k].v);
    EXPECT_EQ(filtered[k].distance, want[k].distance);
  }
  EXPECT_GT(want.size(), 0u);
  EXPECT_LT(want.size(), all.size());  // the filter dropped some: the comparison is not vacuous
}

TEST(NarrowPhase, ThreadAgainstItselfEqualsEveryPair) {
  std::mt19937 rng(17);
  std::vector<std::uint32_t> segs;
  const std::vector<float> x = random_thread(rng, 600, {0, 0, 0}, segs);
  const float thickness = 0.005f;
  std::vector<Aabb> boxes;
  ASSERT_TRUE(primitive_boxes(x, segs, 2, 0.5f * thickness, boxes).ok());
  Bvh tree;
  tree.build(boxes);
  const SharesVertexOf<2> shares{segs};
  std::vector<Pair> candidates, every;
  self_overlapping_pairs(tree, shares, candidates);
  for (std::uint32_t i = 0; i < boxes.size(); ++i)
    for (std::uint32_t j = i + 1; j < boxes.size(); ++j)
      if (!shares(i, j)) every.push_back({i, j});
  std::vector<Contact> fast, slow;
  ASSERT_TRUE(segment_contacts(x, segs, candidates, thickness, fast).ok());
  ASSERT_TRUE(segment_contacts(x, segs, every, thickness, slow).ok());
  expect_same_contacts(fast, slow, "thread self");
  EXPECT_GT(fast.size(), 10u) << "the walk should pass near itself";
  for (const Contact& c : fast) {
    EXPECT_EQ(c.kind, Contact::Kind::edge_edge);
    EXPECT_LT(c.distance, thickness);
    EXPECT_NEAR(std::hypot(c.normal[0], c.normal[1], c.normal[2]), 1.0, 1e-5);
  }
  std::printf("[ narrow ] thread of 600 segments: %zu candidate pairs, %zu contacts\n", candidates.size(), fast.size());
}

// A thread lying across a surface (the armadillo's, scaled to ~10 cm):
// segment-triangle contacts from the two trees equal every pair's.
TEST(NarrowPhase, ThreadAgainstSurfaceEqualsEveryPair) {
  auto mesh = read_tet_mesh(test::data_path("meshes/tet/armadillo_4k.node"));
  ASSERT_TRUE(mesh.ok());
  const TriMesh tri = extract_boundary_surface(*mesh);
  double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
  for (const auto& v : tri.vertices)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
  const double scale = 0.1 / (hi[0] - lo[0]);
  std::mt19937 rng(23);
  std::vector<std::uint32_t> segs, tris;
  // The thread starts at the surface's middle, its vertices first in the
  // position array, the surface's after them.
  std::vector<float> x = random_thread(rng, 300, {0.05f, float(0.5 * (hi[1] - lo[1]) * scale), float(0.5 * (hi[2] - lo[2]) * scale)}, segs);
  const auto offset = static_cast<std::uint32_t>(x.size() / 4);
  for (const auto& v : tri.vertices)
    x.insert(x.end(), {float((v[0] - lo[0]) * scale), float((v[1] - lo[1]) * scale), float((v[2] - lo[2]) * scale), 0.0f});
  for (const auto& t : tri.triangles) tris.insert(tris.end(), {t[0] + offset, t[1] + offset, t[2] + offset});
  const float thickness = 0.004f;
  std::vector<Aabb> sb, tb;
  ASSERT_TRUE(primitive_boxes(x, segs, 2, 0.5f * thickness, sb).ok());
  ASSERT_TRUE(primitive_boxes(x, tris, 3, 0.5f * thickness, tb).ok());
  Bvh st, tt;
  st.build(sb);
  tt.build(tb);
  std::vector<Pair> candidates, every;
  overlapping_pairs(st, tt, candidates);
  for (std::uint32_t i = 0; i < sb.size(); ++i)
    for (std::uint32_t j = 0; j < tb.size(); ++j) every.push_back({i, j});
  std::vector<Contact> fast, slow;
  ASSERT_TRUE(segment_triangle_contacts(x, segs, tris, candidates, thickness, fast).ok());
  ASSERT_TRUE(segment_triangle_contacts(x, segs, tris, every, thickness, slow).ok());
  expect_same_contacts(fast, slow, "thread on surface");
  EXPECT_GT(fast.size(), 10u) << "the thread should pass near the surface";
  std::printf("[ narrow ] thread of 300 segments on a %zu-triangle surface: %zu candidate pairs, %zu contacts\n",
              tri.triangles.size(), candidates.size(), fast.size());
  // Bad input: a NaN thread vertex is named by the first pair that reads it.
  x[4 * 7 + 1] = NAN;
  std::vector<Pair> with7 = {{6, 0}};
  const Status named = segment_triangle_contacts(x, segs, tris, with7, thickness, fast);
  ASSERT_FALSE(named.ok());
  EXPECT_NE(named.error().message().find("segment 6: vertex 7"), std::string::npos) << named.error().message();
}

// A capsule lying 2 mm above the top of a block's surface: contacts with
// the top triangles under it, gap 2 mm, pushing down; the BVH's candidates
// (triangle boxes and the capsule's, inflated) give exactly the contacts of
// all triangles; bad radius and axis are named.
TEST(NarrowPhase, CapsuleOverASurface) {
  auto grid = make_tet_grid({.nx = 10, .ny = 2, .nz = 10, .origin = {0, 0, 0}, .cell_size = {0.01, 0.01, 0.01}});
  ASSERT_TRUE(grid.ok());
  const test::Surface surface = test::surface_of(extract_boundary_surface(*grid));
  const std::vector<float>& x = surface.positions;
  const std::vector<std::uint32_t>& tris = surface.triangles;
  const float radius = 0.003f, thickness = 0.004f, top = 0.02f;
  const std::array<float, 4> p0{0.02f, top + 0.005f, 0.05f, 0.0f}, p1{0.08f, top + 0.005f, 0.05f, 0.0f};
  std::vector<Aabb> boxes;
  ASSERT_TRUE(primitive_boxes(x, tris, 3, 0.5f * thickness, boxes).ok());
  Bvh tree;
  tree.build(boxes);
  const float grow = radius + 0.5f * thickness;
  std::vector<Aabb> capsule = {{{std::min(p0[0], p1[0]) - grow, std::min(p0[1], p1[1]) - grow, std::min(p0[2], p1[2]) - grow},
                                {std::max(p0[0], p1[0]) + grow, std::max(p0[1], p1[1]) + grow, std::max(p0[2], p1[2]) + grow}}};
  Bvh capsule_tree;
  capsule_tree.build(capsule);
  std::vector<Pair> pairs;
  overlapping_pairs(tree, capsule_tree, pairs);
  std::vector<std::uint32_t> candidates, all(tris.size() / 3);
  for (const auto& [t, c] : pairs) candidates.push_back(t);
  std::iota(all.begin(), all.end(), 0u);
  std::vector<Contact> fast, slow;
  ASSERT_TRUE(capsule_triangle_contacts(x, tris, candidates, p0, p1, radius, thickness, fast).ok());
  ASSERT_TRUE(capsule_triangle_contacts(x, tris, all, p0, p1, radius, thickness, slow).ok());
  expect_same_contacts(fast, slow, "capsule");
  ASSERT_GT(fast.size(), 10u);
  int under = 0;
  for (const Contact& c : fast) {
    EXPECT_EQ(c.kind, Contact::Kind::capsule_triangle);
    EXPECT_LT(c.distance, thickness);
    EXPECT_GE(c.distance, 0.002f - 1e-6f) << "nothing is closer than the top face";
    if (std::abs(c.distance - 0.002f) < 1e-5f) {
      ++under;
      EXPECT_NEAR(c.normal[1], -1.0f, 1e-5f) << "pushes the top face down";
    }
  }
  EXPECT_GE(under, 20) << "the triangles right under the axis";
  const Status bad_radius = capsule_triangle_contacts(x, tris, all, p0, p1, 0.0f, thickness, fast);
  ASSERT_FALSE(bad_radius.ok());
  EXPECT_NE(bad_radius.error().message().find("radius"), std::string::npos);
  const std::array<float, 4> nan_end{NAN, 0, 0, 0};
  EXPECT_FALSE(capsule_triangle_contacts(x, tris, all, p0, nan_end, radius, thickness, fast).ok());
  // Pressed 1 mm into the surface: negative gaps.
  std::array<float, 4> q0 = p0, q1 = p1;
  q0[1] = q1[1] = top + radius - 0.001f;
  ASSERT_TRUE(capsule_triangle_contacts(x, tris, all, q0, q1, radius, thickness, fast).ok());
  float deepest = 1.0f;
  for (const Contact& c : fast) deepest = std::min(deepest, c.distance);
  EXPECT_NEAR(deepest, -0.001f, 1e-5f);
}

}  // namespace
}  // namespace sinew::collision
