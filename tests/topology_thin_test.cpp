// Topology changes on thin tissue (issue 16): triangles removed from a tri
// body while the scene runs — by hand, by a blade (across the sheet and in
// its own plane), by tearing and by cautery — on every backend. What every
// change must keep, as for tets (topology_test.cpp): each colour valid, the
// constraints in use exactly the live triangles' (area, edges, hinges), no
// constraint naming a removed vertex, the total mass (cuts and tears).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "topology_support.h"

namespace sinew::test {
namespace {

constexpr double kCell = 5e-3;  // [m]

// A flat sheet of nx x nz cells of `cell` [m] in the plane y = 0, two
// triangles a cell; vertex (i, k) at (i cell, 0, k cell) is i (nz + 1) + k.
TriMesh flat_sheet(int nx, int nz, double cell) {
  TriMesh mesh;
  for (int i = 0; i <= nx; ++i)
    for (int k = 0; k <= nz; ++k) mesh.vertices.push_back({i * cell, 0.0, k * cell});
  const auto at = [&](int i, int k) { return static_cast<std::uint32_t>(i * (nz + 1) + k); };
  for (int i = 0; i < nx; ++i)
    for (int k = 0; k < nz; ++k) {
      mesh.triangles.push_back({at(i, k), at(i, k + 1), at(i + 1, k + 1)});
      mesh.triangles.push_back({at(i, k), at(i + 1, k + 1), at(i + 1, k)});
    }
  return mesh;
}

// A membrane of 1 mm, 1 MPa, with bending, pinned where `pin` says.
template <class Pin>
SceneDesc sheet_scene(int nx, int nz, double cell, Pin pin) {
  SceneDesc scene;
  TriBodyDesc body;
  body.mesh = flat_sheet(nx, nz, cell);
  body.thickness = 1e-3;
  body.density = 1000.0;
  body.distance_compliance = 1e-6;
  body.area_compliance = 1e-6;
  body.bending_compliance = 1.0;
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (pin(body.mesh.vertices[v])) body.pinned.push_back(v);
  scene.tri_bodies.push_back(body);
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 20;
  scene.solver.iterations = 1;
  scene.topology_changes = true;
  return scene;
}

auto left_edge = [](const Vec3d& p) { return p[0] < 1e-9; };

// The particle of tri body 0's vertex 0.
std::uint32_t sheet_first(const Simulation& sim) { return sim.info().tri_body_first_particle[0]; }

// The mean y of tri body 0's vertices with rest x beyond `from` [m].
double mean_y_beyond(const Simulation& sim, const TriMesh& mesh, double from) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  const std::uint32_t first = sheet_first(sim);
  double sum = 0.0;
  int n = 0;
  for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v)
    if (mesh.vertices[v][0] > from) sum += x[4 * (first + v) + 1], ++n;
  return sum / n;
}

