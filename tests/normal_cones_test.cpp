// normal_cones_test.cpp — self-collision culling by normal cones
// (collision/normal_cones.h): every node's cone holds its triangles'
// normals, connectivity equals a search over shared vertices, and on the
// real organ surfaces, bending, the culled self-collision finds every
// facing vertex-triangle contact the unculled one finds (the only contacts
// the solver keeps besides edge-edge ones, which may be lost only inside
// flat patches, where they push across the surface, not through it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>
#include <vector>

#include "collision/bvh.h"
#include "collision/narrow_phase.h"
#include "collision/normal_cones.h"
#include "collision/parallel_pairs.h"
#include "surface_support.h"

namespace sinew::collision {
namespace {

using test::Surface;
using test::bent;
using test::surface_of;

// Per node: its run of slots in order() (inner nodes: both children's).
std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges(const Bvh& tree) {
  const auto& nodes = tree.nodes();
  std::vector<std::pair<std::uint32_t, std::uint32_t>> r(nodes.size());
  for (std::size_t i = nodes.size(); i-- > 0;)
    r[i] = nodes[i].count > 0 ? std::pair{nodes[i].first, nodes[i].count}
                              : std::pair{r[nodes[i].left].first, r[nodes[i].left].second + r[nodes[i].left + 1].second};
  return r;
}

// A tree over the surface's triangle boxes grown by `inflate`, and its cones
// at the surface's positions.
void build_with_cones(const Surface& s, float inflate, Bvh& tree, NormalCones& cones) {
  std::vector<Aabb> boxes;
  ASSERT_TRUE(primitive_boxes(s.positions, s.triangles, 3, inflate, boxes).ok());
  tree.build(boxes);
  cones.update(tree, s.triangles, s.positions);
}

std::array<double, 3> normal_of(std::span<const float> x, const std::uint32_t* t) {
  const float* a = &x[4 * std::size_t{t[0]}];
  const float* b = &x[4 * std::size_t{t[1]}];
  const float* c = &x[4 * std::size_t{t[2]}];
  const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
  const double v[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
  std::array<double, 3> n = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (double& e : n) e /= l;
  return n;
}

TEST(NormalCones, EveryNodesConeHoldsItsTrianglesNormals) {
  for (const char* file : {"meshes/tet/kidney_57k.node", "meshes/tet/armadillo_4k.node"}) {
    const Surface s = surface_of(file);
    ASSERT_FALSE(s.triangles.empty()) << file;
    std::vector<Aabb> boxes;
    ASSERT_TRUE(primitive_boxes(s.positions, s.triangles, 3, 0.1f * s.mean_edge, boxes).ok());
    Bvh tree;
    tree.build(boxes);
    const auto now = bent(s, 2.0f * s.mean_edge, 1);
    NormalCones cones;
    cones.update(tree, s.triangles, now);
    const auto r = ranges(tree);
    const float flat_cos = std::cos(NormalCones::kFlatDegrees * 3.14159265f / 180.0f);
    std::size_t tracked = 0, flat = 0;
    for (std::size_t i = 0; i < tree.nodes().size(); ++i) {
      const auto& cone = cones.cones()[i];
      if (cones.flat()[i]) {
        ++flat;
        EXPECT_GE(cone.cos, flat_cos) << file << " node " << i;
        EXPECT_TRUE(cones.connected()[i]) << file << " node " << i;
      }
      if (cone.cos < flat_cos) {
        EXPECT_FALSE(cones.flat()[i]);
        continue;
      }
      ++tracked;
      for (std::uint32_t slot = r[i].first; slot < r[i].first + r[i].second; ++slot) {
        const auto n = normal_of(now, &s.triangles[3 * std::size_t{tree.order()[slot]}]);
        const double along = cone.axis[0] * n[0] + cone.axis[1] * n[1] + cone.axis[2] * n[2];
        ASSERT_GE(along, double(cone.cos) - 1e-5) << file << " node " << i << " triangle " << tree.order()[slot];
      }
    }
    // Cannot pass vacuously: many nodes are narrow (most on the smooth
    // kidney, a fifth on the coarse armadillo).
    EXPECT_GT(tracked, tree.nodes().size() / 5) << file;
    EXPECT_GT(flat, 0u) << file;
  }
}

TEST(NormalCones, ConnectivityEqualsASearchOverSharedVertices) {
  const Surface s = surface_of("meshes/tet/kidney_57k.node");
  ASSERT_FALSE(s.triangles.empty());
  Bvh tree;
  NormalCones cones;
  build_with_cones(s, 0.0f, tree, cones);
  const auto r = ranges(tree);
  std::size_t checked = 0, connected = 0, disconnected = 0;
  for (std::size_t i = 0; i < tree.nodes().size(); ++i) {
    if (r[i].second > 512) continue;  // the brute force is quadratic
    std::vector<std::uint32_t> mine(tree.order().begin() + r[i].first, tree.order().begin() + r[i].first + r[i].second);
    std::vector<bool> seen(mine.size(), false);
    std::vector<std::size_t> stack{0};
    seen[0] = true;
    std::size_t reached = 1;
    while (!stack.empty()) {
      const std::size_t u = stack.back();
      stack.pop_back();
      for (std::size_t w = 0; w < mine.size(); ++w) {
        if (seen[w]) continue;
        bool shares = false;
        for (int p = 0; p < 3; ++p)
          for (int q = 0; q < 3; ++q) shares |= s.triangles[3 * mine[u] + p] == s.triangles[3 * mine[w] + q];
        if (shares) seen[w] = true, stack.push_back(w), ++reached;
      }
    }
    ++checked;
    const bool one = reached == mine.size();
    (one ? connected : disconnected)++;
    ASSERT_EQ(bool(cones.connected()[i]), one) << "node " << i << " of " << mine.size() << " triangles";
  }
  EXPECT_GT(checked, 1000u);
  EXPECT_GT(disconnected, 0u);  // both answers occur: the comparison is not vacuous
  EXPECT_GT(connected, 0u);
}

// Two parallel sheets 0.5 apart, normals the same way (two layers of a
// rolled membrane): each sheet is flat, but no node or node pair holding
// both is culled, and the culled self-query keeps every pair across them.
TEST(NormalCones, TwoLayersFacingTheSameWayAreNeverCulled) {
  Surface s;
  const int n = 12;
  for (int layer = 0; layer < 2; ++layer)
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) s.positions.insert(s.positions.end(), {float(i), 0.5f * float(layer), float(j), 0.0f});
  for (int layer = 0; layer < 2; ++layer)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const std::uint32_t base = std::uint32_t(layer * (n + 1) * (n + 1));
        const std::uint32_t a = base + std::uint32_t(i * (n + 1) + j), b = a + 1, c = a + std::uint32_t(n + 1), d = c + 1;
        s.triangles.insert(s.triangles.end(), {a, b, c, b, d, c});
      }
  Bvh tree;
  NormalCones cones;
  build_with_cones(s, 0.3f, tree, cones);
  const std::uint32_t per_layer = std::uint32_t(2 * n * n);
  const auto r = ranges(tree);
  std::size_t flat = 0;
  for (std::size_t i = 0; i < tree.nodes().size(); ++i) {
    bool lower = false, upper = false;
    for (std::uint32_t slot = r[i].first; slot < r[i].first + r[i].second; ++slot)
      (tree.order()[slot] < per_layer ? lower : upper) = true;
    if (lower && upper) {
      EXPECT_FALSE(cones.flat()[i]) << "node " << i << " holds both layers";
    }
    flat += cones.flat()[i];
  }
  EXPECT_GT(flat, 0u);  // the layers themselves are flat
  std::vector<Pair> all, culled;
  self_overlapping_pairs(tree, SharesVertex{s.triangles}, all);
  self_overlapping_pairs_parallel(tree, SharesVertex{s.triangles}, culled, &cones);
  std::sort(culled.begin(), culled.end());
  std::size_t across = 0;
  for (const auto& [a, b] : all)
    if ((a < per_layer) != (b < per_layer)) {
      ++across;
      EXPECT_TRUE(std::binary_search(culled.begin(), culled.end(), Pair{a, b})) << a << " " << b;
    }
  EXPECT_GT(across, std::size_t(per_layer));
  EXPECT_LT(culled.size(), all.size());  // pairs within one layer are culled
}

// A sheet with a slit along x < 1.2, one lip raised on a 20-degree ramp
// that comes back to the sheet at the slit's end (found in review): the
// sheet is connected around the slit's end and every normal is within 20
// degrees of y, yet the raised lip faces the other across the slit. Its
// triangles have open edges, so nothing with them is culled: every facing
// vertex-triangle contact of the unculled query is found.
TEST(NormalCones, ASlitWhoseLipsShearApartIsNeverCulled) {
  const int nx = 20, half = 5;
  const float step = 0.1f, gap = 0.01f, slope = std::tan(20.0f * 3.14159265f / 180.0f), end = 1.2f;
  Surface s;
  const auto add = [&](float x, float y, float z) {
    s.positions.insert(s.positions.end(), {x, y, z, 0.0f});
    return static_cast<std::uint32_t>(s.positions.size() / 4 - 1);
  };
  std::vector<std::vector<std::uint32_t>> lower(nx + 1, std::vector<std::uint32_t>(half + 1)), upper = lower;
  for (int i = 0; i <= nx; ++i) {
    const float x = float(i) * step;
    for (int j = 0; j <= half; ++j) lower[i][j] = add(x, 0.0f, float(j) * step);
    for (int j = 0; j <= half; ++j)
      upper[i][j] = j == 0 && x >= end - 1e-6f ? lower[i][half]
                                               : add(x, slope * std::max(0.0f, end - x), 0.5f + gap + float(j) * step);
  }
  for (const auto* g : {&lower, &upper})
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < half; ++j) {
        const std::uint32_t p = (*g)[i][j], q = (*g)[i + 1][j], r = (*g)[i][j + 1], t = (*g)[i + 1][j + 1];
        s.triangles.insert(s.triangles.end(), {p, r, q, q, r, t});
      }
  const float thickness = 0.05f;
  Bvh tree;
  NormalCones cones;
  build_with_cones(s, 0.5f * thickness, tree, cones);
  std::vector<Pair> all, culled;
  self_overlapping_pairs_parallel(tree, SharesVertex{s.triangles}, all);
  self_overlapping_pairs_parallel(tree, SharesVertex{s.triangles}, culled, &cones);
  EXPECT_LT(culled.size(), all.size());  // the sheet away from the slit is culled
  const TriangleOwnership owners = triangle_ownership(s.triangles);
  std::vector<Contact> from_all, from_culled;
  ASSERT_TRUE(triangle_contacts(s.positions, s.triangles, owners, all, thickness, from_all).ok());
  ASSERT_TRUE(triangle_contacts(s.positions, s.triangles, owners, culled, thickness, from_culled).ok());
  std::size_t facing_vertex_triangle = 0;
  for (const Contact& c : from_all) {
    if (c.kind != Contact::Kind::vertex_triangle || !facing(c, s.positions)) continue;
    ++facing_vertex_triangle;
    const bool kept = std::any_of(from_culled.begin(), from_culled.end(),
                                  [&](const Contact& d) { return d.kind == c.kind && d.v == c.v; });
    EXPECT_TRUE(kept) << "vertex " << c.v[0] << " against triangle " << c.v[1] << " " << c.v[2] << " " << c.v[3];
  }
  EXPECT_GT(facing_vertex_triangle, 0u);  // the lips do face each other
}

