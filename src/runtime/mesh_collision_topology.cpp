// mesh_collision_topology.cpp — the collidable primitives after a topology
// change (issue 16; update_topology, see mesh_collision.h): each tet body's
// faces indexed once (index_tet_faces) so that its boundary follows the tets
// that die, in extract_boundary_surface's order; tri and line bodies
// replaced whole when they differ. A changed body's trees start anew and its
// rest-close pairs are carried over and completed; the other bodies keep
// theirs, and the triangles' ownership is carried over, looked up again only
// around the changed triangles. Why in place: a remake costs 20 ms on a
// 50,400-tet block, against the 2 ms a cut may add to its frame.
#include "runtime/mesh_collision.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "mesh/tet_faces.h"

namespace sinew {
namespace {

// Sorts (key, value) pairs by key, stably: least significant digit first,
// 11 bits a pass, as many passes as `bits` needs.
void radix_sort(std::vector<std::pair<std::uint64_t, std::uint32_t>>& items, int bits) {
  constexpr int kDigit = 11;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> other(items.size());
  std::vector<std::uint32_t> count(std::size_t{1} << kDigit);
  for (int shift = 0; shift < bits; shift += kDigit) {
    std::fill(count.begin(), count.end(), 0u);
    for (const auto& item : items) ++count[(item.first >> shift) & ((1u << kDigit) - 1)];
    std::uint32_t sum = 0;
    for (std::uint32_t& c : count) sum += std::exchange(c, sum);
    for (const auto& item : items) other[count[(item.first >> shift) & ((1u << kDigit) - 1)]++] = item;
    items.swap(other);
  }
}

// Bodies [from, to)'s primitives (`arity` particles each) into out and
// body_of: a changed body's `replaced`, an unchanged one's copied from its
// range of `indices`.
void assemble(const std::vector<std::uint8_t>& body_changed, const std::vector<std::vector<std::uint32_t>>& replaced,
              const std::vector<std::uint32_t>& indices,
              const std::vector<std::pair<std::uint32_t, std::uint32_t>>& ranges, std::size_t arity, std::uint32_t from,
              std::uint32_t to, std::vector<std::uint32_t>& out, std::vector<std::uint32_t>& body_of) {
  out.clear();
  body_of.clear();
  for (std::uint32_t b = from; b < to; ++b) {
    if (body_changed[b]) {
      out.insert(out.end(), replaced[b].begin(), replaced[b].end());
    } else {
      const auto [first, count] = ranges[b];
      out.insert(out.end(), indices.begin() + arity * first, indices.begin() + arity * (first + count));
    }
    body_of.resize(out.size() / arity, b);
  }
}

}  // namespace

// Each tet body's faces grouped by their three vertices (a radix sort of
// the packed sorted triples; a plain sort where they do not fit in 64
// bits), linked into rings; the boundary is the faces alone in theirs, as
// extract_boundary_surface finds it. With self-collision, the tets' rest
// boxes too (update_rest_close).
void MeshCollision::index_tet_faces(const SceneDesc& scene, const CompiledScene& compiled) {
  device_of_ = compiled.order.device_of;
  tri_first_.assign(compiled.tri_body_first_particle.begin(), compiled.tri_body_first_particle.end());
  line_first_.assign(compiled.line_body_first_particle.begin(), compiled.line_body_first_particle.end());
  rest_positions_.assign(4 * compiled.positions.size(), 0.0f);
  for (std::size_t p = 0; p < compiled.positions.size(); ++p) {
    const auto& x = compiled.positions[p];
    rest_positions_[4 * p] = x.x, rest_positions_[4 * p + 1] = x.y, rest_positions_[4 * p + 2] = x.z;
  }
  tet_faces_.resize(scene.tet_bodies.size());
  for (std::size_t b = 0; b < scene.tet_bodies.size(); ++b) {
    TetFaces& f = tet_faces_[b];
    const TetMesh& mesh = scene.tet_bodies[b].mesh;
    f.first_particle = compiled.tet_body_first_particle[b];
    f.tets = mesh.tets;
    f.alive.assign(f.tets.size(), 1);
    const std::size_t slots = 4 * f.tets.size();
    int bits = 1;
    while (bits < 32 && (std::uint64_t{1} << bits) < mesh.vertices.size()) ++bits;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(slots);
    std::vector<std::array<std::uint32_t, 3>> triples(3 * bits > 64 ? slots : 0);
    for (std::uint32_t s = 0; s < slots; ++s) {
      const auto& tet = f.tets[s / 4];
      std::array<std::uint32_t, 3> v{tet[kOutwardFaces[s % 4][0]], tet[kOutwardFaces[s % 4][1]],
                                     tet[kOutwardFaces[s % 4][2]]};
      std::sort(v.begin(), v.end());
      if (3 * bits > 64) triples[s] = v;
      else keys[s] = {(std::uint64_t{v[0]} << (2 * bits)) | (std::uint64_t{v[1]} << bits) | v[2], s};
    }
    if (3 * bits > 64) {  // over 2^21 vertices
      std::vector<std::uint32_t> order(slots);
      std::iota(order.begin(), order.end(), 0u);
      std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return triples[x] < triples[y]; });
      std::uint64_t group = 0;
      for (std::size_t k = 0; k < slots; ++k) {
        if (k > 0 && triples[order[k]] != triples[order[k - 1]]) ++group;
        keys[k] = {group, order[k]};
      }
    } else {
      radix_sort(keys, 3 * bits);
    }
    f.twin.resize(slots);
    f.on_boundary.assign(slots, 0);
    f.boundary.clear();
    for (std::size_t k = 0; k < slots;) {
      std::size_t end = k + 1;
      while (end < slots && keys[end].first == keys[k].first) ++end;
      for (std::size_t j = k; j < end; ++j) f.twin[keys[j].second] = keys[j + 1 < end ? j + 1 : k].second;
      if (end == k + 1) f.on_boundary[keys[k].second] = 1;
      k = end;
    }
    for (std::uint32_t s = 0; s < slots; ++s)
      if (f.on_boundary[s]) f.boundary.push_back(s);
    if (desc_.self_collision) {
      const auto half = static_cast<float>(0.5 * desc_.thickness);
      std::vector<collision::Aabb> boxes(f.tets.size());
      for (std::size_t t = 0; t < f.tets.size(); ++t) {
        collision::Aabb& box = boxes[t];
        box = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
        for (std::uint32_t v : f.tets[t])
          for (int a = 0; a < 3; ++a) {
            const float x = rest_positions_[4 * std::size_t{device_of_[f.first_particle + v]} + a];
            box.lo[a] = std::min(box.lo[a], x - half), box.hi[a] = std::max(box.hi[a], x + half);
          }
      }
      f.rest_tree.build(boxes);
    }
  }
}