// The device's constraints in use are exactly what tri body 0's live
// triangles call for: one area constraint per live triangle, one distance
// constraint per edge of a live triangle, and one dihedral constraint per
// hinge (an edge of exactly two triangles in the rest mesh) whose two
// triangles both live.
void expect_constraints_match(const Simulation& sim, const TriMesh& rest) {
  auto check = SimulationInternals::check_colors(sim);
  ASSERT_TRUE(check.ok());
  auto live = sim.current_triangles(0);
  ASSERT_TRUE(live.ok());
  const std::uint32_t first = sheet_first(sim);
  using Entry = std::pair<Kernel, std::vector<std::uint32_t>>;
  std::vector<Entry> expected, actual;
  std::vector<std::vector<std::uint32_t>> edges;
  for (const auto& t : *live) {
    std::vector<std::uint32_t> q{first + t[0], first + t[1], first + t[2]};
    std::sort(q.begin(), q.end());
    expected.emplace_back(Kernel::xpbd_solve_area, q);
    edges.push_back({q[0], q[1]}), edges.push_back({q[1], q[2]}), edges.push_back({q[0], q[2]});
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (auto& e : edges) expected.emplace_back(Kernel::xpbd_solve_distance, e);
  // Hinges: the rest mesh's edges and the triangles at each.
  std::vector<std::pair<std::array<std::uint32_t, 2>, std::uint32_t>> at_edge;  // (edge, triangle)
  for (std::uint32_t t = 0; t < rest.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = rest.triangles[t][k], b = rest.triangles[t][(k + 1) % 3];
      at_edge.push_back({{std::min(a, b), std::max(a, b)}, t});
    }
  std::sort(at_edge.begin(), at_edge.end());
  std::vector<std::uint8_t> alive(rest.triangles.size(), 0);
  for (const auto& t : *live)
    for (std::uint32_t r = 0; r < rest.triangles.size(); ++r)
      if (rest.triangles[r] == t) alive[r] = 1;
  for (std::size_t i = 0; i + 1 < at_edge.size(); ++i) {
    const bool hinge = at_edge[i].first == at_edge[i + 1].first &&
                       (i + 2 == at_edge.size() || at_edge[i + 2].first != at_edge[i].first) &&
                       (i == 0 || at_edge[i - 1].first != at_edge[i].first);
    if (!hinge || !alive[at_edge[i].second] || !alive[at_edge[i + 1].second]) continue;
    std::vector<std::uint32_t> q;
    for (std::uint32_t t : {at_edge[i].second, at_edge[i + 1].second})
      for (std::uint32_t v : rest.triangles[t]) q.push_back(first + v);
    std::sort(q.begin(), q.end());
    q.erase(std::unique(q.begin(), q.end()), q.end());
    expected.emplace_back(Kernel::xpbd_solve_dihedral, q);
  }
  for (const Entry& e : check->in_use)
    if (e.first == Kernel::xpbd_solve_area || e.first == Kernel::xpbd_solve_distance ||
        e.first == Kernel::xpbd_solve_dihedral)
      actual.push_back(e);
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(actual.size(), expected.size());
  EXPECT_TRUE(actual == expected) << "the device's constraints differ from the live triangles'";
}

class ThinTopology : public BackendTest {};

TEST_P(ThinTopology, ASheetCutInTwoFallsApart) {
  // 16 x 4 cells (8 x 2 cm) pinned along its left edge, one frame after
  // its release; a blade across its whole width at x = 4 cm: the right
  // half falls free, the left half hangs on, mass and colours kept.
  const SceneDesc scene = sheet_scene(16, 4, kCell, left_edge);
  const TriMesh& mesh = scene.tri_bodies[0].mesh;
  auto sim = create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const double mass = SimulationInternals::check_colors(*sim)->total_mass;
  expect_constraints_match(*sim, mesh);
  run(*sim, 1);
  const double cut_x = 0.0401;  // off the grid's lines
  auto cut = sim->cut_body(BodyKind::tri, 0, {{cut_x, 0.05, -0.1}, {cut_x, -0.15, -0.1}},
                           {{cut_x, 0.05, 0.1}, {cut_x, -0.15, 0.1}});
  ASSERT_TRUE(cut.ok()) << cut.error().message();
  EXPECT_EQ(cut->body_kind, BodyKind::tri);
  EXPECT_EQ(cut->triangles_removed.size(), 8u);  // the column of cells the blade crosses, 2 triangles each
  EXPECT_TRUE(cut->tets_removed.empty());
  std::printf("cut: %zu triangles, %zu vertices, %u constraints removed, %u edges softened, %.3g kg moved, %.2f ms\n",
              cut->triangles_removed.size(), cut->vertices_removed.size(), cut->constraints_removed,
              cut->edges_softened, cut->mass_moved, cut->wall_ms);
  EXPECT_GT(cut->edges_softened, 0u);  // the cut's border edges lost one of their two triangles
  expect_consistent(*sim, sheet_first(*sim), cut->vertices_removed, mass);
  expect_constraints_match(*sim, mesh);

  run(*sim, 20);  // a third of a second: free fall g t^2 / 2 = 0.545 m
  EXPECT_LT(mean_y_beyond(*sim, mesh, 0.045), -0.45) << "the right half did not fall free";
  std::vector<float> x;
  ASSERT_TRUE(sim->read_positions(x).ok());
  for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v)
    if (mesh.vertices[v][0] < 0.035) {
      EXPECT_GT(x[4 * v + 1], -0.05) << "vertex " << v;  // within its 3.5 cm of the pins
    }
  expect_consistent(*sim, sheet_first(*sim), cut->vertices_removed, mass);
}

