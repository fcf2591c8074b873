// mesh_collision_trees.cpp — the collidable primitives' indices and trees
// (see mesh_collision.h): each body's primitive range, the particles' bodies,
// the solid surfaces' faces around each particle (across_air looks an edge
// up there), the trees refitted to the frame's boxes, and the pairs of
// triangles closer than the thickness at rest (found at create(), carried
// over and completed after a topology change), which self-collision skips.
#include "runtime/mesh_collision.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "mesh/tet_faces.h"

namespace sinew {
namespace {

// Every primitive of `tree` whose box overlaps `box`. [out] out, appended.
void tree_query(const collision::Bvh& tree, const collision::Aabb& box, std::vector<std::uint32_t>& out) {
  if (tree.empty()) return;
  const auto& nodes = tree.nodes();
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const collision::Bvh::Node& node = nodes[stack[--top]];
    if (!collision::overlap(node.box, box)) continue;
    if (node.count > 0) {
      for (std::uint32_t s = node.first; s < node.first + node.count; ++s)
        if (collision::overlap(tree.leaf_boxes()[s], box)) out.push_back(tree.order()[s]);
    } else {
      stack[top++] = node.left;
      stack[top++] = node.left + 1;
    }
  }
}

}  // namespace

// The runs of `body_of` (one body's primitives are contiguous): per body
// of `bodies`, its (first, count); count 0 for a body with none.
std::vector<std::pair<std::uint32_t, std::uint32_t>> MeshCollision::body_ranges(
    const std::vector<std::uint32_t>& body_of, std::uint32_t bodies) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges(bodies, {0u, 0u});
  for (std::uint32_t k = 0; k < body_of.size(); ++k) {
    auto& r = ranges[body_of[k]];
    if (r.second == 0) r.first = k;
    ++r.second;
  }
  return ranges;
}

// The broad phase at the start (boxes grown by half the thickness: every
// pair closer than it overlaps), then the exact distance of each candidate.
// A mesh's fissures and sharp creases, closer than the thickness before
// anything moves, would otherwise be pushed apart to it in the first frame:
// the liver_382k surface at 1 mm has 683 facing vertex-triangle contacts at
// rest, the nearest 0.03 mm, and with self-collision on the organ example
// blew up (28 m/s by frame 20, then the pair capacity error).
Status MeshCollision::find_rest_close(std::span<const float> start) {
  std::vector<collision::Pair> pairs;
  for (BodyTree& body : triangle_trees_) {
    const auto mine = std::span<const std::uint32_t>(triangles_).subspan(std::size_t{body.first} * 3,
                                                                         std::size_t{body.count} * 3);
    if (Status s = collision::rest_close_pairs(start, mine, static_cast<float>(desc_.thickness), pairs); !s) return s;
    body.rest_close = collision::PairSet(pairs, body.count);
  }
  return {};
}

// The solid surface triangles around each particle, ascending (a counting
// sort): an edge's faces are among its lower vertex's.
void MeshCollision::index_solid_edges() {
  solid_first_.assign(movable_.size() + 1, 0);
  for (std::size_t k = 0; k < 3 * solid_triangles_; ++k) ++solid_first_[std::size_t{triangles_[k]} + 1];
  for (std::size_t p = 0; p < movable_.size(); ++p) solid_first_[p + 1] += solid_first_[p];
  solid_around_.resize(3 * solid_triangles_);
  std::vector<std::uint32_t> next(solid_first_.begin(), solid_first_.end() - 1);
  for (std::uint32_t t = 0; t < solid_triangles_; ++t)
    for (int k = 0; k < 3; ++k) solid_around_[next[triangles_[3 * std::size_t{t} + k]]++] = t;
}

template <class Visit>
void MeshCollision::faces_on(std::uint32_t a, std::uint32_t b, Visit visit) const {
  const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
  if (std::size_t{lo} + 1 >= solid_first_.size()) return;
  std::uint32_t last = UINT32_MAX;
  for (std::uint32_t k = solid_first_[lo]; k < solid_first_[lo + 1]; ++k) {
    const std::uint32_t t = solid_around_[k];
    if (t == last) continue;  // a triangle listed twice around lo (a degenerate one)
    last = t;
    const std::uint32_t* v = &triangles_[3 * std::size_t{t}];
    for (int e = 0; e < 3; ++e)  // once per edge of t that is {lo, hi}
      if (std::min(v[e], v[(e + 1) % 3]) == lo && std::max(v[e], v[(e + 1) % 3]) == hi) visit(t);
  }
}