void MeshCollision::boundary_triangles(const TetFaces& faces, std::vector<std::uint32_t>& out) const {
  for (std::uint32_t s : faces.boundary) {
    const auto& tet = faces.tets[s / 4];
    for (int k : kOutwardFaces[s % 4]) out.push_back(device_of_[faces.first_particle + tet[std::size_t(k)]]);
  }
}

Status MeshCollision::update_topology(Device& device, const SceneDesc& scene,
                                      std::span<const std::vector<std::uint8_t>* const> tet_alive, bool& changed) {
  changed = false;
  const auto tri_bodies = static_cast<std::uint32_t>(scene.tri_bodies.size());
  if (tet_faces_.size() != solid_bodies_ || tri_first_.size() != tri_bodies ||
      line_first_.size() != scene.line_bodies.size())
    return Error(ErrorCode::bad_parameter,
                 "mesh collision: update_topology needs a MeshCollision made with SceneDesc::topology_changes, "
                 "for a scene of as many bodies");
  if (tet_alive.size() != solid_bodies_)
    return Error(ErrorCode::bad_parameter, "mesh collision: update_topology takes one alive mask per tet body (" +
                                               std::to_string(solid_bodies_) + ", got " +
                                               std::to_string(tet_alive.size()) + ")");
  std::vector<std::vector<std::uint32_t>> died(solid_bodies_);
  if (Status s = tets_died(tet_alive, died); !s) return s;
  TopologyChange change;
  change.old_triangles = body_ranges(triangle_body_, body_count_);
  change.old_segments = body_ranges(segment_body_, body_count_);
  change.body_changed.assign(body_count_, 0);
  change.remap.resize(solid_bodies_ + tri_bodies);
  change.added.resize(solid_bodies_ + tri_bodies);
  change.replaced.resize(body_count_);
  update_tet_boundaries(died, change);
  compare_tri_bodies(scene, change);
  compare_line_bodies(scene, change);
  const std::vector<std::uint8_t>& body_changed = change.body_changed;
  if (std::find(body_changed.begin(), body_changed.end(), 1) == body_changed.end()) return {};
  changed = true;

  // The primitives in create()'s order: unchanged bodies copied, changed ones replaced.
  std::vector<std::uint32_t> triangles, triangle_body, segments, segment_body;
  assemble(body_changed, change.replaced, triangles_, change.old_triangles, 3, 0, solid_bodies_ + tri_bodies, triangles,
           triangle_body);
  assemble(body_changed, change.replaced, segments_, change.old_segments, 2, solid_bodies_ + tri_bodies, body_count_,
           segments, segment_body);
  triangles_.swap(triangles);
  triangle_body_.swap(triangle_body);
  segments_.swap(segments);
  segment_body_.swap(segment_body);

  if (Status s = retree(triangle_body_, triangle_body, triangle_trees_, true, change); !s) return s;
  if (Status s = retree(segment_body_, segment_body, segment_trees_, false, change); !s) return s;
  carry_ownership(change, triangles, solid_bodies_ + tri_bodies);
  index_primitives(false);

  // Room for the new surface's particles: the Jacobi schedule's lists of
  // touched particles hold up to every collidable one.
  MeshContactBuffers& buffers = buffers_;
  if (buffers.jacobi && collidable_.size() > buffers.touched_capacity) {
    const auto capacity = static_cast<std::uint32_t>(collidable_.size());
    if (Status s = device.resize_buffer(buffers.touched, std::size_t{capacity} * 4); !s) return s;
    if (Status s = device.resize_buffer(buffers.offsets, std::size_t{capacity + 1} * 4); !s) return s;
    buffers.touched_capacity = capacity;  // once both hold it
  }
  if (desc_.continuous)
    reserve_slots_ = std::max(reserve_slots_, static_cast<std::uint32_t>(segments_.size()));
  return {};
}

