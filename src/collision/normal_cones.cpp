// normal_cones.cpp — normal cones and connectivity of BVH nodes (see
// normal_cones.h).
#include "collision/normal_cones.h"
#include "hooks/hooks_internal.h"

#include <algorithm>
#include <array>
#include <iterator>
#include <cmath>
#include <numeric>


namespace sinew::collision {
namespace {

// The unit normal of the triangle with corners `corners` at `x` into n;
// false for a zero-area or non-finite triangle.
bool unit_normal(std::span<const float> x, const std::uint32_t* corners, float n[3]) {
  const float* a = &x[4 * std::size_t{corners[0]}];
  const float* b = &x[4 * std::size_t{corners[1]}];
  const float* c = &x[4 * std::size_t{corners[2]}];
  const float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const float v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  n[0] = u[1] * v[2] - u[2] * v[1];
  n[1] = u[2] * v[0] - u[0] * v[2];
  n[2] = u[0] * v[1] - u[1] * v[0];
  const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(length > 0.0f) || !std::isfinite(length)) return false;
  for (int k = 0; k < 3; ++k) n[k] /= length;
  return true;
}

}  // namespace

// Connectivity by union-find over the triangles' shared vertices, each
// sharing united at the lowest node holding both its triangles: visiting the nodes
// from the deepest up (children come after their parents in Bvh::nodes()),
// a node's components are its children's minus the unions made at it.
// Linear but for the union-find: counting sorts instead of comparison
// sorts, and each vertex's boundary nodes found by climbing from its
// triangles' leaves to their common ancestor instead of merging per-node
// vertex lists up the tree (a 5,000-triangle surface: 5 ms before, paid at
// every rebuild and after every topology change). Everything is indexed by
// leaf slot (Bvh::order()): a node's triangles are one run of slots, so
// the lowest node holding slots a <= b is the first node up from a's leaf
// whose run reaches b, and an open edge is an edge named once in the
// edges grouped by their lower vertex (the 4,960 triangles of a 50,400-tet
// block's surface, rebuilt after each cut: 2.0 -> 0.8 ms, min of 4).
void NormalCones::connect(const Bvh& tree, std::span<const std::uint32_t> triangles) {
  const auto& nodes = tree.nodes();
  const auto& order = tree.order();
  const std::size_t n = nodes.size();
  const auto slots = static_cast<std::uint32_t>(order.size());
  // The triangles' corners in leaf order: every pass below reads them in sequence.
  corners_.resize(3 * std::size_t{slots});
  for (std::size_t slot = 0; slot < slots; ++slot)
    for (int c = 0; c < 3; ++c) corners_[3 * slot + std::size_t(c)] = triangles[3 * std::size_t{order[slot]} + std::size_t(c)];
  // Per node: its parent and the end of its run of slots; per slot: its leaf.
  std::vector<std::uint32_t> parent(n, 0), end(n), leaf_of(slots), count(n);
  for (std::size_t i = n; i-- > 0;) {
    if (nodes[i].count > 0) {
      end[i] = nodes[i].first + nodes[i].count;
      count[i] = nodes[i].count;
      for (std::uint32_t s = nodes[i].first; s < end[i]; ++s) leaf_of[s] = static_cast<std::uint32_t>(i);
    } else {
      parent[nodes[i].left] = parent[nodes[i].left + 1] = static_cast<std::uint32_t>(i);
      end[i] = end[nodes[i].left + 1];
      count[i] = count[nodes[i].left] + count[nodes[i].left + 1];
    }
  }
  const auto common = [&](std::uint32_t a, std::uint32_t b) {  // the lowest node holding slots a <= b
    std::uint32_t i = leaf_of[a];
    while (end[i] <= b) i = parent[i];
    return i;
  };
  // The triangles around each vertex, in leaf order (slots): vertex v's
  // are around[around_first[v] .. around_first[v + 1]), a counting sort by
  // vertex of the slots taken in order. Uniting neighbours in that order
  // is enough: a node's triangles are one run of slots, so the ones of it
  // around a vertex are consecutive there, and their unions all happen at
  // or below the node.
  std::uint32_t vertices = 0;
  for (const std::uint32_t v : corners_) vertices = std::max(vertices, v + 1);
  std::vector<std::uint32_t> around_first(std::size_t{vertices} + 1, 0), around(corners_.size());
  for (const std::uint32_t v : corners_) ++around_first[std::size_t{v} + 1];
  for (std::size_t v = 0; v < vertices; ++v) around_first[v + 1] += around_first[v];
  {
    std::vector<std::uint32_t> next(around_first.begin(), around_first.end() - 1);
    for (std::size_t k = 0; k < corners_.size(); ++k) around[next[corners_[k]]++] = static_cast<std::uint32_t>(k / 3);
  }
  // Three independent passes, run side by side on the host's threads: the
  // nodes' connectivity, their open edges, their boundary vertices.
  const auto connectivity = [&] {
    // The unions (node, slot, slot), grouped by node (a counting sort).
    std::vector<std::array<std::uint32_t, 3>> made;
    made.reserve(around.size());
    for (std::uint32_t v = 0; v < vertices; ++v)
      for (std::uint32_t k = around_first[v] + 1; k < around_first[v + 1]; ++k) {
        const std::uint32_t s = around[k - 1], t = around[k];
        if (s != t) made.push_back({common(s, t), s, t});  // s == t: a triangle listed twice around v
      }
    std::vector<std::uint32_t> union_first(n + 1, 0);
    for (const auto& u : made) ++union_first[std::size_t{u[0]} + 1];
    for (std::size_t i = 0; i < n; ++i) union_first[i + 1] += union_first[i];
    std::vector<std::array<std::uint32_t, 2>> unions(made.size());
    {
      std::vector<std::uint32_t> next(union_first.begin(), union_first.end() - 1);
      for (const auto& u : made) unions[next[u[0]]++] = {u[1], u[2]};
    }
    std::vector<std::uint32_t> root(slots);
    std::iota(root.begin(), root.end(), 0u);
    const auto find = [&](std::uint32_t x) {
      while (root[x] != x) x = root[x] = root[root[x]];
      return x;
    };
    std::vector<std::uint32_t> components(n);
    connected_.assign(n, 0);
    for (std::size_t i = n; i-- > 0;) {
      components[i] = nodes[i].count > 0 ? count[i] : components[nodes[i].left] + components[nodes[i].left + 1];
      for (std::uint32_t k = union_first[i]; k < union_first[i + 1]; ++k) {
        const std::uint32_t a = find(unions[k][0]), b = find(unions[k][1]);
        if (a != b) root[a] = b, --components[i];
      }
      connected_[i] = components[i] == 1;
    }
  };
  const auto open_edges = [&] {
    // Open edges (one triangle only: a membrane's border, a slit's lips): a
    // node with a triangle on one is never flat, nor culled against another.
    // Every triangle's three edges, grouped by their lower vertex (a counting
    // sort); within a group, an upper vertex named once is an open edge's
    // (a degenerate triangle's repeated edge is named twice).
    std::vector<std::uint32_t> edge_first(std::size_t{vertices} + 1, 0);
    const auto lower = [&](std::size_t k) {  // edge k: corners k and the next of its triangle
      const std::size_t other = k % 3 == 2 ? k - 2 : k + 1;
      return std::min(corners_[k], corners_[other]);
    };
    for (std::size_t k = 0; k < corners_.size(); ++k) ++edge_first[std::size_t{lower(k)} + 1];
    for (std::size_t v = 0; v < vertices; ++v) edge_first[v + 1] += edge_first[v];
    std::vector<std::uint32_t> edges(corners_.size());  // edge k = 3 slot + c, by lower vertex
    {
      std::vector<std::uint32_t> next(edge_first.begin(), edge_first.end() - 1);
      for (std::size_t k = 0; k < corners_.size(); ++k) edges[next[lower(k)]++] = static_cast<std::uint32_t>(k);
    }
    const auto upper = [&](std::uint32_t k) { return std::max(corners_[k], corners_[k % 3 == 2 ? k - 2 : k + 1]); };
    std::vector<std::uint8_t> open_slot(slots, 0);
    std::vector<std::uint32_t> named(vertices, 0);  // per upper vertex: times named in the group (reset after it)
    for (std::uint32_t v = 0; v < vertices; ++v) {
      for (std::uint32_t e = edge_first[v]; e < edge_first[v + 1]; ++e) ++named[upper(edges[e])];
      for (std::uint32_t e = edge_first[v]; e < edge_first[v + 1]; ++e)
        if (named[upper(edges[e])] == 1) open_slot[edges[e] / 3] = 1;
      for (std::uint32_t e = edge_first[v]; e < edge_first[v + 1]; ++e) named[upper(edges[e])] = 0;
    }
    open_.assign(n, 0);
    for (std::size_t i = n; i-- > 0;) {
      if (nodes[i].count > 0) {
        for (std::uint32_t slot = nodes[i].first; slot < end[i]; ++slot) open_[i] |= open_slot[slot];
      } else {
        open_[i] = open_[nodes[i].left] | open_[nodes[i].left + 1];
      }
    }
  };
  const auto boundaries = [&] {
    // Boundary vertices: a vertex is on a node's boundary when the node
    // holds some but not all of the triangles around it: the nodes on the
    // way up from those triangles' leaves to their lowest common ancestor
    // (which holds them all: the lowest node holding the first and the last
    // of its slots), met once each (stamped with the vertex).
    // Vertices are visited in increasing order and the pairs grouped by node
    // by a stable counting sort, so each node's list comes out sorted.
    std::vector<std::array<std::uint32_t, 2>> pairs;  // (node, vertex)
    std::vector<std::uint32_t> stamp(n, UINT32_MAX);
    for (std::uint32_t v = 0; v < vertices; ++v) {
      const std::uint32_t lo = around_first[v], hi = around_first[v + 1];
      if (lo == hi) continue;
      const std::uint32_t top = common(around[lo], around[hi - 1]);
      for (std::uint32_t k = lo; k < hi; ++k)
        for (std::uint32_t i = leaf_of[around[k]]; i != top && stamp[i] != v; i = parent[i]) {
          stamp[i] = v;
          pairs.push_back({i, v});
        }
    }
    boundary_first_.assign(n + 1, 0);
    for (const auto& p : pairs) ++boundary_first_[std::size_t{p[0]} + 1];
    for (std::size_t i = 0; i < n; ++i) boundary_first_[i + 1] += boundary_first_[i];
    boundary_.resize(pairs.size());
    {
      std::vector<std::uint32_t> next(boundary_first_.begin(), boundary_first_.end() - 1);
      for (const auto& p : pairs) boundary_[next[p[0]]++] = p[1];
    }
  };
  hooks::parallel_invoke({connectivity, open_edges, boundaries});
  leaves_.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (nodes[i].count > 0) leaves_.push_back(static_cast<std::uint32_t>(i));
  build_id_ = tree.build_id();
}