TEST_P(ThinTopology, AnUncutSheetKeepsHanging) {
  // The control of the test above.
  const SceneDesc scene = sheet_scene(16, 4, kCell, left_edge);
  auto sim = create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  run(*sim, 21);
  EXPECT_GT(mean_y_beyond(*sim, scene.tri_bodies[0].mesh, 0.045), -0.1);
}

TEST_P(ThinTopology, EveryColourStaysValidThroughManyRemovals) {
  // 30 removals of 5 random triangles each from a hanging sheet with
  // bending, the colouring and the constraints checked after every one.
  const SceneDesc scene = sheet_scene(6, 6, kCell, left_edge);
  auto sim = create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const double mass = SimulationInternals::check_colors(*sim)->total_mass;
  std::vector<std::uint32_t> live(scene.tri_bodies[0].mesh.triangles.size()), gone;
  std::iota(live.begin(), live.end(), 0u);
  std::uint32_t seed = 16;
  for (int round = 0; round < 30 && live.size() > 5; ++round) {
    const std::vector<std::uint32_t> take = take_random(live, 5, seed);
    auto event = sim->remove_triangles(0, take);
    ASSERT_TRUE(event.ok()) << event.error().message();
    gone.insert(gone.end(), event->vertices_removed.begin(), event->vertices_removed.end());
    expect_consistent(*sim, sheet_first(*sim), gone, mass);
    expect_constraints_match(*sim, scene.tri_bodies[0].mesh);
    run(*sim, 2);
  }
  auto triangles = sim->current_triangles(0);
  ASSERT_TRUE(triangles.ok());
  EXPECT_EQ(triangles->size(), live.size());
}

TEST_P(ThinTopology, AStripPulledPastItsThresholdTearsAndBelowItDoesNot) {
  // A strip of 10 x 1 cells pinned at both ends, held 30% (or 10%) beyond
  // its rest length: tear_strain 0.2 tears the first and never the second.
  for (const double stretch : {0.3, 0.1}) {
    SceneDesc scene = sheet_scene(10, 1, kCell, [](const Vec3d& p) { return p[0] < 1e-9 || p[0] > 10 * kCell - 1e-9; });
    TriBodyDesc& body = scene.tri_bodies[0];
    body.tear_strain = 0.2;
    body.distance_compliance = 1e-5;
    for (const Vec3d& v : body.mesh.vertices) body.initial_vertices.push_back({v[0] * (1.0 + stretch), v[1], v[2]});
    auto sim = create_or_skip(scene, GetParam());
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    const double mass = SimulationInternals::check_colors(*sim)->total_mass;
    std::size_t torn = 0;
    std::vector<std::uint32_t> gone;
    for (int f = 0; f < 30; ++f) {
      ASSERT_TRUE(sim->step().ok());
      for (const auto& e : sim->last_tears()) {
        EXPECT_EQ(e.body_kind, BodyKind::tri);
        torn += e.triangles_removed.size();
        gone.insert(gone.end(), e.vertices_removed.begin(), e.vertices_removed.end());
      }
    }
    if (stretch > 0.2) {
      EXPECT_GT(torn, 0u) << "stretched 30%";
    } else {
      EXPECT_EQ(torn, 0u) << "stretched 10%";
    }
    expect_consistent(*sim, sheet_first(*sim), gone, mass);
    expect_constraints_match(*sim, scene.tri_bodies[0].mesh);
  }
}