// Per tet body: the tets that died since the last call, ascending. The
// masks are compared 8 bytes at a time (a cut changes a few dozen of
// 50,000: the byte loop took 0.05 ms a pass).
Status MeshCollision::tets_died(std::span<const std::vector<std::uint8_t>* const> tet_alive,
                                std::vector<std::vector<std::uint32_t>>& died) const {
  for (std::uint32_t b = 0; b < solid_bodies_; ++b) {
    const TetFaces& f = tet_faces_[b];
    if (tet_alive[b] == nullptr || tet_alive[b]->size() != f.tets.size())
      return Error(ErrorCode::bad_parameter, "mesh collision: tet body " + std::to_string(b) + "'s alive mask has " +
                                                 std::to_string(tet_alive[b] ? tet_alive[b]->size() : 0) +
                                                 " entries for " + std::to_string(f.tets.size()) + " tets");
    const std::uint8_t* now = tet_alive[b]->data();
    const std::uint8_t* was = f.alive.data();
    const std::size_t n = f.tets.size();
    for (std::size_t t0 = 0; t0 < n; t0 += 8) {
      if (t0 + 8 <= n) {
        std::uint64_t x = 0, y = 0;
        std::memcpy(&x, now + t0, 8);
        std::memcpy(&y, was + t0, 8);
        if (x == y) continue;
      }
      for (std::size_t t = t0; t < std::min(n, t0 + 8); ++t) {
        if (now[t] && !was[t])
          return Error(ErrorCode::bad_parameter, "mesh collision: tet " + std::to_string(t) + " of body " +
                                                     std::to_string(b) + " is alive again");
        if (was[t] && !now[t]) died[b].push_back(static_cast<std::uint32_t>(t));
      }
    }
  }
  return {};
}

