// The mesh collision after topology changes (issue 16): MeshCollision::
// update_topology follows removals in place instead of making the whole
// collision again. What it must keep: exactly what a MeshCollision made
// afresh from the live scene holds — the same triangles and segments (in
// the same order, so the same ownership of vertices and edges), the same
// rest-close pairs, and the same contacts from the same positions — after
// every one of a series of random removals, on every backend.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include "backends/backend.h"
#include "compiler/scene_compiler.h"
#include "runtime/mesh_collision.h"
#include "test_support.h"

namespace sinew::test {
namespace {

constexpr double kCell = 5e-3;  // [m]

// A block of 6 x 4 x 5 cells (6 tets each), a membrane of 8 x 6 cells
// beside it and a thread of 12 links above it; mesh collision with
// self-collision at `thickness`, topology changes on.
SceneDesc scene_of(double thickness) {
  SceneDesc scene;
  TetBodyDesc block;
  block.mesh = *make_tet_grid({.nx = 6, .ny = 4, .nz = 5, .cell_size = {kCell, kCell, kCell}});
  EXPECT_TRUE(block.set_elastic(3e5, 0.3).ok());
  block.pinned.push_back(0);
  scene.tet_bodies.push_back(block);
  TriBodyDesc membrane;
  constexpr int kNx = 8, kNz = 6;
  for (int j = 0; j <= kNz; ++j)
    for (int i = 0; i <= kNx; ++i) membrane.mesh.vertices.push_back({0.04 + kCell * i, 0.0, kCell * j});
  for (std::uint32_t j = 0; j < kNz; ++j)
    for (std::uint32_t i = 0; i < kNx; ++i) {
      const std::uint32_t v = j * (kNx + 1) + i;
      membrane.mesh.triangles.push_back({v, v + kNx + 1, v + 1});
      membrane.mesh.triangles.push_back({v + 1, v + kNx + 1, v + kNx + 2});
    }
  scene.tri_bodies.push_back(membrane);
  LineBodyDesc thread;
  for (int k = 0; k <= 12; ++k) {
    thread.vertices.push_back({kCell * k * 0.5, 0.03, 0.01});
    thread.masses.push_back(1e-4);
  }
  for (std::uint32_t k = 0; k < 12; ++k) thread.segments.push_back({k, k + 1});
  scene.line_bodies.push_back(thread);
  scene.solver.time_step = 1.0 / 60.0;
  scene.topology_changes = true;
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = thickness;
  return scene;
}

// The next number of a linear congruential generator on [in/out] seed.
std::uint32_t next(std::uint32_t& seed) {
  seed = seed * 1664525u + 1013904223u;
  return seed >> 8;
}

// One uploaded contact: its four particles, coefficients and normal (with offset).
using Row = std::tuple<std::array<std::uint32_t, 4>, std::array<float, 4>, std::array<float, 4>>;

// The contacts `mc` finds at `positions` (device order, xyzw; velocities
// 0), as a sorted list: their colours' order is not compared.
std::vector<Row> contacts_at(Device& device, MeshCollision& mc, const std::vector<float>& positions) {
  XpbdBuffers buffers;
  const std::size_t bytes = positions.size() * 4;
  buffers.position = *device.create_buffer(bytes, "test positions");
  buffers.velocity = *device.create_buffer(bytes, "test velocities");
  EXPECT_TRUE(device.write_buffer(buffers.position, 0, positions.data(), bytes).ok());
  const std::vector<float> still(positions.size(), 0.0f);
  EXPECT_TRUE(device.write_buffer(buffers.velocity, 0, still.data(), bytes).ok());
  bool grew = false;
  const Status s = mc.before_frame(device, buffers, {}, {}, {}, grew);
  EXPECT_TRUE(s.ok()) << s.error().message();
  const std::uint32_t n = mc.contacts();
  std::vector<std::uint32_t> particles(4 * std::size_t{n});
  std::vector<float> coefficients(4 * std::size_t{n}), normals(4 * std::size_t{n});
  if (n > 0) {
    EXPECT_TRUE(device.read_buffer(mc.buffers().particles, 0, particles.data(), particles.size() * 4).ok());
    EXPECT_TRUE(device.read_buffer(mc.buffers().coefficients, 0, coefficients.data(), coefficients.size() * 4).ok());
    EXPECT_TRUE(device.read_buffer(mc.buffers().normals, 0, normals.data(), normals.size() * 4).ok());
  }
  EXPECT_TRUE(device.destroy_buffer(buffers.position).ok());
  EXPECT_TRUE(device.destroy_buffer(buffers.velocity).ok());
  std::vector<Row> rows(n);
  for (std::size_t k = 0; k < n; ++k)
    for (int j = 0; j < 4; ++j) {
      std::get<0>(rows[k])[j] = particles[4 * k + j];
      std::get<1>(rows[k])[j] = coefficients[4 * k + j];
      std::get<2>(rows[k])[j] = normals[4 * k + j];
    }
  std::sort(rows.begin(), rows.end());
  return rows;
}

// Random removals — single tets, a tet and the tets after it (a kerf),
// membrane triangles, thread links — each followed by update_topology and
// compared with a MeshCollision made afresh from the live scene (without
// topology changes, so from extract_boundary_surface), at the thickness
// given: 1 mm (no rest-close pairs on the 5 mm grid) or 6 mm (many: the new
// faces' pairs must be found).
void expect_updates_match(const std::string& backend, double thickness) {
  auto device = create_device({.backend = backend, .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  const SceneDesc scene = scene_of(thickness);
  auto compiled = compile_scene(scene);
  ASSERT_TRUE(compiled.ok()) << compiled.error().message();
  auto made = MeshCollision::create(scene, *compiled, **device);
  ASSERT_TRUE(made.ok()) << made.error().message();
  MeshCollision& mc = **made;

  SceneDesc live = scene;  // the live elements, as Simulation::Impl::remake_collision fills them
  live.topology_changes = false;
  std::vector<std::uint8_t> alive(scene.tet_bodies[0].mesh.tets.size(), 1);
  const std::vector<const std::vector<std::uint8_t>*> masks{&alive};
  // Positions to find contacts at: the rest shape, each particle moved
  // by up to 0.3 of a cell (the same draw for both).
  std::uint32_t seed = 12345;
  std::vector<float> positions(4 * compiled->positions.size());
  for (std::size_t p = 0; p < compiled->positions.size(); ++p) {
    const auto& x = compiled->positions[p];
    const float jitter[3] = {float(next(seed) % 1000) / 1000.0f - 0.5f, float(next(seed) % 1000) / 1000.0f - 0.5f,
                             float(next(seed) % 1000) / 1000.0f - 0.5f};
    positions[4 * p] = x.x + float(0.6 * kCell) * jitter[0];
    positions[4 * p + 1] = x.y + float(0.6 * kCell) * jitter[1];
    positions[4 * p + 2] = x.z + float(0.6 * kCell) * jitter[2];
    positions[4 * p + 3] = x.w;
  }
  std::size_t contacts_seen = 0, rest_close_seen = 0;
  for (int round = 0; round < 12; ++round) {
    // A few single tets anywhere, and a run of consecutive tets (a cluster in the grid).
    const std::size_t tets = alive.size();
    for (int k = 0; k < 3; ++k) alive[next(seed) % tets] = 0;
    const std::size_t run = next(seed) % tets;
    for (std::size_t t = run; t < std::min(tets, run + 12); ++t) alive[t] = 0;
    auto& triangles = live.tri_bodies[0].mesh.triangles;
    if (round % 2 == 0 && !triangles.empty()) triangles.erase(triangles.begin() + next(seed) % triangles.size());
    auto& segments = live.line_bodies[0].segments;
    if (round % 3 == 1 && !segments.empty()) segments.erase(segments.begin() + next(seed) % segments.size());
    live.tet_bodies[0].mesh.tets.clear();
    for (std::size_t t = 0; t < tets; ++t)
      if (alive[t]) live.tet_bodies[0].mesh.tets.push_back(scene.tet_bodies[0].mesh.tets[t]);

    bool changed = false;
    const Status s = mc.update_topology(**device, live, masks, changed);
    ASSERT_TRUE(s.ok()) << s.error().message();
    auto fresh = MeshCollision::create(live, *compiled, **device);
    ASSERT_TRUE(fresh.ok()) << fresh.error().message();
    EXPECT_EQ(mc.triangles(), (*fresh)->triangles()) << "round " << round;
    EXPECT_EQ(mc.segments(), (*fresh)->segments()) << "round " << round;
    EXPECT_EQ(mc.rest_close_pairs(), (*fresh)->rest_close_pairs()) << "round " << round;
    const auto found = contacts_at(**device, mc, positions);
    const auto expected = contacts_at(**device, **fresh, positions);
    EXPECT_EQ(found, expected) << "round " << round;
    contacts_seen += expected.size();
    rest_close_seen += (*fresh)->rest_close_pairs();
    ASSERT_TRUE((*fresh)->release(**device).ok());
    if (::testing::Test::HasFailure()) break;
  }
  EXPECT_GT(contacts_seen, 0u) << "the positions make no contacts: nothing compared";
  if (thickness > kCell) {
    EXPECT_GT(rest_close_seen, 0u) << "no rest-close pairs: nothing compared";
  }
  // Nothing changed: nothing to do.
  bool changed = true;
  ASSERT_TRUE(mc.update_topology(**device, live, masks, changed).ok());
  EXPECT_FALSE(changed);
  ASSERT_TRUE(mc.release(**device).ok());
}

// The reference median split (bvh.h): node `index` over `prims`, split at
// the median by (centroid along the longest axis of the centroids' bounds,
// index), as a selection would; children numbered as Bvh::build numbers
// them. [out] sets: per node, its primitives (sorted).
void median_split(const std::vector<collision::Aabb>& boxes, std::vector<std::uint32_t> prims, std::size_t index,
                  std::vector<std::vector<std::uint32_t>>& sets) {
  const auto centroid = [&](std::uint32_t p, int k) { return 0.5f * (boxes[p].lo[k] + boxes[p].hi[k]); };
  std::vector<std::uint32_t> sorted = prims;
  std::sort(sorted.begin(), sorted.end());
  sets[index] = sorted;
  if (prims.size() <= collision::Bvh::kLeafSize) return;
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = centroid(prims[0], k);
  for (std::uint32_t p : prims)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], centroid(p, k)), hi[k] = std::max(hi[k], centroid(p, k));
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  const std::size_t half = prims.size() / 2;
  std::nth_element(prims.begin(), prims.begin() + half, prims.end(), [&](std::uint32_t a, std::uint32_t b) {
    return centroid(a, axis) < centroid(b, axis) || (centroid(a, axis) == centroid(b, axis) && a < b);
  });
  const std::size_t left = sets.size();
  sets.resize(left + 2);
  median_split(boxes, {prims.begin(), prims.begin() + half}, left, sets);
  median_split(boxes, {prims.begin() + half, prims.end()}, left + 1, sets);
}

// What a rebuild after a change makes of a cut surface (the block's with
// tets gone, the membrane's with triangles gone: holes, slits, open
// borders, non-manifold edges), checked against the definitions: the
// tree's nodes are the median split's, each node's box the union of its
// primitives', and each node's cone flags (normal_cones.h) those of a
// search over shared vertices and edges: connected, flat exactly when
// narrow, connected and without an open edge (an edge of one triangle
// only), and culled against another node only when they share a vertex.
TEST(TopologyCollision, RebuiltTreesAndConesOfACutSurfaceEqualTheirDefinitions) {
  auto device = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(device.ok());
  const SceneDesc scene = scene_of(1e-3);
  auto compiled = compile_scene(scene);
  ASSERT_TRUE(compiled.ok());
  auto made = MeshCollision::create(scene, *compiled, **device);
  ASSERT_TRUE(made.ok());
  MeshCollision& mc = **made;
  SceneDesc live = scene;
  std::vector<std::uint8_t> alive(scene.tet_bodies[0].mesh.tets.size(), 1);
  const std::vector<const std::vector<std::uint8_t>*> masks{&alive};
  std::vector<float> positions(4 * compiled->positions.size());
  for (std::size_t p = 0; p < compiled->positions.size(); ++p) {
    const auto& x = compiled->positions[p];
    positions[4 * p] = x.x, positions[4 * p + 1] = x.y, positions[4 * p + 2] = x.z;
  }
  const float flat_cos = std::cos(collision::NormalCones::kFlatDegrees * 3.14159265358979f / 180.0f);
  std::uint32_t seed = 777;
  std::size_t flat_seen = 0, open_seen = 0, culled_seen = 0;
  for (int round = 0; round < 6; ++round) {
    const std::size_t run = next(seed) % alive.size();
    for (std::size_t t = run; t < std::min(alive.size(), run + 10); ++t) alive[t] = 0;
    auto& triangles = live.tri_bodies[0].mesh.triangles;
    for (int k = 0; k < 3 && !triangles.empty(); ++k) triangles.erase(triangles.begin() + next(seed) % triangles.size());
    bool changed = false;
    ASSERT_TRUE(mc.update_topology(**device, live, masks, changed).ok());
    ASSERT_TRUE(changed);
    const std::vector<std::uint32_t>& tris = mc.triangles();
    std::vector<collision::Aabb> boxes;
    ASSERT_TRUE(collision::primitive_boxes(positions, tris, 3, 1e-4f, boxes).ok());
    collision::Bvh tree;
    tree.build(boxes);
    std::vector<std::vector<std::uint32_t>> expected(1);
    std::vector<std::uint32_t> all(boxes.size());
    for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    median_split(boxes, all, 0, expected);
    const auto& nodes = tree.nodes();
    ASSERT_EQ(nodes.size(), expected.size()) << "round " << round;
    // Per node: its triangles (sorted), from the tree's leaves up.
    std::vector<std::vector<std::uint32_t>> sets(nodes.size());
    for (std::size_t i = nodes.size(); i-- > 0;) {
      if (nodes[i].count > 0) {
        sets[i].assign(tree.order().begin() + nodes[i].first, tree.order().begin() + nodes[i].first + nodes[i].count);
      } else {
        sets[i] = sets[nodes[i].left];
        sets[i].insert(sets[i].end(), sets[nodes[i].left + 1].begin(), sets[nodes[i].left + 1].end());
      }
      std::sort(sets[i].begin(), sets[i].end());
      ASSERT_EQ(sets[i], expected[i]) << "round " << round << " node " << i;
      collision::Aabb box = boxes[sets[i][0]];
      for (std::uint32_t p : sets[i]) box = collision::merge(box, boxes[p]);
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(nodes[i].box.lo[k], box.lo[k]);
        EXPECT_EQ(nodes[i].box.hi[k], box.hi[k]);
      }
    }
    collision::NormalCones cones;
    cones.update(tree, tris, positions);
    // Edge uses over the whole surface, and each triangle's vertices.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (std::size_t t = 0; t < tris.size() / 3; ++t)
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t a = tris[3 * t + c], b = tris[3 * t + (c + 1) % 3];
        ++uses[{std::min(a, b), std::max(a, b)}];
      }
    const auto vertices_of = [&](const std::vector<std::uint32_t>& set) {
      std::vector<std::uint32_t> v;
      for (std::uint32_t t : set) v.insert(v.end(), &tris[3 * t], &tris[3 * t] + 3);
      std::sort(v.begin(), v.end());
      v.erase(std::unique(v.begin(), v.end()), v.end());
      return v;
    };
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const auto& set = sets[i];
      // Connected: a search from the first triangle over shared vertices.
      std::vector<std::uint8_t> reached(set.size(), 0);
      std::vector<std::size_t> stack{0};
      reached[0] = 1;
      while (!stack.empty()) {
        const std::size_t a = stack.back();
        stack.pop_back();
        for (std::size_t b = 0; b < set.size(); ++b)
          if (!reached[b] && collision::SharesVertex{tris}(set[a], set[b])) reached[b] = 1, stack.push_back(b);
      }
      const bool connected = std::find(reached.begin(), reached.end(), 0) == reached.end();
      bool open = false;
      for (std::uint32_t t : set)
        for (int c = 0; c < 3; ++c) {
          const std::uint32_t a = tris[3 * t + c], b = tris[3 * t + (c + 1) % 3];
          open |= uses[{std::min(a, b), std::max(a, b)}] == 1;
        }
      ASSERT_EQ(bool(cones.connected()[i]), connected) << "round " << round << " node " << i;
      const bool narrow = cones.cones()[i].cos >= flat_cos;
      ASSERT_EQ(bool(cones.flat()[i]), narrow && connected && !open) << "round " << round << " node " << i;
      flat_seen += cones.flat()[i];
      open_seen += open;
    }
    // Culled pairs of disjoint nodes share a vertex.
    for (std::size_t a = 0; a < nodes.size(); ++a) {
      if (!cones.flat()[a]) continue;
      const auto va = vertices_of(sets[a]);
      for (std::size_t b = a + 1; b < nodes.size(); ++b) {
        if (!cones.flat()[b] || !cones.pair(static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b))) continue;
        std::vector<std::uint32_t> both;
        const auto vb = vertices_of(sets[b]);
        std::set_intersection(va.begin(), va.end(), vb.begin(), vb.end(), std::back_inserter(both));
        EXPECT_FALSE(both.empty()) << "round " << round << " nodes " << a << ", " << b;
        ++culled_seen;
      }
    }
  }
  EXPECT_GT(flat_seen, 0u) << "no flat node: the flags were not compared";
  EXPECT_GT(open_seen, 0u) << "no open edge: the flags were not compared";
  EXPECT_GT(culled_seen, 0u) << "no culled pair: the pairs were not compared";
  ASSERT_TRUE(mc.release(**device).ok());
}