std::uint32_t MeshCollision::solid_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
  std::uint32_t found = UINT32_MAX;
  faces_on(a, b, [&](std::uint32_t t) {
    const std::uint32_t* v = &triangles_[3 * std::size_t{t}];
    if (found == UINT32_MAX && (v[0] == c || v[1] == c || v[2] == c)) found = t;
  });
  return found;
}

bool MeshCollision::solid_edge(std::uint32_t a, std::uint32_t b, float out[3]) const {
  bool any = false;
  out[0] = out[1] = out[2] = 0.0f;
  faces_on(a, b, [&](std::uint32_t t) {
    any = true;
    for (int d = 0; d < 3; ++d) out[d] += face_out_[3 * std::size_t{t} + d];
  });
  return any;
}

void MeshCollision::index_primitives(bool ownership) {
  const std::size_t particles = movable_.size();
  body_of_.assign(particles, UINT32_MAX);
  for (std::size_t t = 0; t < triangle_body_.size(); ++t)
    for (int k = 0; k < 3; ++k) body_of_[triangles_[3 * t + k]] = triangle_body_[t];
  for (std::size_t t = 0; t < segment_body_.size(); ++t)
    for (int k = 0; k < 2; ++k) body_of_[segments_[2 * t + k]] = segment_body_[t];
  if (ownership) ownership_ = collision::triangle_ownership(triangles_);
  solid_triangles_ = 0;
  while (solid_triangles_ < triangle_body_.size() && triangle_body_[solid_triangles_] < solid_bodies_) ++solid_triangles_;
  if (desc_.self_collision) index_solid_edges();
  // Every particle of a primitive, ascending.
  std::vector<std::uint8_t> used(particles, 0);
  for (std::uint32_t v : triangles_) used[v] = 1;
  for (std::uint32_t v : segments_) used[v] = 1;
  collidable_.clear();
  for (std::uint32_t p = 0; p < particles; ++p)
    if (used[p]) collidable_.push_back(p);
}

std::uint32_t MeshCollision::rest_close_pairs() const {
  std::size_t sum = 0;
  for (const BodyTree& body : triangle_trees_) sum += body.rest_close.size();
  return static_cast<std::uint32_t>(sum);
}

void MeshCollision::refit(std::vector<BodyTree>& trees, std::span<const collision::Aabb> boxes) {
  for (BodyTree& t : trees) {
    const auto mine = boxes.subspan(t.first, t.count);
    if (t.tree.empty()) t.tree.build(mine);
    else t.tree.refit(mine);
  }
}

// A tri body's added triangles are tested against all its triangles up to
// this many box tests; past it, its pairs are all found afresh.
constexpr std::size_t kMaxRestTests = std::size_t{1} << 20;