// Tet bodies: each face of a tet that died since the last call, and the
// faces in its ring, is on the boundary when its tet lives and it is the
// only live face of its ring (extract_boundary_surface's rule).
void MeshCollision::update_tet_boundaries(const std::vector<std::vector<std::uint32_t>>& died, TopologyChange& change) {
  const auto& old_triangles = change.old_triangles;
  auto& body_changed = change.body_changed;
  auto& remap = change.remap;
  auto& added = change.added;
  auto& replaced = change.replaced;
  for (std::uint32_t b = 0; b < solid_bodies_; ++b) {
    TetFaces& f = tet_faces_[b];
    std::vector<std::uint32_t> touched;
    for (std::uint32_t t : died[b]) {
      f.alive[t] = 0;
      for (std::uint32_t k = 0; k < 4; ++k) touched.push_back(4 * t + k);
    }
    if (touched.empty()) continue;
    std::vector<std::uint32_t> joined;
    for (std::uint32_t s : touched) {
      std::uint32_t live = 0;
      for (std::uint32_t u = s;;) {
        live += f.alive[u / 4];
        if ((u = f.twin[u]) == s) break;
      }
      for (std::uint32_t u = s;;) {
        const std::uint8_t boundary = f.alive[u / 4] && live == 1;
        if (boundary != f.on_boundary[u]) {
          f.on_boundary[u] = boundary;
          if (boundary) joined.push_back(u);
        }
        if ((u = f.twin[u]) == s) break;
      }
    }
    std::sort(joined.begin(), joined.end());
    // The new boundary: the old one's faces still on it, merged with those that joined.
    // Its triangles: a kept face's copied from the old ones (triangles_
    // holds boundary_triangles of the old boundary), a joined face's made.
    std::vector<std::uint32_t> boundary;
    boundary.reserve(f.boundary.size() + joined.size());
    remap[b].assign(f.boundary.size(), UINT32_MAX);
    std::vector<std::uint32_t>& out = replaced[b];
    out.reserve(3 * (f.boundary.size() + joined.size()));
    const std::uint32_t* old = triangles_.data() + 3 * std::size_t{old_triangles[b].first};
    const auto join = [&](std::uint32_t s) {
      added[b].push_back(static_cast<std::uint32_t>(boundary.size()));
      boundary.push_back(s);
      const auto& tet = f.tets[s / 4];
      for (int k : kOutwardFaces[s % 4]) out.push_back(device_of_[f.first_particle + tet[std::size_t(k)]]);
    };
    std::size_t j = 0;
    for (std::size_t i = 0; i < f.boundary.size(); ++i) {
      for (; j < joined.size() && joined[j] < f.boundary[i]; ++j) join(joined[j]);
      if (!f.on_boundary[f.boundary[i]]) continue;
      remap[b][i] = static_cast<std::uint32_t>(boundary.size());
      boundary.push_back(f.boundary[i]);
      out.insert(out.end(), old + 3 * i, old + 3 * i + 3);
    }
    for (; j < joined.size(); ++j) join(joined[j]);
    f.boundary = std::move(boundary);
    body_changed[b] = 1;
  }
}

// Tri bodies: replaced whole when their triangles differ. The carried
// pairs follow the old triangles that are still there in order (a removal
// keeps the rest in order); otherwise every triangle counts as new.
void MeshCollision::compare_tri_bodies(const SceneDesc& scene, TopologyChange& change) {
  const auto tri_bodies = static_cast<std::uint32_t>(scene.tri_bodies.size());
  const auto& old_triangles = change.old_triangles;
  auto& body_changed = change.body_changed;
  auto& remap = change.remap;
  auto& added = change.added;
  auto& replaced = change.replaced;
  for (std::uint32_t k = 0; k < tri_bodies; ++k) {
    const std::uint32_t b = solid_bodies_ + k;
    std::vector<std::uint32_t>& mine = replaced[b];
    for (const auto& t : scene.tri_bodies[k].mesh.triangles)
      for (std::uint32_t v : t) mine.push_back(device_of_[tri_first_[k] + v]);
    const auto [first, count] = old_triangles[b];
    const auto old = std::span<const std::uint32_t>(triangles_).subspan(3 * std::size_t{first}, 3 * std::size_t{count});
    if (std::equal(old.begin(), old.end(), mine.begin(), mine.end())) {
      mine.clear();
      continue;
    }
    body_changed[b] = 1;
    const std::size_t n = mine.size() / 3;
    remap[b].assign(count, UINT32_MAX);
    std::size_t j = 0;
    for (std::size_t i = 0; i < count && j < n; ++i)
      if (std::equal(&old[3 * i], &old[3 * i] + 3, &mine[3 * j])) remap[b][i] = static_cast<std::uint32_t>(j++);
    if (j < n) remap[b].assign(count, UINT32_MAX);  // not a removal: nothing carried
    std::vector<std::uint8_t> kept(n, 0);
    for (std::uint32_t r : remap[b])
      if (r != UINT32_MAX) kept[r] = 1;
    for (std::uint32_t t = 0; t < n; ++t)
      if (!kept[t]) added[b].push_back(t);
  }
}

