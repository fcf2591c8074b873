// topology_editor.cpp — see topology_editor.h (Box2D v3's constraint
// graph: colours with spare capacity, a removal moves the colour's last
// constraint into the freed slot).
#include "runtime/topology_editor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "compiler/edge_network.h"
#include "math/thin_math.h"
#include "mesh/tet_faces.h"
#include "math/xpbd_math.h"
#include "runtime/topology_queries.h"

namespace sinew {

namespace {

// The blocks whose constraints a change can remove or soften (graspers'
// and contacts' blocks are managed by their owners).
bool is_editable(Kernel k) {
  switch (k) {
    case Kernel::xpbd_solve_volume:
    case Kernel::xpbd_solve_neo_hookean:
    case Kernel::xpbd_solve_stvk:
    case Kernel::xpbd_solve_corotational:
    case Kernel::xpbd_solve_area:
    case Kernel::xpbd_solve_dihedral:
    case Kernel::xpbd_solve_distance:
    case Kernel::xpbd_solve_line_bending: return true;
    default: return false;
  }
}

// Writes slots [first, first + count) of a per-slot array of `words` 32-bit
// words each.
template <class T>
Status write_slots(Device& device, BufferHandle buffer, const std::vector<T>& host, std::uint32_t words,
                   std::uint32_t first, std::uint32_t count) {
  return device.write_buffer(buffer, std::size_t{first} * words * 4, host.data() + std::size_t{first} * words,
                             std::size_t{count} * words * 4);
}

}  // namespace

std::size_t TopologyEditor::ElementKeyHash::operator()(const ElementKey& k) const noexcept {
  std::size_t h = 1469598103934665603ull;
  for (std::uint32_t v : k) h = (h ^ v) * 1099511628211ull;
  return h;
}

std::uint64_t TopologyEditor::edge_key(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t{a} << 32) | b;
}

TopologyEditor::ElementKey TopologyEditor::sorted_key(const std::uint32_t* particles, std::uint32_t arity) {
  ElementKey k{kNone, kNone, kNone, kNone};
  std::copy_n(particles, arity, k.begin());
  // Insertion sort of at most 4 (std::sort of a run whose length the
  // compiler cannot bound trips -Warray-bounds).
  for (std::uint32_t i = 1; i < arity; ++i)
    for (std::uint32_t j = i; j > 0 && k[j - 1] > k[j]; --j) std::swap(k[j - 1], k[j]);
  return k;
}

TopologyEditor::ElementKey TopologyEditor::element_key(const Body& b, std::uint32_t e) const {
  std::uint32_t p[4];
  for (std::uint32_t i = 0; i < b.arity; ++i) p[i] = b.device[b.of(e)[i]];
  return sorted_key(p, b.arity);
}

TopologyEditor::Body TopologyEditor::make_body(std::uint32_t arity, const std::vector<Vec3d>& rest,
                                               std::span<const std::uint32_t> corners, std::uint32_t first,
                                               const CompiledScene& compiled) {
  Body b;
  b.arity = arity;
  b.rest = rest;
  b.corners.assign(corners.begin(), corners.end());
  b.first = first;
  const std::size_t nv = rest.size(), ne = corners.size() / arity;
  for (std::uint32_t v = 0; v < nv; ++v) b.device.push_back(compiled.order.device_of[first + v]);
  b.alive.assign(ne, 1);
  b.heat.assign(ne, 0.0);
  b.live.assign(nv, 0);
  b.offsets.assign(nv + 1, 0);
  // Rest measures exactly as the compile computes them (float positions,
  // float volume or area: add_tet_body, add_tri_body).
  auto at = [&](std::uint32_t v) {
    return kernels::float4{static_cast<float>(rest[v][0]), static_cast<float>(rest[v][1]),
                           static_cast<float>(rest[v][2]), 0.0f};
  };
  for (std::size_t e = 0; e < ne; ++e) {
    const std::uint32_t* q = b.of(e);
    b.rest_measure.push_back(arity == 4 ? kernels::tet_volume(at(q[0]), at(q[1]), at(q[2]), at(q[3]))
                                        : kernels::thin::triangle_area(at(q[0]), at(q[1]), at(q[2])));
    for (std::uint32_t i = 0; i < arity; ++i) ++b.live[q[i]], ++b.offsets[q[i] + 1];
  }
  for (std::size_t v = 0; v < nv; ++v) b.offsets[v + 1] += b.offsets[v];
  b.list.resize(b.offsets[nv]);
  std::vector<std::uint32_t> fill(b.offsets.begin(), b.offsets.end() - 1);
  for (std::uint32_t e = 0; e < ne; ++e)  // ascending: each vertex's elements in mesh order
    for (std::uint32_t i = 0; i < arity; ++i) b.list[fill[b.of(e)[i]]++] = e;
  return b;
}