TEST_P(ThinTopology, CauteryBurnsTheDiscsAreaAfterItsDwellTime) {
  // A 5 cm square sheet of 2.5 mm cells, its border pinned, no gravity (it
  // stays where it is); a tip of 10 mm radius on its centre for 0.5 s with
  // a dwell time of 0.3 s: nothing before 0.3 s, then the disc's area
  // (pi r^2 = 3.14 cm^2) with its mass.
  const double cell = 2.5e-3, side = 20 * cell, radius = 0.01;
  SceneDesc scene = sheet_scene(20, 20, cell, [&](const Vec3d& p) {
    return p[0] < 1e-9 || p[2] < 1e-9 || p[0] > side - 1e-9 || p[2] > side - 1e-9;
  });
  scene.gravity = {0.0, 0.0, 0.0};
  const TriBodyDesc& body = scene.tri_bodies[0];
  auto sim = create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const double mass = SimulationInternals::check_colors(*sim)->total_mass;
  const double frame = scene.solver.time_step;
  int first_burn = -1;
  double area = 0.0, removed = 0.0;
  std::vector<std::uint32_t> gone;
  for (int f = 0; f < 30; ++f) {
    auto burn = sim->cauterize(BodyKind::tri, 0, {side / 2, 0.0, side / 2}, radius, frame, 0.3);
    ASSERT_TRUE(burn.ok()) << burn.error().message();
    if (!burn->triangles_removed.empty() && first_burn < 0) first_burn = f;
    for (std::uint32_t t : burn->triangles_removed) {
      const auto& q = body.mesh.triangles[t];
      const Vec3d& a = body.mesh.vertices[q[0]];
      const Vec3d& b = body.mesh.vertices[q[1]];
      const Vec3d& c = body.mesh.vertices[q[2]];
      area += 0.5 * std::abs((b[0] - a[0]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[0] - a[0]));
    }
    removed += burn->mass_removed;
    gone.insert(gone.end(), burn->vertices_removed.begin(), burn->vertices_removed.end());
    run(*sim, 1);
  }
  const double disc = M_PI * radius * radius;
  std::printf("first burn after %d frames; burned %.4g m^2 against the disc's %.4g; %.4g kg removed\n", first_burn,
              area, disc, removed);
  EXPECT_GE(first_burn, 17);  // 0.3 s is 18 frames
  EXPECT_LE(first_burn, 18);
  EXPECT_NEAR(area, disc, 0.1 * disc);
  EXPECT_NEAR(removed, body.density * body.thickness * area, 1e-6 * removed);
  expect_consistent(*sim, sheet_first(*sim), gone, mass - removed);
  expect_constraints_match(*sim, body.mesh);
}

TEST_P(ThinTopology, ACutInTheSheetsOwnPlaneTakesWhatTheBladeCoversAndNoMore) {
  // A flat sheet at rest (border pinned, no gravity) cut by a blade lying
  // in its plane: the segment P-Q along the diagonal swept 0.7 mm across
  // it, a thin rectangle. Removed: every triangle that reaches into the
  // rectangle, and none that does not. (Two triangles in one plane have no
  // separating axis among their normals and edges' cross products, which
  // all point out of the plane: without the in-plane axes every triangle in
  // the rectangle's bounding box would go.)
  const double side = 12 * kCell;
  SceneDesc scene = sheet_scene(12, 12, kCell, [&](const Vec3d& p) {
    return p[0] < 1e-9 || p[2] < 1e-9 || p[0] > side - 1e-9 || p[2] > side - 1e-9;
  });
  scene.gravity = {0.0, 0.0, 0.0};
  const TriMesh& mesh = scene.tri_bodies[0].mesh;
  auto sim = create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const std::array<double, 3> p{0.0101, 0.0, 0.0103}, q{0.0501, 0.0, 0.0503};
  const double width = 7e-4, s2 = std::sqrt(0.5);
  const std::array<double, 3> d{width * s2, 0.0, -width * s2};  // across the diagonal, in the plane
  auto cut = sim->cut_body(BodyKind::tri, 0, {p, q}, {{p[0] + d[0], 0.0, p[2] + d[2]}, {q[0] + d[0], 0.0, q[2] + d[2]}});
  ASSERT_TRUE(cut.ok()) << cut.error().message();
  std::vector<std::uint8_t> removed(mesh.triangles.size(), 0);
  for (std::uint32_t t : cut->triangles_removed) removed[t] = 1;
  // The rectangle in its own coordinates: s across [0, width], u along [0, |PQ|].
  const double length = std::hypot(q[0] - p[0], q[2] - p[2]);
  std::size_t must = 0;
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    double s_lo = 1e9, s_hi = -1e9, u_lo = 1e9, u_hi = -1e9;
    for (std::uint32_t v : mesh.triangles[t]) {
      const double x = mesh.vertices[v][0] - p[0], z = mesh.vertices[v][2] - p[2];
      const double s = (x - z) * s2, u = (x + z) * s2;
      s_lo = std::min(s_lo, s), s_hi = std::max(s_hi, s), u_lo = std::min(u_lo, u), u_hi = std::max(u_hi, u);
    }
    const double eps = 1e-7;  // float positions
    const bool may = s_lo <= width + eps && s_hi >= -eps && u_lo <= length + eps && u_hi >= -eps;
    const bool needs = s_lo < width - eps && s_hi > eps && u_lo > eps && u_hi < length - eps;
    if (removed[t]) {
      EXPECT_TRUE(may) << "triangle " << t << " is beyond the blade's reach";
    }
    if (needs) {
      ++must;
      EXPECT_TRUE(removed[t]) << "triangle " << t << " lies across the blade";
    }
  }
  std::printf("%zu triangles removed, %zu of them required\n", cut->triangles_removed.size(), must);
  EXPECT_GT(must, 10u);
  expect_constraints_match(*sim, mesh);
}

