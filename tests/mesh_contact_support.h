// mesh_contact_support.h — measuring contact between simulated bodies in
// the tests (tests/mesh_contact_test.cpp): how deep any body's surface
// vertex sits inside another tet body, from the positions alone.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "math/proximity_math.h"
#include "sinew/mesh.h"
#include "sinew/scene.h"
#include "sinew/simulation.h"

namespace sinew::test {

using P3 = std::array<double, 3>;

inline P3 sub(const P3& a, const P3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const P3& a, const P3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline P3 cross(const P3& a, const P3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

/// Distance from p to triangle (a, b, c), in double: the closest point of
/// the narrow phase's own query (kernels/math/proximity_math.h).
inline double point_triangle_distance(const P3& p, const P3& a, const P3& b, const P3& c) {
  using kernels::double4;
  const auto d4 = [](const P3& q) { return double4{q[0], q[1], q[2], 0.0}; };
  const double4 q = kernels::proximity::at(kernels::proximity::closest_on_triangle(d4(p), d4(a), d4(b), d4(c)),
                                           d4(a), d4(b), d4(c));
  return std::sqrt((p[0] - q.x) * (p[0] - q.x) + (p[1] - q.y) * (p[1] - q.y) + (p[2] - q.z) * (p[2] - q.z));
}

/// A tet body as the test sees it after a run: its mesh and the positions
/// of its vertices (from Simulation::read_positions, from `first` on).
struct PlacedBody {
  const TetMesh* mesh;
  std::uint32_t first;
};

inline P3 at(const std::vector<float>& xyzw, std::uint32_t p) {
  return {xyzw[4 * std::size_t{p}], xyzw[4 * std::size_t{p} + 1], xyzw[4 * std::size_t{p} + 2]};
}

/// Whether p is inside tet (a, b, c, d), by the signs of the four sub-volumes.
inline bool inside_tet(const P3& p, const P3& a, const P3& b, const P3& c, const P3& d) {
  const double v = dot(sub(b, a), cross(sub(c, a), sub(d, a)));
  const double s[4] = {dot(sub(b, p), cross(sub(c, p), sub(d, p))), dot(sub(p, a), cross(sub(c, a), sub(d, a))),
                       dot(sub(b, a), cross(sub(p, a), sub(d, a))), dot(sub(b, a), cross(sub(c, a), sub(p, a)))};
  for (double x : s)
    if ((v > 0 && x < 0) || (v < 0 && x > 0)) return false;
  return true;
}

/// The deepest any boundary vertex of `a` lies inside `b`'s tets [m]: its
/// distance to b's boundary surface (0 when none is inside).
inline double penetration(const std::vector<float>& x, const PlacedBody& a, const PlacedBody& b) {
  const TriMesh sa = extract_boundary_surface(*a.mesh), sb = extract_boundary_surface(*b.mesh);
  std::vector<char> on_surface(a.mesh->vertices.size(), 0);
  for (const auto& t : sa.triangles)
    for (auto v : t) on_surface[v] = 1;
  double deepest = 0.0;
  for (std::uint32_t v = 0; v < on_surface.size(); ++v) {
    if (!on_surface[v]) continue;
    const P3 p = at(x, a.first + v);
    bool in = false;
    for (const auto& t : b.mesh->tets) {
      if (inside_tet(p, at(x, b.first + t[0]), at(x, b.first + t[1]), at(x, b.first + t[2]), at(x, b.first + t[3]))) {
        in = true;
        break;
      }
    }
    if (!in) continue;
    double depth = std::numeric_limits<double>::infinity();
    for (const auto& f : sb.triangles)
      depth = std::min(depth, point_triangle_distance(p, at(x, b.first + f[0]), at(x, b.first + f[1]),
                                                      at(x, b.first + f[2])));
    deepest = std::max(deepest, depth);
  }
  return deepest;
}

}  // namespace sinew::test

namespace sinew::test {

/// A flat rectangular membrane in the y = `height` plane: nx * nz cells of
/// `cell` [m] from the origin along +x and +z, two triangles per cell.
inline TriMesh membrane(int nx, int nz, double cell, double height) {
  TriMesh m;
  for (int i = 0; i <= nx; ++i)
    for (int k = 0; k <= nz; ++k) m.vertices.push_back({i * cell, height, k * cell});
  const auto id = [&](int i, int k) { return static_cast<std::uint32_t>(i * (nz + 1) + k); };
  for (int i = 0; i < nx; ++i)
    for (int k = 0; k < nz; ++k) {
      m.triangles.push_back({id(i, k), id(i + 1, k), id(i + 1, k + 1)});
      m.triangles.push_back({id(i, k), id(i + 1, k + 1), id(i, k + 1)});
    }
  return m;
}

/// membrane(cells, cells, cell, 0) as a tri body pinned along its border,
/// its distance and area compliance `compliance` [1/Pa], velocity damping 5 / s.
inline TriBodyDesc pinned_membrane(int cells, double cell, double compliance) {
  TriBodyDesc sheet;
  sheet.mesh = membrane(cells, cells, cell, 0.0);
  sheet.distance_compliance = compliance;
  sheet.area_compliance = compliance;
  sheet.velocity_damping = 5.0;
  for (int i = 0; i <= cells; ++i)
    for (int k = 0; k <= cells; ++k)
      if (i == 0 || k == 0 || i == cells || k == cells)
        sheet.pinned.push_back(static_cast<std::uint32_t>(i * (cells + 1) + k));
  return sheet;
}

/// Whether segment (p, q) crosses triangle (a, b, c) (touching counts), in double.
inline bool segment_crosses_triangle(const P3& p, const P3& q, const P3& a, const P3& b, const P3& c) {
  const P3 n = cross(sub(b, a), sub(c, a));
  const double dp = dot(n, sub(p, a)), dq = dot(n, sub(q, a));
  if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0) || dp == dq) return false;
  const double t = dp / (dp - dq);
  const P3 x{p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), p[2] + t * (q[2] - p[2])};
  const double s0 = dot(n, cross(sub(b, a), sub(x, a))), s1 = dot(n, cross(sub(c, b), sub(x, b))),
               s2 = dot(n, cross(sub(a, c), sub(x, c)));
  return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

/// Pairs of triangles of one surface that share no vertex yet intersect
/// (an edge of one crosses the other): where it has passed through itself.
/// Brute force over all pairs, for small test meshes.
inline int self_intersections(const std::vector<float>& x, const TriMesh& mesh, std::uint32_t first) {
  int found = 0;
  const auto& t = mesh.triangles;
  for (std::size_t i = 0; i < t.size(); ++i)
    for (std::size_t j = i + 1; j < t.size(); ++j) {
      bool shared = false;
      for (auto a : t[i])
        for (auto b : t[j]) shared |= a == b;
      if (shared) continue;
      const P3 pi[3] = {at(x, first + t[i][0]), at(x, first + t[i][1]), at(x, first + t[i][2])};
      const P3 pj[3] = {at(x, first + t[j][0]), at(x, first + t[j][1]), at(x, first + t[j][2])};
      bool hit = false;
      for (int e = 0; e < 3 && !hit; ++e)
        hit = segment_crosses_triangle(pi[e], pi[(e + 1) % 3], pj[0], pj[1], pj[2]) ||
              segment_crosses_triangle(pj[e], pj[(e + 1) % 3], pi[0], pi[1], pi[2]);
      found += hit;
    }
  return found;
}

}  // namespace sinew::test