Result<std::unique_ptr<TopologyEditor>> TopologyEditor::create(const SceneDesc& scene, const CompiledScene& compiled) {
  auto e = std::unique_ptr<TopologyEditor>(new TopologyEditor());
  e->warm_start_ = scene.solver.warm_start;
  for (std::uint32_t k = 0; k < compiled.blocks.size(); ++k) {
    const ConstraintBlock& c = compiled.blocks[k];
    Block b;
    b.kernel = c.kernel;
    b.arity = c.arity;
    b.data_stride = c.data_stride;
    b.lambda_stride = c.lambda_stride;
    b.particles = c.particles;
    b.data = c.data;
    b.offsets = c.color_offsets;
    for (std::size_t col = 0; col < c.colors(); ++col) b.counts.push_back(c.color_count(col));
    if (is_editable(c.kernel))
      for (std::uint32_t i = 0; i < c.size(); ++i) e->index(k, b, i);
    e->blocks_.push_back(std::move(b));
  }
  e->mass_.resize(compiled.positions.size());
  for (std::size_t i = 0; i < compiled.positions.size(); ++i)
    e->mass_[i] = compiled.positions[i].w > 0.0f ? 1.0 / double(compiled.positions[i].w) : 0.0;
  for (std::size_t bi = 0; bi < scene.line_bodies.size(); ++bi) {
    Line l;
    l.desc = scene.line_bodies[bi];
    l.first = compiled.line_body_first_particle[bi];
    for (std::uint32_t v = 0; v < l.desc.vertices.size(); ++v) l.device.push_back(compiled.order.device_of[l.first + v]);
    l.whole.assign(l.desc.segments.size(), 1);
    e->lines_.push_back(std::move(l));
  }
  for (std::size_t bi = 0; bi < scene.tet_bodies.size(); ++bi) {
    const TetBodyDesc& desc = scene.tet_bodies[bi];
    const auto corners = std::span<const std::uint32_t>(desc.mesh.tets.data()->data(), desc.mesh.tets.size() * 4);
    Body b = make_body(4, desc.mesh.vertices, corners, compiled.tet_body_first_particle[bi], compiled);
    b.mass_density = desc.density;
    b.edge_depth = 1.0;
    b.distance_compliance = desc.distance_compliance;
    if (desc.calibrated_network && desc.distance_constraints)
      for (const TetNetworkFit& fit : fit_body_network(desc.mesh, desc.youngs_modulus, desc.poisson_ratio).tets)
        b.edge_stiffness.push_back(fit.edge);
    b.tear_strain = desc.tear_strain;
    if (b.tear_strain > 0.0) b.edges = unique_edges({b.rest, b.corners, b.arity, b.alive, b.offsets, b.list});
    e->tets_.push_back(std::move(b));
    e->tet_meshes_.push_back(desc.mesh);
  }
  for (std::size_t bi = 0; bi < scene.tri_bodies.size(); ++bi) {
    const TriBodyDesc& desc = scene.tri_bodies[bi];
    const auto corners =
        std::span<const std::uint32_t>(desc.mesh.triangles.data()->data(), desc.mesh.triangles.size() * 3);
    Body b = make_body(3, desc.mesh.vertices, corners, compiled.tri_body_first_particle[bi], compiled);
    b.mass_density = desc.density * desc.thickness;
    b.edge_depth = desc.thickness;
    b.distance_compliance = desc.distance_compliance;
    b.tear_strain = desc.tear_strain;
    if (b.tear_strain > 0.0) b.edges = unique_edges({b.rest, b.corners, b.arity, b.alive, b.offsets, b.list});
    e->sheets_.push_back(std::move(b));
    e->tri_meshes_.push_back(desc.mesh);
  }
  return e;
}