// Line bodies: replaced whole when their segments differ.
void MeshCollision::compare_line_bodies(const SceneDesc& scene, TopologyChange& change) {
  const auto tri_bodies = static_cast<std::uint32_t>(scene.tri_bodies.size());
  auto& body_changed = change.body_changed;
  auto& replaced = change.replaced;
  for (std::uint32_t k = 0; k < scene.line_bodies.size(); ++k) {
    const std::uint32_t b = solid_bodies_ + tri_bodies + k;
    std::vector<std::uint32_t>& mine = replaced[b];
    for (const auto& s : scene.line_bodies[k].segments)
      for (std::uint32_t v : s) mine.push_back(device_of_[line_first_[k] + v]);
    const auto [first, count] = change.old_segments[b];
    const auto old = std::span<const std::uint32_t>(segments_).subspan(2 * std::size_t{first}, 2 * std::size_t{count});
    if (std::equal(old.begin(), old.end(), mine.begin(), mine.end())) mine.clear();
    else body_changed[b] = 1;
  }
}

// The trees: an unchanged body keeps its own (local indices), a changed
// one starts empty and is built in the next before_frame, as after create().
// [in] old_body_of: the body of each primitive before the change.
Status MeshCollision::retree(const std::vector<std::uint32_t>& body_of, const std::vector<std::uint32_t>& old_body_of,
                             std::vector<BodyTree>& trees, bool triangles_of, const TopologyChange& change) {
  const auto& body_changed = change.body_changed;
  const auto& remap = change.remap;
  const auto& added = change.added;
  std::vector<BodyTree> old(body_count_);
  for (BodyTree& t : trees) {
    const std::uint32_t b = old_body_of[t.first];  // the old body_of
    old[b] = std::move(t);
  }
  trees.clear();
  const auto ranges = body_ranges(body_of, body_count_);
  for (std::uint32_t b = 0; b < body_count_; ++b) {
    const auto [first, count] = ranges[b];
    if (count == 0) continue;
    if (!body_changed[b]) {
      trees.push_back(std::move(old[b]));
    } else {
      trees.emplace_back();
      if (triangles_of && desc_.self_collision) {
        trees.back().first = first;
        trees.back().count = count;
        if (Status s = update_rest_close(b, trees.back(), old[b].rest_close, remap[b], added[b]); !s) return s;
      }
    }
    trees.back().first = first;
    trees.back().count = count;
  }
  return {};
}