// The bending organs: the culled pairs (serial and parallel queries, after
// a build, a refit and a rebuild) are a subset of the unculled, the
// facing vertex-triangle contacts of both are the same, and every facing
// edge-edge contact lost lies inside a flat patch: its normal is >= 30
// degrees from both edges' triangle normals (normal_cones.h: >= 60 degrees
// from the patch's axis, the normals within 30 of it).
TEST(NormalCones, CullingKeepsEveryFacingVertexTriangleContactOnBendingOrgans) {
  for (const char* file : {"meshes/tet/kidney_57k.node", "meshes/tet/armadillo_4k.node", "meshes/tet/liver_382k.node"}) {
    const Surface s = surface_of(file);
    ASSERT_FALSE(s.triangles.empty()) << file;
    const float inflate = 0.1f * s.mean_edge;
    const TriangleOwnership owners = triangle_ownership(s.triangles);
    Bvh tree;
    NormalCones cones;
    std::vector<Aabb> boxes;
    std::size_t facing_seen = 0, lost_edge_edge = 0, culled_away = 0;
    for (int frame = 0; frame < 3; ++frame) {
      const auto x = bent(s, 2.0f * s.mean_edge, 2 * frame);
      ASSERT_TRUE(primitive_boxes(x, s.triangles, 3, inflate, boxes).ok());
      // Built, refitted, then rebuilt (the cones must follow the new shape:
      // Bvh::build_id); the parallel query, then the serial one with the
      // same policy, then the parallel one again.
      if (frame == 1) {
        tree.refit(boxes);
      } else {
        tree.build(boxes);
      }
      cones.update(tree, s.triangles, x);
      std::vector<Pair> all, culled;
      self_overlapping_pairs_parallel(tree, SharesVertex{s.triangles}, all);
      if (frame == 1) {
        self_overlapping_pairs(tree, SharesVertex{s.triangles}, culled, cones);
      } else {
        self_overlapping_pairs_parallel(tree, SharesVertex{s.triangles}, culled, &cones);
      }
      std::sort(all.begin(), all.end());
      std::sort(culled.begin(), culled.end());
      ASSERT_TRUE(std::includes(all.begin(), all.end(), culled.begin(), culled.end())) << file;
      culled_away += all.size() - culled.size();
      std::vector<Contact> from_all, from_culled;
      ASSERT_TRUE(triangle_contacts(x, s.triangles, owners, all, 2.0f * inflate, from_all).ok());
      ASSERT_TRUE(triangle_contacts(x, s.triangles, owners, culled, 2.0f * inflate, from_culled).ok());
      const auto key = [](const Contact& c) { return std::tuple(c.kind, c.v[0], c.v[1], c.v[2], c.v[3]); };
      std::set<decltype(key(from_all[0]))> kept;
      for (const Contact& c : from_culled) kept.insert(key(c));
      for (const Contact& c : from_all) {
        if (!facing(c, x)) continue;
        ++facing_seen;
        if (kept.count(key(c))) continue;
        ASSERT_EQ(c.kind, Contact::Kind::edge_edge)
            << file << ": a facing vertex-triangle contact was culled: vertex " << c.v[0] << " triangle " << c.v[1]
            << " " << c.v[2] << " " << c.v[3];
        ++lost_edge_edge;
        for (std::size_t t = 0; t < s.triangles.size() / 3; ++t) {
          const std::uint32_t* tri = &s.triangles[3 * t];
          const auto has = [&](std::uint32_t v) { return tri[0] == v || tri[1] == v || tri[2] == v; };
          if (!((has(c.v[0]) && has(c.v[1])) || (has(c.v[2]) && has(c.v[3])))) continue;
          const auto n = normal_of(x, tri);
          const double along = std::abs(n[0] * c.normal[0] + n[1] * c.normal[1] + n[2] * c.normal[2]);
          EXPECT_LE(along, std::cos(30.0 * 3.14159265358979 / 180.0))
              << file << ": a culled edge-edge contact pushes through the surface (triangle " << t << ")";
        }
      }
    }
    EXPECT_GT(culled_away, 0u) << file;
    EXPECT_GT(facing_seen, 0u) << file;  // there were facing contacts to keep
    std::printf("%s: %zu candidate pairs culled, %zu facing contacts, %zu of them edge-edge inside flat patches lost\n",
                file, culled_away, facing_seen, lost_edge_edge);
  }
}

}  // namespace
}  // namespace sinew::collision