namespace sinew::test {

/// A tet block of cells^3 cubes of `cell` [m] with its corner at `origin`,
/// E = 2 MPa, nu = 0.3, lightly damped.
inline TetBodyDesc soft_block(int cells, double cell, const std::array<double, 3>& origin) {
  TetBodyDesc body;
  body.mesh = *make_tet_grid({.nx = cells, .ny = cells, .nz = cells, .origin = {0, 0, 0},
                              .cell_size = {cell, cell, cell}});
  for (auto& v : body.mesh.vertices)
    for (int k = 0; k < 3; ++k) v[k] += origin[k];
  (void)body.set_elastic(2e6, 0.3);
  body.density = 1000.0;
  body.velocity_damping = 2.0;
  return body;
}

/// Two tissue blocks dropped onto each other (tests/mesh_contact_test.cpp,
/// benchmarks/mesh_contact_benchmark.cpp): a 3 cm block 1 cm above a 4 cm
/// block resting on the floor, offset so that its edges and corners meet
/// the lower block's faces and its vertices fall between the lower one's.
/// 60 Hz frames of 10 substeps of 2 sweeps; 1 mm thickness.
inline SceneDesc dropped_blocks_scene(ContactSchedule schedule) {
  SceneDesc scene;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 10;
  scene.solver.iterations = 2;
  scene.tet_bodies.push_back(soft_block(4, 0.01, {0.0, 0.0, 0.0}));
  scene.tet_bodies.push_back(soft_block(4, 0.0075, {0.005, 0.05, 0.0065}));
  scene.colliders.push_back(ColliderDesc{});  // the floor, y = 0
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 1e-3;
  scene.mesh_collision.schedule = schedule;
  return scene;
}

/// A membrane strip (12 x 3 cm, 5 mm cells, no bending) lying on the floor
/// with one end lifted by its edge's vertices (attached to targets) over
/// the rest and laid down on it: the fold's upper layer settles onto the
/// lower one. Its far edge's targets follow a half circle about x = 5.75
/// cm over fold_frames frames, ending just past the strip's other end
/// (x = -0.5 cm), 3 mm up, so the upper layer is pulled taut over the lower.
struct FoldedStrip {
  static constexpr int nx = 24, nz = 6, fold_frames = 90;
  static constexpr double cell = 0.005;
  static SceneDesc scene(ContactSchedule schedule) {
    SceneDesc scene;
    scene.solver.time_step = 1.0 / 60.0;
    scene.solver.substeps = 10;
    scene.solver.iterations = 2;
    TriBodyDesc strip;
    strip.mesh = membrane(nx, nz, cell, 0.002);
    strip.thickness = 1e-3;
    strip.distance_compliance = 1e-6;
    strip.area_compliance = 1e-6;
    // No bending constraints: like cloth, the fold lies flat under its weight.
    strip.velocity_damping = 3.0;
    scene.tri_bodies.push_back(strip);
    scene.colliders.push_back(ColliderDesc{});  // the floor
    for (int k = 0; k <= nz; ++k) {
      scene.targets.push_back({nx * cell, 0.002, k * cell});
      AttachmentDesc a;
      a.vertex = {BodyKind::tri, 0, static_cast<std::uint32_t>(nx * (nz + 1) + k)};
      a.target = static_cast<std::uint32_t>(k);
      a.compliance = 1e-6;
      scene.attachments.push_back(a);
    }
    scene.mesh_collision.enabled = true;
    scene.mesh_collision.thickness = 1.5e-3;
    scene.mesh_collision.schedule = schedule;
    return scene;
  }
  /// Where target k is at the end of frame f [m].
  static std::array<double, 3> target(int f, int k) {
    const double centre = 0.0575, radius = nx * cell - centre;
    const double done = std::min(1.0, double(f + 1) / fold_frames);
    const double angle = 3.14159265358979 * done;
    return {centre + radius * std::cos(angle), 0.002 + 0.001 * done + radius * std::sin(angle), k * cell};
  }
};

}  // namespace sinew::test