// The ownership (triangle_ownership of triangles_, 0.3 ms on the block's
// 5,000 triangles) carried over from the old one: bodies share no
// particle, so an unchanged body's owners are its own triangles, shifted
// with it. In a changed body, a kept triangle's vertex that no removed or
// added triangle has is on the same triangles as before, renumbered in
// the same order (remap keeps it), so its owner is the old owner
// renumbered; likewise an edge with such an end. Only the features around
// the changed triangles are looked up, among the new triangles around
// their lower vertex, ascending, as triangle_ownership does.
// [in] triangles: the triangles before the change (triangles_ as it was);
// triangle_bodies: the tet and tri bodies.
void MeshCollision::carry_ownership(const TopologyChange& change, const std::vector<std::uint32_t>& triangles,
                                    std::uint32_t triangle_bodies) {
  const auto& old_triangles = change.old_triangles;
  const auto& body_changed = change.body_changed;
  const auto& remap = change.remap;
  const auto& added = change.added;
  const auto new_triangles = body_ranges(triangle_body_, body_count_);
  std::vector<std::array<std::uint32_t, 6>>& owner = owner_scratch_;  // every row written below
  owner.resize(triangle_body_.size());
  std::vector<std::uint8_t>& dirty = dirty_;  // all 0 between calls
  dirty.resize(movable_.size(), 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> around;  // (dirty particle, new local triangle)
  std::vector<std::uint32_t> old_of;
  for (std::uint32_t b = 0; b < triangle_bodies; ++b) {
    const auto [nf, nc] = new_triangles[b];
    const auto [of, oc] = old_triangles[b];
    if (!body_changed[b]) {
      for (std::uint32_t t = 0; t < nc; ++t)
        for (int k = 0; k < 6; ++k) owner[std::size_t{nf} + t][k] = ownership_.owner[std::size_t{of} + t][k] - of + nf;
      continue;
    }
    const std::uint32_t* nt = triangles_.data() + 3 * std::size_t{nf};
    const std::uint32_t* ot = triangles.data() + 3 * std::size_t{of};  // the old triangles_ (swapped)
    const std::vector<std::uint32_t>& map = remap[b];
    old_of.assign(nc, UINT32_MAX);
    for (std::uint32_t i = 0; i < oc; ++i) {
      if (i < map.size() && map[i] != UINT32_MAX) old_of[map[i]] = i;
      else
        for (int c = 0; c < 3; ++c) dirty[ot[3 * std::size_t{i} + c]] = 1;
    }
    for (std::uint32_t t : added[b])
      for (int c = 0; c < 3; ++c) dirty[nt[3 * std::size_t{t} + c]] = 1;
    around.clear();
    for (std::uint32_t t = 0; t < nc; ++t)
      for (int c = 0; c < 3; ++c)
        if (dirty[nt[3 * std::size_t{t} + c]]) around.push_back({nt[3 * std::size_t{t} + c], t});
    std::stable_sort(around.begin(), around.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    const auto first_around = [&](std::uint32_t v) {
      return std::lower_bound(around.begin(), around.end(), v, [](const auto& x, std::uint32_t w) { return x.first < w; });
    };
    const auto has_edge = [&](std::uint32_t u, std::uint32_t lo, std::uint32_t hi) {
      const std::uint32_t* x = nt + 3 * std::size_t{u};
      for (int e = 0; e < 3; ++e)
        if (std::min(x[e], x[(e + 1) % 3]) == lo && std::max(x[e], x[(e + 1) % 3]) == hi) return true;
      return false;
    };
    for (std::uint32_t t = 0; t < nc; ++t) {
      const std::uint32_t i = old_of[t];
      auto& row = owner[std::size_t{nf} + t];
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t v = nt[3 * std::size_t{t} + c], w = nt[3 * std::size_t{t} + (c + 1) % 3];
        if (i != UINT32_MAX && !dirty[v]) row[c] = map[ownership_.owner[std::size_t{of} + i][c] - of] + nf;
        else row[c] = first_around(v)->second + nf;
        if (i != UINT32_MAX && (!dirty[v] || !dirty[w])) {
          row[3 + c] = map[ownership_.owner[std::size_t{of} + i][3 + c] - of] + nf;
        } else {
          const std::uint32_t lo = std::min(v, w), hi = std::max(v, w);
          auto k = first_around(lo);
          while (!has_edge(k->second, lo, hi)) ++k;  // ends at t itself at the latest
          row[3 + c] = k->second + nf;
        }
      }
    }
    for (std::uint32_t i = 0; i < oc; ++i)
      if (!(i < map.size() && map[i] != UINT32_MAX))
        for (int c = 0; c < 3; ++c) dirty[ot[3 * std::size_t{i} + c]] = 0;
    for (std::uint32_t t : added[b])
      for (int c = 0; c < 3; ++c) dirty[nt[3 * std::size_t{t} + c]] = 0;
  }
  ownership_.owner.swap(owner);  // the old rows: the next call's scratch
}

}  // namespace sinew