void TopologyEditor::track_boundaries() {
  for (std::size_t i = 0; i < tets_.size(); ++i) {
    Body& b = tets_[i];
    b.boundary = extract_boundary_surface(tet_meshes_[i]).triangles;
    b.boundary_index.clear();
    for (std::uint32_t k = 0; k < b.boundary.size(); ++k) b.boundary_index[sorted_key(b.boundary[k].data(), 3)] = k;
  }
  tracking_ = true;
}

void TopologyEditor::update_boundary(Body& b, std::span<const std::uint32_t> removed) {
  for (std::uint32_t t : removed)
    for (const auto& local : kOutwardFaces) {
      const std::uint32_t* q = b.of(t);
      const std::array<std::uint32_t, 3> face{q[local[0]], q[local[1]], q[local[2]]};
      const ElementKey key = sorted_key(face.data(), 3);
      // The live tets with this face: around its lowest vertex.
      std::uint32_t live = 0, owner = 0;
      for (std::uint32_t k = b.offsets[key[0]]; k < b.offsets[key[0] + 1]; ++k) {
        const std::uint32_t s = b.list[k];
        const std::uint32_t* r = b.of(s);
        if (b.alive[s] && std::find(r, r + 4, key[1]) != r + 4 && std::find(r, r + 4, key[2]) != r + 4)
          ++live, owner = s;
      }
      const auto at = b.boundary_index.find(key);
      if (live != 1) {
        if (at == b.boundary_index.end()) continue;
        const std::uint32_t k = at->second;  // leaves: the last face takes its index
        b.boundary_index.erase(at);
        if (k + 1 != b.boundary.size()) {
          b.boundary[k] = b.boundary.back();
          b.boundary_index[sorted_key(b.boundary[k].data(), 3)] = k;
        }
        b.boundary.pop_back();
        continue;
      }
      for (const auto& other : kOutwardFaces) {  // the owner's face with these vertices, wound outward from it
        const std::uint32_t* r = b.of(owner);
        const std::array<std::uint32_t, 3> mine{r[other[0]], r[other[1]], r[other[2]]};
        if (sorted_key(mine.data(), 3) != key) continue;
        if (at != b.boundary_index.end()) {
          b.boundary[at->second] = mine;
        } else {
          b.boundary_index[key] = static_cast<std::uint32_t>(b.boundary.size());
          b.boundary.push_back(mine);
        }
      }
    }
}

ElementView TopologyEditor::view(BodyKind kind, std::size_t body) const {
  const Body& b = of(kind, body);
  return {b.rest, b.corners, b.arity, b.alive, b.offsets, b.list};
}

bool TopologyEditor::tears() const {
  const auto tear = [](const Body& b) { return b.tear_strain > 0.0; };
  return std::any_of(tets_.begin(), tets_.end(), tear) || std::any_of(sheets_.begin(), sheets_.end(), tear) ||
         std::any_of(lines_.begin(), lines_.end(), [](const Line& l) { return l.desc.tear_strain > 0.0; });
}

void TopologyEditor::index(std::uint32_t k, const Block& b, std::uint32_t slot) {
  const std::uint32_t* p = &b.particles[std::size_t{slot} * b.arity];
  switch (b.kernel) {
    case Kernel::xpbd_solve_distance: edge_slots_[edge_key(p[0], p[1])] = {k, slot}; break;
    case Kernel::xpbd_solve_line_bending: bend_slots_[p[1]] = {k, slot}; break;
    case Kernel::xpbd_solve_dihedral: hinge_slots_[edge_key(p[0], p[1])] = {k, slot}; break;  // the hinge's edge
    default: element_slots_[sorted_key(p, b.arity)].push_back({k, slot}); break;  // volume, FEM, area
  }
}