namespace sinew::test {

/// How many (segment, triangle) pairs cross (`segment_crosses_triangle`),
/// both given as particle indices into `x`. Candidates come from a uniform
/// grid of `cell` [m] over the triangles' boxes: every pair whose boxes
/// share a cell is tested exactly, so nothing is missed, only skipped
/// where the boxes are apart.
inline int crossings(const std::vector<float>& x, const std::vector<std::array<std::uint32_t, 2>>& segments,
                     const std::vector<std::array<std::uint32_t, 3>>& triangles, double cell) {
  auto key = [cell](const P3& p, int k) { return static_cast<std::int64_t>(std::floor(p[k] / cell)); };
  auto pack = [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return ((i & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (k & 0x1FFFFF);
  };
  auto box = [&](std::initializer_list<std::uint32_t> ids, std::array<std::int64_t, 3>& lo, std::array<std::int64_t, 3>& hi) {
    for (int k = 0; k < 3; ++k) lo[k] = INT64_MAX, hi[k] = INT64_MIN;
    for (auto id : ids) {
      const P3 p = at(x, id);
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], key(p, k)), hi[k] = std::max(hi[k], key(p, k));
    }
  };
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> grid;
  std::array<std::int64_t, 3> lo, hi;
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    box({triangles[t][0], triangles[t][1], triangles[t][2]}, lo, hi);
    for (auto i = lo[0]; i <= hi[0]; ++i)
      for (auto j = lo[1]; j <= hi[1]; ++j)
        for (auto k = lo[2]; k <= hi[2]; ++k) grid[pack(i, j, k)].push_back(t);
  }
  int found = 0;
  std::vector<std::uint32_t> seen(triangles.size(), UINT32_MAX);
  for (std::uint32_t s = 0; s < segments.size(); ++s) {
    box({segments[s][0], segments[s][1]}, lo, hi);
    for (auto i = lo[0]; i <= hi[0]; ++i)
      for (auto j = lo[1]; j <= hi[1]; ++j)
        for (auto k = lo[2]; k <= hi[2]; ++k) {
          const auto cell_triangles = grid.find(pack(i, j, k));
          if (cell_triangles == grid.end()) continue;
          for (std::uint32_t t : cell_triangles->second) {
            if (seen[t] == s) continue;
            seen[t] = s;
            const auto& tri = triangles[t];
            found += segment_crosses_triangle(at(x, segments[s][0]), at(x, segments[s][1]), at(x, tri[0]), at(x, tri[1]),
                                              at(x, tri[2]));
          }
        }
  }
  return found;
}