TEST_P(ThinTopology, MeshCollisionSeesTheHoleCut) {
  // An 8 mm cube rests on a sheet pinned at its border (mesh collision
  // between them); a 2 cm hole cut under it lets it fall through. With
  // stale surfaces it would stay on triangles that are gone.
  const double side = 8 * kCell;
  SceneDesc scene = sheet_scene(8, 8, kCell, [&](const Vec3d& p) {
    return p[0] < 1e-9 || p[2] < 1e-9 || p[0] > side - 1e-9 || p[2] > side - 1e-9;
  });
  add_resting_cube(scene, {0.016, 0.001, 0.016});
  auto sim = create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  auto lowest = [&] { return lowest_y(*sim, scene, 0); };
  run(*sim, 20);
  const double resting = lowest();
  EXPECT_GT(resting, -0.005) << "the cube fell through the whole sheet";
  const TriMesh& mesh = scene.tri_bodies[0].mesh;
  std::vector<std::uint32_t> hole;
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    Vec3d c{};
    for (std::uint32_t v : mesh.triangles[t])
      for (int a = 0; a < 3; ++a) c[a] += mesh.vertices[v][a] / 3.0;
    if (c[0] > 0.01 && c[0] < 0.03 && c[2] > 0.01 && c[2] < 0.03) hole.push_back(t);
  }
  auto removed = sim->remove_triangles(0, hole);
  ASSERT_TRUE(removed.ok()) << removed.error().message();
  run(*sim, 20);
  std::printf("the cube's lowest point: %.2f mm resting, %.2f mm after the hole\n", 1e3 * resting, 1e3 * lowest());
  EXPECT_LT(lowest(), -0.05) << "the cube did not fall through the hole";
}

// The point of triangle `t` of tri body 0 at the current positions, at
// barycentric weights w.
std::array<double, 3> point_on(const Simulation& sim, const TriMesh& mesh, std::uint32_t t,
                               const std::array<double, 3>& w) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  std::array<double, 3> p{};
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) p[a] += w[k] * x[4 * (sheet_first(sim) + mesh.triangles[t][k]) + a];
  return p;
}