void TopologyEditor::swap_remove(std::uint32_t k, std::uint32_t slot) {
  Block& b = blocks_[k];
  const auto color = static_cast<std::uint32_t>(std::upper_bound(b.offsets.begin(), b.offsets.end(), slot) -
                                                b.offsets.begin() - 1);
  const std::uint32_t last = b.offsets[color] + b.counts[color] - 1;
  if (slot != last) {
    std::copy_n(&b.particles[std::size_t{last} * b.arity], b.arity, &b.particles[std::size_t{slot} * b.arity]);
    std::copy_n(&b.data[std::size_t{last} * b.data_stride], b.data_stride, &b.data[std::size_t{slot} * b.data_stride]);
    // The moved constraint's index entry follows it.
    const std::uint32_t* p = &b.particles[std::size_t{slot} * b.arity];
    switch (b.kernel) {
      case Kernel::xpbd_solve_distance: edge_slots_[edge_key(p[0], p[1])] = {k, slot}; break;
      case Kernel::xpbd_solve_line_bending: bend_slots_[p[1]] = {k, slot}; break;
      case Kernel::xpbd_solve_dihedral: hinge_slots_[edge_key(p[0], p[1])] = {k, slot}; break;
      default:
        for (Slot& s : element_slots_[sorted_key(p, b.arity)])
          if (s.block == k && s.slot == last) s.slot = slot;
        break;
    }
    b.dirty.push_back(slot);
  }
  b.freed.push_back(last);
  --b.counts[color];
}

double TopologyEditor::edge_share(const Body& b, std::uint32_t a, std::uint32_t v) const {
  const double parts = b.arity == 4 ? 6.0 : 3.0;  // a tet's six edges, a triangle's three
  double share = 0.0;
  for (std::uint32_t i = b.offsets[a]; i < b.offsets[a + 1]; ++i) {
    const std::uint32_t e = b.list[i];
    const std::uint32_t* q = b.of(e);
    if (!b.alive[e] || std::find(q, q + b.arity, v) == q + b.arity) continue;
    if (b.edge_stiffness.empty()) {
      share += static_cast<double>(b.rest_measure[e]) / parts;  // as the compile sums it, in element order
      continue;
    }
    for (int k = 0; k < 6; ++k) {  // calibrated: this tet's spring on the edge
      const std::uint32_t s = q[kTetEdgePairs[k][0]], t = q[kTetEdgePairs[k][1]];
      if ((s == a && t == v) || (s == v && t == a)) share += b.edge_stiffness[e][std::size_t(k)];
    }
  }
  return share;
}

double TopologyEditor::hand_off(const Body& b, std::uint32_t v, std::span<const std::uint32_t> removed,
                                std::vector<std::uint32_t>& changed, double& moved) {
  double& m = mass_[b.device[v]];
  // Its neighbours through the removed elements that still hold elements and move.
  std::vector<std::uint32_t> to;
  for (std::uint32_t e : removed) {
    const std::uint32_t* q = b.of(e);
    if (std::find(q, q + b.arity, v) == q + b.arity) continue;
    for (std::uint32_t i = 0; i < b.arity; ++i)
      if (b.live[q[i]] > 0 && mass_[b.device[q[i]]] > 0.0) to.push_back(q[i]);
  }
  std::sort(to.begin(), to.end());
  to.erase(std::unique(to.begin(), to.end()), to.end());
  if (to.empty()) {  // none: the nearest live movable vertex of the body, at rest
    double best = std::numeric_limits<double>::infinity();
    std::uint32_t nearest = 0;
    for (std::uint32_t u = 0; u < b.rest.size(); ++u) {
      if (b.live[u] == 0 || mass_[b.device[u]] <= 0.0) continue;
      double d2 = 0.0;
      for (int a = 0; a < 3; ++a) d2 += (b.rest[u][a] - b.rest[v][a]) * (b.rest[u][a] - b.rest[v][a]);
      if (d2 < best) best = d2, nearest = u;
    }
    if (std::isfinite(best)) to.push_back(nearest);
  }
  const double mass = m;
  m = 0.0;
  if (to.empty()) return mass;  // nothing of the body is left to carry it
  for (std::uint32_t u : to) {
    mass_[b.device[u]] += mass / double(to.size());
    changed.push_back(b.device[u]);
  }
  moved += mass;
  return 0.0;
}