bool NormalCones::pair(std::uint32_t a, std::uint32_t b) const {
  // flat_: connected, without open edges, a cone within kFlatDegrees (one
  // byte per node; most node pairs stop here).
  if (!flat_[a] || !flat_[b]) return false;
  float axis[3] = {sum_[3 * a] + sum_[3 * b], sum_[3 * a + 1] + sum_[3 * b + 1], sum_[3 * a + 2] + sum_[3 * b + 2]};
  const float length = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  if (!(length > 0.0f)) return false;
  for (float& x : axis) x /= length;
  for (const std::uint32_t c : {a, b}) {
    const Cone& cone = cones_[c];
    const float cos_phi =
        std::clamp(axis[0] * cone.axis[0] + axis[1] * cone.axis[1] + axis[2] * cone.axis[2], -1.0f, 1.0f);
    if (cos_phi * cone.cos - std::sqrt(1.0f - cos_phi * cos_phi) * sin_[c] < flat_cos_) return false;
  }
  // A shared vertex, by merging the two sorted boundaries.
  const std::uint32_t* p = boundary_.data() + boundary_first_[a];
  const std::uint32_t* p_end = boundary_.data() + boundary_first_[a + 1];
  const std::uint32_t* q = boundary_.data() + boundary_first_[b];
  const std::uint32_t* q_end = boundary_.data() + boundary_first_[b + 1];
  while (p != p_end && q != q_end) {
    if (*p == *q) return true;
    if (*p < *q) ++p;
    else ++q;
  }
  return false;
}