TEST_P(ThinTopology, JawsClosingBetweenVerticesHoldTheSurfacePointTheyTouch) {
  // A coarse membrane (1 cm cells) hangs from its left edge. Jaws of 2 mm
  // close on the centroid of a triangle at its free end, where no vertex
  // is within 7 mm: the grasper holds that point through its barycentric
  // weights (a vertex-only grasper would hold nothing), lifts it 3 cm over
  // half a second (the point follows the jaws), and lets go (it falls).
  for (const std::uint32_t point_capacity : {16u, 0u}) {
    SceneDesc scene = sheet_scene(4, 4, 0.01, left_edge);
    // Grasper 1 does the work (its slots and targets after grasper 0's).
    scene.graspers.push_back({.capacity = 4, .point_capacity = 4, .compliance = 1.0});
    scene.graspers.push_back({.capacity = 8, .point_capacity = point_capacity, .compliance = 0.0});
    const TriMesh& mesh = scene.tri_bodies[0].mesh;
    auto sim = create_or_skip(scene, GetParam());
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    run(*sim, 30);
    const std::uint32_t t = 6 * 2 + 2;  // cell (3, 1)'s first triangle, at the free end
    const std::array<double, 3> third{1.0 / 3, 1.0 / 3, 1.0 / 3};
    const std::array<double, 3> start = point_on(*sim, mesh, t, third);
    Pose jaws{start, {1, 0, 0, 0}};
    auto held = sim->close_grasper(1, jaws, {0.001, 0.001, 0.001});
    ASSERT_TRUE(held.ok()) << held.error().message();
    EXPECT_TRUE(held->empty()) << "no vertex lies between the jaws";
    EXPECT_TRUE(sim->held_points(0)->empty());
    auto points = sim->held_points(1);
    ASSERT_TRUE(points.ok());
    if (point_capacity == 0) {
      EXPECT_TRUE(points->empty());
    } else {
      ASSERT_EQ(points->size(), 1u);
      const std::uint32_t first = sheet_first(*sim);
      std::array<std::uint32_t, 3> expected{first + mesh.triangles[t][0], first + mesh.triangles[t][1],
                                            first + mesh.triangles[t][2]};
      EXPECT_EQ((*points)[0].particles, expected);
      for (double w : (*points)[0].weights) EXPECT_NEAR(w, 1.0 / 3, 1e-5);  // the centroid is the nearest point
      auto check = SimulationInternals::check_colors(*sim);
      ASSERT_TRUE(check.ok());
      EXPECT_EQ(check->conflicts, 0u);
    }
    for (int f = 1; f <= 30; ++f) {
      jaws.position[1] = start[1] + 0.03 * f / 30.0;
      ASSERT_TRUE(sim->move_grasper(1, jaws).ok());
      ASSERT_TRUE(sim->step().ok());
    }
    run(*sim, 10);
    const std::array<double, 3> lifted = point_on(*sim, mesh, t, third);
    std::printf("point_capacity %u: the point rose %.2f mm (the jaws 30 mm)\n", point_capacity,
                1e3 * (lifted[1] - start[1]));
    if (point_capacity == 0) {
      EXPECT_LT(lifted[1], start[1] + 0.01) << "nothing was held, yet the point rose";
      continue;
    }
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(lifted[a], jaws.position[a], 1e-3) << "axis " << a;
    auto released = sim->open_grasper(1);
    ASSERT_TRUE(released.ok());
    EXPECT_TRUE(sim->held_points(1)->empty());
    run(*sim, 20);
    EXPECT_LT(point_on(*sim, mesh, t, third)[1], lifted[1] - 0.01) << "released, the point did not fall";
  }
}