/// The edges of a triangle mesh, each once, offset by `first` (a body's
/// first particle).
inline std::vector<std::array<std::uint32_t, 2>> edges_of(const TriMesh& mesh, std::uint32_t first) {
  std::vector<std::array<std::uint32_t, 2>> edges;
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[e], b = t[(e + 1) % 3];
      if (a < b) edges.push_back({first + a, first + b});
      else if (a != b) edges.push_back({first + b, first + a});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

/// The kidney pressed onto the liver by a probe (issue 12's organ scene,
/// cheap enough for a test): the kidney_57k tet body (millimetres scaled to
/// metres, mesher's order, 50 kPa) 3 mm above the liver_382k's boundary
/// triangles under the kidney's footprint (+ 1 cm each side, down to 3 cm
/// below the highest), pinned: the liver as a fixed surface. No gravity
/// (the organs lie supported in the abdomen). A kinematic capsule probe
/// (radius 8 mm along x) starts 5 mm above the kidney's highest point and
/// moves down `depth` beyond touching over `press_frames`, then holds.
/// 60 Hz frames of 10 substeps of 5 sweeps, 1 mm thickness, no
/// self-collision.
struct KidneyOnLiver {
  TetMesh kidney;
  TriMesh liver;                      ///< the fixed patch of the liver's surface
  std::array<double, 3> probe_start;  ///< [m]
  static constexpr int press_frames = 20;
  static constexpr double depth = 0.012;  ///< [m] the probe's travel past touching the kidney

  /// [in] data: the data folder (SINEW_DATA_DIR).
  static Result<KidneyOnLiver> load(const std::string& data) {
    auto liver = read_tet_mesh(data + "/meshes/tet/liver_382k.node");
    if (!liver) return liver.error();
    auto kidney = read_tet_mesh(data + "/meshes/tet/kidney_57k.node");
    if (!kidney) return kidney.error();
    scale_mesh(*liver, 1e-3);
    scale_mesh(*kidney, 1e-3);
    P3 klo{1e9, 1e9, 1e9}, khi{-1e9, -1e9, -1e9}, lo = klo, hi = khi;
    for (const auto& v : liver->vertices)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
    for (const auto& v : kidney->vertices)
      for (int k = 0; k < 3; ++k) klo[k] = std::min(klo[k], v[k]), khi[k] = std::max(khi[k], v[k]);
    const double cx = 0.5 * (lo[0] + hi[0]), cz = 0.5 * (lo[2] + hi[2]);
    const double hx = 0.5 * (khi[0] - klo[0]), hz = 0.5 * (khi[2] - klo[2]);
    double top = lo[1];
    for (const auto& v : liver->vertices)
      if (std::abs(v[0] - cx) <= hx && std::abs(v[2] - cz) <= hz) top = std::max(top, v[1]);
    const P3 shift{cx - 0.5 * (klo[0] + khi[0]), top + 0.003 - klo[1], cz - 0.5 * (klo[2] + khi[2])};
    for (auto& v : kidney->vertices)
      for (int k = 0; k < 3; ++k) v[k] += shift[k];

    KidneyOnLiver s;
    const TriMesh surface = extract_boundary_surface(*liver);
    std::vector<std::int64_t> index(surface.vertices.size(), -1);
    for (const auto& t : surface.triangles) {
      bool under = true;
      for (auto v : t) {
        const auto& p = surface.vertices[v];
        under &= std::abs(p[0] - cx) <= hx + 0.01 && std::abs(p[2] - cz) <= hz + 0.01 && p[1] >= top - 0.03;
      }
      if (!under) continue;
      std::array<std::uint32_t, 3> kept;
      for (int k = 0; k < 3; ++k) {
        if (index[t[k]] < 0) {
          index[t[k]] = static_cast<std::int64_t>(s.liver.vertices.size());
          s.liver.vertices.push_back(surface.vertices[t[k]]);
        }
        kept[k] = static_cast<std::uint32_t>(index[t[k]]);
      }
      s.liver.triangles.push_back(kept);
    }
    P3 highest = kidney->vertices.front();
    for (const auto& v : kidney->vertices)
      if (v[1] > highest[1]) highest = v;
    s.probe_start = {highest[0], highest[1] + 0.008 + 0.005, highest[2]};
    s.kidney = std::move(*kidney);
    return s;
  }

  SceneDesc scene() const {
    SceneDesc scene;
    scene.solver.time_step = 1.0 / 60.0;
    scene.solver.substeps = 10;
    scene.solver.iterations = 5;
    scene.gravity = {0.0, 0.0, 0.0};
    TetBodyDesc organ;
    organ.mesh = kidney;
    (void)organ.set_elastic(5e4, 0.4);
    organ.density = 1060.0;
    organ.velocity_damping = 5.0;
    scene.tet_bodies.push_back(std::move(organ));
    TriBodyDesc surface;
    surface.mesh = liver;
    for (std::uint32_t v = 0; v < liver.vertices.size(); ++v) surface.pinned.push_back(v);
    scene.tri_bodies.push_back(std::move(surface));
    ColliderDesc probe;
    probe.shape = ColliderShape::capsule;
    probe.radius = 0.008;
    probe.half_height = 0.02;
    probe.rotation = {std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};  // its axis along x
    probe.position = probe_start;
    scene.colliders.push_back(probe);
    scene.mesh_collision.enabled = true;
    scene.mesh_collision.thickness = 1e-3;
    scene.mesh_collision.self_collision = false;  // organ against organ
    return scene;
  }

  /// The probe's centre at the end of frame f [m].
  std::array<double, 3> probe_at(int f) const {
    const double done = std::min(1.0, double(f + 1) / press_frames);
    return {probe_start[0], probe_start[1] - (0.005 + depth) * done, probe_start[2]};
  }
};

}  // namespace sinew::test