Result<TopologyEvent> TopologyEditor::remove(Device& device, const XpbdBuffers& buffers,
                                                         CompiledScene& shape, BodyKind kind, std::size_t body,
                                                         std::span<const std::uint32_t> elements, bool burn) {
  const bool tri = kind == BodyKind::tri;
  const char* what = tri ? "tri_bodies[" : "tet_bodies[";
  const char* element = tri ? "] triangle " : "] tet ";
  if (kind == BodyKind::line || body >= bodies(kind))
    return Error(ErrorCode::bad_parameter, std::string(tri ? "tri body " : "tet body ") + std::to_string(body) +
                                               " does not exist (the scene has " + std::to_string(bodies(kind)) + ")");
  Body& b = of(kind, body);
  std::vector<std::uint8_t> seen(b.alive.size(), 0);
  for (std::uint32_t t : elements) {
    const std::string name = what + std::to_string(body) + element + std::to_string(t);
    if (t >= b.alive.size())
      return Error(ErrorCode::bad_parameter, name + " does not exist (the mesh has " + std::to_string(b.alive.size()) +
                                                 (tri ? " triangles)" : " tets)"));
    if (!b.alive[t]) return Error(ErrorCode::bad_parameter, name + " was removed already");
    if (seen[t]) return Error(ErrorCode::bad_parameter, name + " is listed twice");
    seen[t] = 1;
  }
  TopologyEvent event;
  event.body_kind = kind;
  event.body = body;
  (tri ? event.triangles_removed : event.tets_removed).assign(elements.begin(), elements.end());

  // The elements' own constraints: one of each block (volume, FEM; area) per element.
  std::vector<std::uint32_t> touched;  // vertices of the removed elements
  for (std::uint32_t t : elements) {
    b.alive[t] = 0;
    b.heat[t] = 0.0;
    for (std::uint32_t i = 0; i < b.arity; ++i) --b.live[b.of(t)[i]], touched.push_back(b.of(t)[i]);
    const auto it = element_slots_.find(element_key(b, t));
    if (it == element_slots_.end()) continue;  // a body without volume, FEM or area constraints
    std::vector<Slot>& slots = it->second;
    std::vector<std::uint32_t> done;
    for (std::size_t i = 0; i < slots.size();) {
      if (std::find(done.begin(), done.end(), slots[i].block) != done.end()) {
        ++i;
        continue;
      }
      const Slot s = slots[i];
      done.push_back(s.block);
      slots.erase(slots.begin() + std::ptrdiff_t(i));
      swap_remove(s.block, s.slot);
      ++event.constraints_removed;
    }
    if (slots.empty()) element_slots_.erase(it);
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  if (tracking_ && !tri) update_boundary(b, elements);

  // Their edges: a hinge goes with either of its triangles; a distance
  // constraint goes with its last element, or is softer by the share it lost.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (std::uint32_t t : elements)
    for (const auto& e : element_edges(b.arity)) {
      const std::uint32_t u = b.of(t)[e[0]], v = b.of(t)[e[1]];
      edges.emplace_back(std::min(u, v), std::max(u, v));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [u, v] : edges) {
    const std::uint64_t key = edge_key(b.device[u], b.device[v]);
    if (const auto it = hinge_slots_.find(key); tri && it != hinge_slots_.end()) {
      const Slot s = it->second;
      hinge_slots_.erase(it);
      swap_remove(s.block, s.slot);
      ++event.constraints_removed;
    }
    const auto it = edge_slots_.find(key);
    if (it == edge_slots_.end()) continue;  // a body without distance constraints
    const Slot s = it->second;
    const double share = edge_share(b, u, v);
    if (share <= 0.0) {
      edge_slots_.erase(it);
      swap_remove(s.block, s.slot);
      ++event.constraints_removed;
      continue;
    }
    Block& k = blocks_[s.block];
    float* data = &k.data[std::size_t{s.slot} * k.data_stride];
    const float len = data[0];
    const auto alpha =
        b.edge_stiffness.empty()
            ? static_cast<float>(b.distance_compliance * static_cast<double>(len) * len / (share * b.edge_depth))
            : static_cast<float>(1.0 / share);
    if (alpha != data[1]) {
      data[1] = alpha;
      k.dirty.push_back(s.slot);
      ++event.edges_softened;
    }
  }

  // Masses.
  std::vector<std::uint32_t> mass_changed;
  if (burn) {
    for (std::uint32_t t : elements) {
      const double share = b.mass_density * static_cast<double>(b.rest_measure[t]) / b.arity;  // as the compile lumps it
      for (std::uint32_t i = 0; i < b.arity; ++i) {
        const std::uint32_t d = b.device[b.of(t)[i]];
        double& m = mass_[d];
        if (m <= 0.0) continue;  // pinned: its share was never on it
        const double taken = std::min(m, share);
        m -= taken;
        event.mass_removed += taken;
        mass_changed.push_back(d);
      }
    }
  }
  for (std::uint32_t v : touched) {
    double& m = mass_[b.device[v]];
    if (b.live[v] > 0 || m <= 0.0) continue;
    event.vertices_removed.push_back(v);
    mass_changed.push_back(b.device[v]);
    if (burn) {  // what rounding left
      event.mass_removed += m;
      m = 0.0;
      continue;
    }
    event.mass_removed += hand_off(b, v, elements, mass_changed, event.mass_moved);
  }
  std::sort(mass_changed.begin(), mass_changed.end());
  mass_changed.erase(std::unique(mass_changed.begin(), mass_changed.end()), mass_changed.end());
  if (Status s = commit(device, buffers, shape, mass_changed); !s) return s.error();
  return event;
}

Status TopologyEditor::commit(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                              std::span<const std::uint32_t> mass_changed) {
  if (Status s = upload(device, buffers, mass_changed); !s) return s;
  // The counts of the blocks a removal can change (graspers' blocks keep theirs).
  for (std::size_t k = 0; k < blocks_.size(); ++k)
    if (is_editable(blocks_[k].kernel)) shape.blocks[k].color_counts = blocks_[k].counts;
  return {};
}

Result<TopologyEvent> TopologyEditor::remove_segments(Device& device, const XpbdBuffers& buffers,
                                                                  CompiledScene& shape, std::size_t body,
                                                                  std::span<const std::uint32_t> segments) {
  if (body >= lines_.size())
    return Error(ErrorCode::bad_parameter, "line body " + std::to_string(body) + " does not exist (the scene has " +
                                               std::to_string(lines_.size()) + ")");
  Line& l = lines_[body];
  std::vector<std::uint8_t> seen(l.whole.size(), 0);
  for (std::uint32_t s : segments) {
    const std::string name = "line_bodies[" + std::to_string(body) + "] segment " + std::to_string(s);
    if (s >= l.whole.size())
      return Error(ErrorCode::bad_parameter,
                   name + " does not exist (the body has " + std::to_string(l.whole.size()) + " segments)");
    if (!l.whole[s]) return Error(ErrorCode::bad_parameter, name + " was broken already");
    if (seen[s]) return Error(ErrorCode::bad_parameter, name + " is listed twice");
    seen[s] = 1;
  }
  TopologyEvent event;
  event.body_kind = BodyKind::line;
  event.body = body;
  event.segments_removed.assign(segments.begin(), segments.end());
  for (std::uint32_t s : segments) {
    l.whole[s] = 0;
    const std::uint32_t p = l.device[l.desc.segments[s][0]], q = l.device[l.desc.segments[s][1]];
    if (const auto it = edge_slots_.find(edge_key(p, q)); it != edge_slots_.end()) {
      const Slot slot = it->second;
      edge_slots_.erase(it);
      swap_remove(slot.block, slot.slot);
      ++event.constraints_removed;
    }
    // The bending constraints across it: those centred on either end that
    // reach the other.
    for (const auto& [middle, other] : {std::pair{p, q}, std::pair{q, p}}) {
      const auto it = bend_slots_.find(middle);
      if (it == bend_slots_.end()) continue;
      const Slot slot = it->second;
      const std::uint32_t* ends = &blocks_[slot.block].particles[std::size_t{slot.slot} * 3];
      if (ends[0] != other && ends[2] != other) continue;
      bend_slots_.erase(it);
      swap_remove(slot.block, slot.slot);
      ++event.constraints_removed;
    }
  }
  if (Status s = commit(device, buffers, shape, {}); !s) return s.error();
  return event;
}

namespace {

// Sorted, unique slots as runs [first, last], two runs merged when fewer
// than kGap slots lie between them: each run is one write per buffer, and
// some backends pay far more per write than per byte. PoCL takes about
// 0.1 ms a write, as long as copying ~1 MB: a 44-tet cut wrote 18.7 ms
// as runs of consecutive slots, 5.8 ms merged across gaps of 256 slots
// (bench_topology); 4,096 slots are at most ~100 KB of one block.
constexpr std::uint32_t kGap = 4096;
std::vector<std::array<std::uint32_t, 2>> merged_runs(std::vector<std::uint32_t>& slots, std::uint32_t gap) {
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
  std::vector<std::array<std::uint32_t, 2>> runs;
  for (std::uint32_t s : slots) {
    if (!runs.empty() && s - runs.back()[1] <= gap) {
      runs.back()[1] = s;
    } else {
      runs.push_back({s, s});
    }
  }
  return runs;
}

}  // namespace

Status TopologyEditor::upload(Device& device, const XpbdBuffers& buffers, std::span<const std::uint32_t> mass_changed) {
  for (std::size_t k = 0; k < blocks_.size(); ++k) {
    Block& b = blocks_[k];
    const BlockBuffers& d = buffers.blocks[k];
    // Particles and data: the host copy is the device's for every slot, so
    // a run may carry unchanged slots between changed ones.
    for (const auto& [first, last] : merged_runs(b.dirty, kGap)) {
      if (Status s = write_slots(device, d.particles, b.particles, b.arity, first, last - first + 1); !s) return s;
      if (Status s = write_slots(device, d.data, b.data, b.data_stride, first, last - first + 1); !s) return s;
    }
    // A moved constraint's lambda record would be its slot's last owner's.
    // It matters where something outlives the first sweep's reset: a warm
    // start's multipliers, and the corotational tets' rotation, kept in the
    // record from solve to solve (fem_params.h, SINEW_FEM_ROTATION; all
    // zero: start from the exact rotation). There it starts again from 0,
    // slot by slot (a merged run would reset the records between).
    if (warm_start_ || b.kernel == Kernel::xpbd_solve_corotational)
      for (const auto& [first, last] : merged_runs(b.dirty, 1)) {
        const std::vector<float> zeros(std::size_t{last - first + 1} * b.lambda_stride, 0.0f);
        if (Status s = device.write_buffer(d.lambda, std::size_t{first} * b.lambda_stride * 4, zeros.data(),
                                           zeros.size() * 4);
            !s)
          return s;
      }
    // Freed slots: their residual (the statistics and the residual checks
    // reduce the whole block) becomes 0. The slots in use between them are
    // zeroed too, harmlessly: every frame's measuring pass writes theirs
    // before anything reads them.
    for (const auto& [first, last] : merged_runs(b.freed, kGap)) {
      const std::vector<float> zeros(last - first + 1, 0.0f);
      if (Status s = device.write_buffer(d.residual, std::size_t{first} * 4, zeros.data(), zeros.size() * 4); !s)
        return s;
    }
    b.dirty.clear();
    b.freed.clear();
  }
  // Inverse masses: read each changed particle (the device moved it) and
  // write it back with its new w.
  for (std::uint32_t p : mass_changed) {
    kernels::float4 x{};
    if (Status s = device.read_buffer(buffers.position, std::size_t{p} * 16, &x, 16); !s) return s;
    x.w = mass_[p] > 0.0 ? static_cast<float>(1.0 / mass_[p]) : 0.0f;
    if (Status s = device.write_buffer(buffers.position, std::size_t{p} * 16, &x, 16); !s) return s;
  }
  return {};
}

}  // namespace sinew