void NormalCones::update(const Bvh& tree, std::span<const std::uint32_t> triangles, std::span<const float> positions) {
  if (build_id_ != tree.build_id() || connected_.size() != tree.nodes().size()) connect(tree, triangles);
  refresh(tree, corners_, positions);
}

void NormalCones::update(const Bvh& tree, std::span<const std::uint32_t> triangles, const LeafVertices& leaf) {
  if (build_id_ != tree.build_id() || connected_.size() != tree.nodes().size()) connect(tree, triangles);
  if (leaf.build_id() != tree.build_id()) {  // gathered for another shape: cull nothing rather than guess
    flat_.assign(tree.nodes().size(), 0);
    return;
  }
  refresh(tree, leaf.corners(), leaf.positions());
}

void NormalCones::refresh(const Bvh& tree, std::span<const std::uint32_t> corners, std::span<const float> positions) {
  const auto& nodes = tree.nodes();
  const std::size_t n = nodes.size();
  const float flat_cos = flat_cos_ = std::cos(kFlatDegrees * 3.14159265358979f / 180.0f);
  cones_.resize(n);
  sum_.resize(3 * n);
  sin_.resize(n);
  flat_.resize(n);
  const auto wide = [&](std::size_t i) {
    cones_[i] = {{0.0f, 0.0f, 0.0f}, -1.0f};
    sin_[i] = 0.0f;
    flat_[i] = 0;
  };
  // The cone around sum_[i] is set: keep it if narrow enough.
  const auto finish = [&](std::size_t i) {
    if (cones_[i].cos < flat_cos) return wide(i);
    sin_[i] = std::sqrt(std::max(0.0f, 1.0f - cones_[i].cos * cones_[i].cos));
    flat_[i] = connected_[i] && !open_[i];
  };
  // The axis: the node's summed normals, normalised; false if they cancel.
  const auto axis = [&](std::size_t i) {
    const float* sum = &sum_[3 * i];
    const float length = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
    if (!(length > 0.0f)) return false;
    for (int a = 0; a < 3; ++a) cones_[i].axis[a] = sum[a] / length;
    return true;
  };
  // Leaves: the normals themselves. (On TBB's
  // threads this took as long on 2 cores, 2.0 ms for the liver's surface:
  // the vertex reads bound it, and the solver's own threads then waited on
  // TBB's, so it stays serial.)
  for (const std::uint32_t i : leaves_) {
    const Bvh::Node& node = nodes[i];
    float normals[Bvh::kLeafSize][3];
    std::uint32_t m = 0;
    bool ok = true;
    for (std::uint32_t s = 0; s < node.count; ++s)
      ok = ok && unit_normal(positions, &corners[3 * (std::size_t{node.first} + s)], normals[m++]);
    float* sum = &sum_[3 * i];
    sum[0] = sum[1] = sum[2] = 0.0f;
    for (std::uint32_t q = 0; ok && q < m; ++q)
      for (int a = 0; a < 3; ++a) sum[a] += normals[q][a];
    if (!ok || !axis(i)) {
      wide(i);
      continue;
    }
    Cone& cone = cones_[i];
    cone.cos = 1.0f;
    for (std::uint32_t q = 0; q < m; ++q)
      cone.cos = std::min(cone.cos, cone.axis[0] * normals[q][0] + cone.axis[1] * normals[q][1] +
                                        cone.axis[2] * normals[q][2]);
    finish(i);
  }
  // Inner nodes, children first: around the children's summed normals, wide
  // enough for both children's cones (angle to a child's axis plus its
  // half-angle).
  for (std::size_t i = n; i-- > 0;) {
    const Bvh::Node& node = nodes[i];
    if (node.count > 0) continue;
    const std::uint32_t l = node.left, r = node.left + 1;
    for (int a = 0; a < 3; ++a) sum_[3 * i + a] = sum_[3 * l + a] + sum_[3 * r + a];
    if (cones_[l].cos < flat_cos || cones_[r].cos < flat_cos || !axis(i)) {
      wide(i);
      continue;
    }
    Cone& cone = cones_[i];
    cone.cos = 1.0f;
    for (const std::uint32_t c : {l, r}) {
      const Cone& child = cones_[c];
      const float cos_phi = std::clamp(
          cone.axis[0] * child.axis[0] + cone.axis[1] * child.axis[1] + cone.axis[2] * child.axis[2], -1.0f, 1.0f);
      const float sin_phi = std::sqrt(1.0f - cos_phi * cos_phi);
      cone.cos = std::min(cone.cos, cos_phi * child.cos - sin_phi * sin_[c]);  // cos(phi + theta)
    }
    finish(i);
  }
}

}  // namespace sinew::collision