namespace sinew::test {

/// A thin probe (a capsule collider 4 mm thick, 12 mm long, along z)
/// pressed 15 mm down over 30 frames into the middle of one 2 cm cell of a
/// coarse membrane (4 x 4 cells, pinned at its border, no gravity), then
/// held for 15: no vertex of the membrane touches it, only its triangles.
struct ThinProbe {
  static constexpr int frames = 45;
  static SceneDesc scene() {
    SceneDesc scene;
    scene.solver.time_step = 1.0 / 60.0;
    scene.solver.substeps = 10;
    scene.solver.iterations = 2;
    scene.gravity = {0.0, 0.0, 0.0};
    scene.tri_bodies.push_back(pinned_membrane(4, 0.02, 1e-5));
    ColliderDesc probe;
    probe.shape = ColliderShape::capsule;
    probe.radius = 0.002;
    probe.half_height = 0.006;
    probe.rotation = {std::sqrt(0.5), std::sqrt(0.5), 0.0, 0.0};  // its axis along z
    probe.position = probe_at(-1);
    scene.colliders.push_back(probe);
    scene.mesh_collision.enabled = true;
    scene.mesh_collision.thickness = 1e-3;
    return scene;
  }
  /// The probe's centre at the end of frame f [m] (f = -1: the start).
  static std::array<double, 3> probe_at(int f) {
    return {0.03, 0.007 - 0.015 * std::min(1.0, (f + 1) / 30.0), 0.03};  // over the middle of cell (1, 1)
  }
  /// The same membrane with the probe as a rigid tool of `mass` [kg] (no
  /// collider, no gravity) starting 0.1 mm above it over the middle of
  /// cell (1, 1) (no vertex under it), to be held by couple().
  static SceneDesc tool_scene(double mass) {
    SceneDesc scene = ThinProbe::scene();
    const ColliderDesc probe = scene.colliders[0];
    scene.colliders.clear();
    ToolDesc tool;
    tool.radius = probe.radius;
    tool.half_height = probe.half_height;
    tool.mass = mass;
    tool.gravity = false;
    const double length = 2.0 * probe.half_height;  // a solid rod's moments, about its centre
    tool.inertia = {mass * length * length / 12.0, 0.5 * mass * probe.radius * probe.radius,
                    mass * length * length / 12.0};
    tool.rotation = probe.rotation;  // its axis along z
    tool.position = {0.03, 0.0001 + probe.radius + scene.mesh_collision.thickness, 0.03};
    scene.tools.push_back(tool);
    return scene;
  }
  /// A virtual coupling, as a haptic device drives a tool (rigid_tool.h): a
  /// critically damped spring of kCoupling [N/m] from the tool of `mass`
  /// [kg] to kTarget, 10 mm under the membrane, applied for the coming
  /// frame from the tool's state. [out] pull: the spring's force [N].
  static constexpr double kCoupling = 20.0;
  static constexpr std::array<double, 3> kTarget{0.03, -0.01, 0.03};
  static Status couple(Simulation& sim, double mass, std::array<double, 3>& pull) {
    Tools tools = sim.tools();
    const auto tool = tools.tool(0);
    if (!tool) return tool.error();
    auto state = tools.state(*tool);
    if (!state) return state.error();
    const double damping = 2.0 * std::sqrt(kCoupling * mass);
    for (int k = 0; k < 3; ++k) pull[k] = kCoupling * (kTarget[k] - state->position[k]) - damping * state->velocity[k];
    return tools.apply_force(*tool, pull, {0.0, 0.0, 0.0});
  }
};

}  // namespace sinew::test