// The carried pairs, then the added triangles' own: each added triangle's
// rest box (grown by half the thickness, as rest_close_pairs grows them)
// against the body's tets' rest boxes (a tet body: its faces on the
// boundary now are the candidates) or the body's triangles' (a tri body),
// kept when the triangles share no vertex and are closer than the
// thickness (rest_close_pairs' test, in the same argument order).
Status MeshCollision::update_rest_close(std::uint32_t body, BodyTree& tree, const collision::PairSet& old,
                                       std::span<const std::uint32_t> remap, std::span<const std::uint32_t> added) {
  std::vector<collision::Pair> pairs;
  for (const auto& [i, j] : old.pairs())
    if (i < remap.size() && j < remap.size() && remap[i] != UINT32_MAX && remap[j] != UINT32_MAX)
      pairs.push_back({remap[i], remap[j]});
  const auto mine = std::span<const std::uint32_t>(triangles_).subspan(std::size_t{tree.first} * 3,
                                                                       std::size_t{tree.count} * 3);
  const auto thickness = static_cast<float>(desc_.thickness);
  if (!added.empty()) {
    std::vector<std::uint32_t> corners;
    corners.reserve(3 * added.size());
    for (std::uint32_t t : added) corners.insert(corners.end(), &mine[3 * std::size_t{t}], &mine[3 * std::size_t{t}] + 3);
    std::vector<collision::Aabb> boxes;
    if (Status s = collision::primitive_boxes(rest_positions_, corners, 3, 0.5f * thickness, boxes); !s) return s;
    const collision::SharesVertexOf<3> shares{mine};
    // The pair of added triangle k and local triangle `other`, when their
    // boxes overlap (rest_close_pairs' candidates), kept if close.
    // A separating axis first (triangles_apart, 50 times cheaper than the
    // distance): it rejects a pair only when its exact distance exceeds the
    // thickness by 1e-4 of the pair's largest coordinate, far beyond the
    // float error of triangle_distance (a few ulps of the coordinates: it
    // measures between points on the two triangles), so every pair it
    // rejects triangle_distance would have put at or past the thickness.
    const auto test = [&](std::size_t k, std::uint32_t other, const collision::Aabb& other_box) {
      const std::uint32_t i = std::min(added[k], other), j = std::max(added[k], other);
      if (i == j || !collision::overlap(boxes[k], other_box) || shares(i, j)) return;
      const std::uint32_t* a = &mine[3 * std::size_t{i}];
      const std::uint32_t* b = &mine[3 * std::size_t{j}];
      float scale = 0.0f;
      for (const std::uint32_t* v : {a, b})
        for (int c = 0; c < 3; ++c)
          for (int d = 0; d < 3; ++d) scale = std::max(scale, std::abs(rest_positions_[4 * std::size_t{v[c]} + d]));
      if (collision::triangles_apart(rest_positions_, a, b, thickness + 1e-4f * scale)) return;
      if (collision::triangle_distance(rest_positions_, a, b) < thickness) pairs.push_back({i, j});
    };
    if (body < solid_bodies_) {
      // The boundary faces of the tets whose rest boxes the added
      // triangle's meets (a face's box lies in its tet's).
      const TetFaces& f = tet_faces_[body];
      // (The face's box made here as primitive_boxes makes it, from the
      // face's corners, and its index looked up only when the boxes meet.)
      std::vector<std::uint32_t> tets;
      const float half = 0.5f * thickness;
      for (std::size_t k = 0; k < added.size(); ++k) {
        tets.clear();
        tree_query(f.rest_tree, boxes[k], tets);
        for (std::uint32_t tet : tets)
          for (std::uint32_t s = 4 * tet; s < 4 * tet + 4; ++s) {
            if (!f.on_boundary[s]) continue;
            collision::Aabb face_box{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
            for (int c : kOutwardFaces[s % 4]) {
              const float* x = &rest_positions_[4 * std::size_t{device_of_[f.first_particle + f.tets[tet][std::size_t(c)]]}];
              for (int d = 0; d < 3; ++d)
                face_box.lo[d] = std::min(face_box.lo[d], x[d]), face_box.hi[d] = std::max(face_box.hi[d], x[d]);
            }
            for (int d = 0; d < 3; ++d) face_box.lo[d] -= half, face_box.hi[d] += half;
            if (!collision::overlap(boxes[k], face_box)) continue;
            const auto other = static_cast<std::uint32_t>(std::lower_bound(f.boundary.begin(), f.boundary.end(), s) -
                                                          f.boundary.begin());
            test(k, other, face_box);
          }
      }
    } else if (added.size() * std::size_t{tree.count} <= kMaxRestTests) {
      std::vector<collision::Aabb> all;
      if (Status s = collision::primitive_boxes(rest_positions_, mine, 3, 0.5f * thickness, all); !s) return s;
      for (std::size_t k = 0; k < added.size(); ++k)
        for (std::uint32_t other = 0; other < tree.count; ++other) test(k, other, all[other]);
    } else {  // a tri body mostly new: all its pairs found afresh
      if (Status s = collision::rest_close_pairs(rest_positions_, mine, thickness, pairs); !s) return s;
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  tree.rest_close = collision::PairSet(pairs, tree.count);
  return {};
}

}  // namespace sinew
