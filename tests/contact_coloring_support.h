// contact_coloring_support.h — contact sets to colour (tests/
// contact_coloring_test.cpp, benchmarks/contact_coloring_benchmark.cpp):
// random ones, and the real contacts of the kidney_57k surface bent so that
// its folds touch themselves (the device narrow-phase test's bend), as the
// solver uploads them: four particles per contact, the vertex-triangle and
// edge-edge contacts of the narrow phase. No GoogleTest here: the benchmark
// includes it too.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <random>
#include <string>
#include <vector>

#include "collision/aabb.h"
#include "collision/bvh.h"
#include "collision/narrow_phase.h"
#include "sinew/mesh.h"

namespace sinew::test {

/// Contacts of four particles each, and which particles can move.
struct ContactSet {
  std::vector<std::uint32_t> particles;  ///< 4 per contact
  std::vector<std::uint8_t> movable;     ///< per particle
  // The kidney's only: the particles' positions (xyzw, w the inverse mass:
  // 1 or 0), each contact's coefficients c_k and normal (xyz, w = 0)
  // (kernels/shared/mesh_contact_params.h), and the thickness [mesh units].
  std::vector<float> positions, coefficients, normals;
  float thickness = 0.0f;
  [[nodiscard]] std::uint32_t contacts() const { return static_cast<std::uint32_t>(particles.size() / 4); }
};

/// `count` contacts over `particle_count` particles (fewer particles: more
/// conflicts), a fraction `pinned` of the particles immovable, some
/// contacts repeating a particle (as the shape contacts do).
inline ContactSet random_contacts(std::uint32_t count, std::uint32_t particle_count, double pinned, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::uint32_t> particle(0, particle_count - 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  ContactSet s;
  s.movable.resize(particle_count);
  for (auto& m : s.movable) m = u(rng) < pinned ? 0 : 1;
  for (std::uint32_t c = 0; c < count; ++c) {
    const std::uint32_t a = particle(rng), b = particle(rng), d = particle(rng), e = particle(rng);
    if (c % 7 == 3)
      s.particles.insert(s.particles.end(), {a, a, d, e});  // a triangle-shape contact
    else
      s.particles.insert(s.particles.end(), {a, b, d, e});
  }
  return s;
}

/// The solver's pruning (runtime/mesh_collision.h, "nearest few"), on one
/// body's contacts: a vertex-triangle contact kept when it is its vertex's
/// nearest, an edge-edge contact when it is among the 4 nearest of both its edges.
inline std::vector<collision::Contact> nearest_few(const std::vector<collision::Contact>& all) {
  using Key = std::pair<std::uint64_t, float>;  // (the primitive, the distance)
  std::map<std::uint64_t, std::vector<float>> near;
  const auto edge = [](std::uint32_t a, std::uint32_t b) { return std::uint64_t{std::min(a, b)} << 32 | std::max(a, b); };
  const auto keys = [&](const collision::Contact& c) {
    if (c.kind == collision::Contact::Kind::vertex_triangle) return std::vector<Key>{{std::uint64_t{c.v[0]} | 1ull << 63, c.distance}};
    return std::vector<Key>{{edge(c.v[0], c.v[1]), c.distance}, {edge(c.v[2], c.v[3]), c.distance}};
  };
  for (const auto& c : all)
    for (const Key& k : keys(c)) near[k.first].push_back(k.second);
  for (auto& [primitive, d] : near) std::sort(d.begin(), d.end());
  std::vector<collision::Contact> kept;
  for (const auto& c : all) {
    bool keep = true;
    for (const Key& k : keys(c)) {
      const std::vector<float>& d = near[k.first];
      const std::size_t rank = (k.first >> 63) != 0 ? 1 : 4;
      keep = keep && k.second <= d[std::min(rank, d.size()) - 1];
    }
    if (keep) kept.push_back(c);
  }
  return kept;
}

/// The self-contacts of the kidney_57k boundary surface (19,126 triangles)
/// bent by 3 mean edges so that folds come within `thickness_edges` mean
/// edges of each other (the narrow phase, collision/narrow_phase.h), all
/// of them or `pruned` as the solver prunes them (nearest_few), every
/// vertex movable but those of the lowest `pinned` fraction of its height.
/// [in] data: the data folder. Empty on a missing mesh.
inline ContactSet kidney_contacts(const std::string& data, float thickness_edges, double pinned, bool pruned = false) {
  ContactSet s;
  auto mesh = read_tet_mesh(data + "/meshes/tet/kidney_57k.node");
  if (!mesh) return s;
  const TriMesh surface = extract_boundary_surface(*mesh);
  std::vector<float> x;
  std::vector<std::uint32_t> triangles;
  double edge = 0.0;
  for (const auto& v : surface.vertices) x.insert(x.end(), {float(v[0]), float(v[1]), float(v[2]), 0.0f});
  for (const auto& t : surface.triangles) {
    triangles.insert(triangles.end(), t.begin(), t.end());
    for (int e = 0; e < 3; ++e) {
      const auto& a = surface.vertices[t[e]];
      const auto& b = surface.vertices[t[(e + 1) % 3]];
      edge += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    }
  }
  const float mean_edge = float(edge / (3.0 * double(surface.triangles.size())));
  // The bend of tests/surface_support.h (frame 3, amplitude 3 mean edges).
  float lo = INFINITY, hi = -INFINITY, bottom = INFINITY, top = -INFINITY;
  for (std::size_t v = 0; v < x.size(); v += 4) {
    lo = std::min(lo, x[v]), hi = std::max(hi, x[v]);
    bottom = std::min(bottom, x[v + 1]), top = std::max(top, x[v + 1]);
  }
  const float k = 6.2831853f / (hi - lo), amount = 3.0f * mean_edge;
  const std::vector<float> rest = x;
  for (std::size_t v = 0; v < x.size(); v += 4) {
    const float* r = &rest[v];
    x[v] += amount * std::sin(k * r[1] + 0.3f);
    x[v + 1] += amount * std::sin(k * r[2] + 0.6f);
    x[v + 2] += amount * std::sin(k * r[0] + 0.9f);
  }
  const float thickness = thickness_edges * mean_edge;
  std::vector<collision::Aabb> boxes;
  if (!collision::primitive_boxes(x, triangles, 3, 0.5f * thickness, boxes).ok()) return s;
  collision::Bvh tree;
  tree.build(boxes);
  std::vector<collision::Pair> pairs;
  collision::self_overlapping_pairs(tree, collision::SharesVertex{triangles}, pairs);
  std::vector<collision::Contact> contacts;
  if (!collision::triangle_contacts(x, triangles, pairs, thickness, contacts).ok()) return s;
  if (pruned) contacts = nearest_few(contacts);
  s.movable.resize(surface.vertices.size());
  for (std::size_t v = 0; v < s.movable.size(); ++v)
    s.movable[v] = rest[4 * v + 1] >= bottom + float(pinned) * (top - bottom) ? 1 : 0;
  for (const collision::Contact& c : contacts) {
    s.particles.insert(s.particles.end(), c.v.begin(), c.v.end());
    // Both weights of the second primitive negative (mesh_contact_params.h).
    const bool vt = c.kind == collision::Contact::Kind::vertex_triangle;
    s.coefficients.insert(s.coefficients.end(), {c.w[0], vt ? -c.w[1] : c.w[1], -c.w[2], -c.w[3]});
    s.normals.insert(s.normals.end(), {c.normal[0], c.normal[1], c.normal[2], 0.0f});
  }
  s.positions = x;
  for (std::size_t v = 0; v < s.movable.size(); ++v) s.positions[4 * v + 3] = s.movable[v] ? 1.0f : 0.0f;
  s.thickness = thickness;
  return s;
}

}  // namespace sinew::test