TEST_P(ThinTopology, APointGraspTakesOneTriangleAVertexAndNamesItsCapacity) {
  // Two flat sheets 2 mm apart, at rest (no gravity). Jaws of 4 mm across
  // the middle of a cell's diagonal cross both of its triangles in both
  // sheets: one point per sheet (the two triangles of a cell share the
  // diagonal's vertices), two in all; a point_capacity of 1 is too small,
  // and the error says so with nothing held.
  for (const std::uint32_t point_capacity : {2u, 1u}) {
    SceneDesc scene = sheet_scene(4, 4, 0.01, [](const Vec3d&) { return false; });
    scene.gravity = {0.0, 0.0, 0.0};
    TriBodyDesc upper = scene.tri_bodies[0];
    for (Vec3d& v : upper.mesh.vertices) v[1] += 0.002;
    scene.tri_bodies.push_back(upper);
    scene.graspers.push_back({.capacity = 8, .point_capacity = point_capacity, .compliance = 0.0});
    auto sim = create_or_skip(scene, GetParam());
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    const Pose jaws{{0.015, 0.001, 0.015}, {1, 0, 0, 0}};  // the centre of cell (1, 1), on its diagonal
    auto held = sim->close_grasper(0, jaws, {0.002, 0.002, 0.002});
    if (point_capacity == 1) {
      ASSERT_FALSE(held.ok());
      EXPECT_EQ(held.error().code(), ErrorCode::capacity_exceeded);
      EXPECT_NE(held.error().message().find("point_capacity"), std::string::npos) << held.error().message();
      EXPECT_TRUE(sim->held_points(0)->empty());
      continue;
    }
    ASSERT_TRUE(held.ok()) << held.error().message();
    auto points = sim->held_points(0);
    ASSERT_EQ(points->size(), 2u);
    EXPECT_NE((*points)[0].particles[0] < sim->info().tri_body_first_particle[1],
              (*points)[1].particles[0] < sim->info().tri_body_first_particle[1])
        << "one point in each sheet";
    for (const auto& p : *points) {
      EXPECT_NEAR(p.weights[0] + p.weights[1] + p.weights[2], 1.0, 1e-12);
      std::printf("held at weights (%.3f, %.3f, %.3f)\n", p.weights[0], p.weights[1], p.weights[2]);
    }
    run(*sim, 10);
    auto check = SimulationInternals::check_colors(*sim);
    ASSERT_TRUE(check.ok());
    EXPECT_EQ(check->conflicts, 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, ThinTopology, ::testing::ValuesIn(backends()), backend_name);

TEST(ThinTopology, ScriptedCutsAgreeAcrossBackends) {
  // The same scripted cuts and frames on every backend with a device:
  // positions within 1e-5 m of the CPU's.
  auto script = [](const std::string& backend, std::vector<float>& x) -> bool {
    const SceneDesc scene = sheet_scene(12, 3, kCell, left_edge);
    auto sim = create_or_skip(scene, backend);
    if (!sim.ok()) return false;
    for (int step = 0; step < 3; ++step) {
      for (int f = 0; f < 5; ++f) EXPECT_TRUE(sim->step().ok());
      const double cx = 0.011 + 0.0152 * step;
      EXPECT_TRUE(sim->cut_body(BodyKind::tri, 0, {{cx, 0.05, -0.1}, {cx, -0.15, -0.1}},
                                {{cx, 0.05, 0.1}, {cx, -0.15, 0.1}})
                      .ok());
    }
    for (int f = 0; f < 10; ++f) EXPECT_TRUE(sim->step().ok());
    return sim->read_positions(x).ok();
  };
  expect_backends_agree(script);
}

TEST(ThinTopology, BadInputIsNamed) {
  SceneDesc scene = sheet_scene(2, 1, kCell, left_edge);
  scene.topology_changes = false;
  auto plain = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(plain.ok());
  const std::uint32_t one[] = {0};
  EXPECT_NE(plain->remove_triangles(0, one).error().message().find("topology_changes"), std::string::npos);
  EXPECT_NE(plain->current_triangles(0).error().message().find("topology_changes"), std::string::npos);

  scene.tri_bodies[0].tear_strain = 0.5;
  EXPECT_NE(Simulation::create(scene, {.backend = "cpu", .quiet = true}).error().message().find("tri_bodies[0].tear_strain"),
            std::string::npos);
  scene.topology_changes = true;
  scene.tri_bodies[0].tear_strain = -1.0;
  EXPECT_NE(Simulation::create(scene, {.backend = "cpu", .quiet = true}).error().message().find("tear_strain"),
            std::string::npos);
  scene.tri_bodies[0].tear_strain = 0.0;

  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok());
  const std::uint32_t twice[] = {1, 1}, beyond[] = {4};
  EXPECT_NE(sim->remove_triangles(1, one).error().message().find("tri body 1"), std::string::npos);
  EXPECT_NE(sim->remove_triangles(0, twice).error().message().find("twice"), std::string::npos);
  EXPECT_NE(sim->remove_triangles(0, beyond).error().message().find("triangle 4"), std::string::npos);
  EXPECT_NE(sim->remove_tets(0, one).error().message().find("tet body 0"), std::string::npos);
  ASSERT_TRUE(sim->remove_triangles(0, one).ok());
  EXPECT_NE(sim->remove_triangles(0, one).error().message().find("removed already"), std::string::npos);
  EXPECT_NE(sim->cut_body(BodyKind::line, 0, {}, {}).error().message().find("line body"), std::string::npos);
  EXPECT_NE(sim->cut_body(BodyKind::tri, 2, {}, {}).error().message().find("tri body 2"), std::string::npos);
  EXPECT_NE(sim->cauterize(BodyKind::tri, 0, {0, 0, 0}, -1.0, 0.1, 0.1).error().message().find("radius"),
            std::string::npos);
  EXPECT_NE(sim->current_triangles(3).error().message().find("tri body 3"), std::string::npos);
  EXPECT_EQ(sim->current_triangles(0)->size(), 3u);
}

}  // namespace
}  // namespace sinew::test