class TopologyCollision : public BackendTest {};

TEST_P(TopologyCollision, UpdatesEqualAFreshMeshCollision) { expect_updates_match(GetParam(), 1e-3); }

TEST_P(TopologyCollision, UpdatesFindTheNewFacesRestClosePairs) { expect_updates_match(GetParam(), 6e-3); }

INSTANTIATE_TEST_SUITE_P(Backends, TopologyCollision, ::testing::ValuesIn(backends()), backend_name);

TEST(TopologyCollision, BadUpdatesAreRefused) {
  auto device = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(device.ok());
  SceneDesc scene = scene_of(1e-3);
  auto compiled = compile_scene(scene);
  ASSERT_TRUE(compiled.ok());
  std::vector<std::uint8_t> alive(scene.tet_bodies[0].mesh.tets.size(), 1);
  std::vector<const std::vector<std::uint8_t>*> masks{&alive};
  bool changed = false;
  {  // made without topology changes
    scene.topology_changes = false;
    auto mc = MeshCollision::create(scene, *compiled, **device);
    ASSERT_TRUE(mc.ok());
    EXPECT_FALSE((*mc)->update_topology(**device, scene, masks, changed).ok());
    ASSERT_TRUE((*mc)->release(**device).ok());
    scene.topology_changes = true;
  }
  auto mc = MeshCollision::create(scene, *compiled, **device);
  ASSERT_TRUE(mc.ok());
  std::vector<std::uint8_t> short_mask(3, 1);
  const std::vector<const std::vector<std::uint8_t>*> wrong{&short_mask};
  EXPECT_FALSE((*mc)->update_topology(**device, scene, wrong, changed).ok());
  EXPECT_FALSE((*mc)->update_topology(**device, scene, {}, changed).ok());
  alive[5] = 0;
  ASSERT_TRUE((*mc)->update_topology(**device, scene, masks, changed).ok());
  EXPECT_TRUE(changed);
  alive[5] = 1;  // back from the dead
  const auto before = (*mc)->triangles();
  EXPECT_FALSE((*mc)->update_topology(**device, scene, masks, changed).ok());
  EXPECT_EQ((*mc)->triangles(), before);
  ASSERT_TRUE((*mc)->release(**device).ok());
}

}  // namespace
}  // namespace sinew::test
