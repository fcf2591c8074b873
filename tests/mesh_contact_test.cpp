// mesh_contact_test.cpp — contacts between meshes in the solver (issue 12,
// part 3), on every backend: tissue against tissue and a membrane against
// itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "contact_hold_support.h"
#include "mesh_contact_support.h"
#include "test_support.h"

namespace sinew::test {
namespace {

class MeshContact : public BackendTest {};

// The dropped blocks after a run: how deep either lies in the other [m] and
// the upper block's lowest vertex [m].
std::pair<double, double> blocks_at_rest(const Simulation& sim, const SceneDesc& scene) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  const PlacedBody lower{&scene.tet_bodies[0].mesh, sim.info().tet_body_first_particle[0]};
  const PlacedBody upper{&scene.tet_bodies[1].mesh, sim.info().tet_body_first_particle[1]};
  const double depth = std::max(penetration(x, upper, lower), penetration(x, lower, upper));
  double lowest_upper = 1e9;
  for (std::uint32_t v = 0; v < scene.tet_bodies[1].mesh.vertices.size(); ++v)
    lowest_upper = std::min(lowest_upper, at(x, upper.first + v)[1]);
  return {depth, lowest_upper};
}

// A 3 cm block dropped from 1 cm onto a 4 cm block resting on the floor,
// offset so that its edges and corners meet the lower block's faces and its
// vertices fall between the lower one's (finer and coarser meshes).
// Without mesh collision the measured depth after 60 frames is 10 mm.
TEST_P(MeshContact, DroppedBlocksRestOnEachOtherWithinTheThickness) {
  const SceneDesc scene = dropped_blocks_scene(ContactSchedule::colored);
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  for (int f = 0; f < 120; ++f) SINEW_ASSERT_OK(sim->step());
  const auto [depth, lowest_upper] = blocks_at_rest(*sim, scene);
  const FrameStats& s = sim->last_frame();
  std::printf("[%s] depth %.3g mm, upper block's lowest %.4f m, KE %.3g J, %u contacts in %u colours, margin %.3g mm, %.2f ms\n",
              GetParam().c_str(), depth * 1e3, lowest_upper, s.kinetic_energy, s.mesh_contacts, s.mesh_contact_colors,
              s.collision_margin * 1e3, s.collision_ms);
  EXPECT_LT(depth, scene.mesh_collision.thickness);
  EXPECT_GT(lowest_upper, 0.0395);  // on the lower block (top at 4 cm), not beside or inside it
  EXPECT_LT(s.kinetic_energy, 1e-5);
  EXPECT_GT(s.mesh_contacts, 0u);
}

// The dropped blocks in the residual-driven mode: the contacts ride in
// every sweep the host sequences (sweeps until the bodies' residual reaches
// the tolerance), and the blocks rest on each other as in the fixed mode.
// The contacts' buffers and colours grow while they land, so the stepper's
// programs are rebuilt on the way.
TEST_P(MeshContact, DroppedBlocksRestOnEachOtherInTheResidualMode) {
  SceneDesc scene = dropped_blocks_scene(ContactSchedule::colored);
  scene.solver.residual_tolerance = 1e-4;
  scene.solver.max_iterations = 12;
  scene.solver.check_interval = 2;
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  std::uint64_t most_sweeps = 0;
  for (int f = 0; f < 80; ++f) {
    SINEW_ASSERT_OK(sim->step());
    most_sweeps = std::max(most_sweeps, sim->last_frame().sweeps);
  }
  const auto [depth, lowest_upper] = blocks_at_rest(*sim, scene);
  const FrameStats& s = sim->last_frame();
  std::printf("[%s] residual mode: depth %.3g mm, upper block's lowest %.4f m, KE %.3g J, %u contacts, most sweeps "
              "per frame %llu, violation %.3g mm\n",
              GetParam().c_str(), depth * 1e3, lowest_upper, s.kinetic_energy, s.mesh_contacts,
              static_cast<unsigned long long>(most_sweeps), s.contact_violation * 1e3);
  EXPECT_LT(depth, scene.mesh_collision.thickness);
  EXPECT_GT(lowest_upper, 0.0395);
  EXPECT_LT(s.kinetic_energy, 1e-5);
  EXPECT_GT(s.mesh_contacts, 0u);
  EXPECT_LT(s.contact_violation, scene.mesh_collision.thickness);
  // More sweeps than the fixed mode's 2 per substep ran at some frame: the
  // checks drove the sweeps.
  EXPECT_GT(most_sweeps, std::uint64_t(scene.solver.substeps) * scene.solver.iterations);
}

// The lambda warm start carries the bodies' lambdas across substeps; the
// mesh contacts change every frame, so the two together are an error that
// names both, on a scene of two blocks and no collider (whose contacts the
// warm start rejects on their own).
TEST_P(MeshContact, WarmStartWithMeshCollisionIsANamedError) {
  SceneDesc scene = dropped_blocks_scene(ContactSchedule::colored);
  scene.colliders.clear();
  scene.solver.residual_tolerance = 1e-4;
  scene.solver.warm_start = true;
  auto sim = create_or_skip(scene, GetParam());
  ASSERT_FALSE(sim.ok());
  EXPECT_NE(sim.error().message().find("warm_start"), std::string::npos) << sim.error().message();
  EXPECT_NE(sim.error().message().find("mesh_collision"), std::string::npos) << sim.error().message();
  scene.mesh_collision.enabled = false;
  auto fine = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(fine);
}

// A membrane strip lying on the floor has one end lifted by its edge's
// vertices (attached to targets) over the rest and laid down on it: the
// fold's upper layer settles onto the lower one by gravity and must never
// pass through it (no two triangles sharing no vertex ever intersect), and
// ends resting on it.
TEST_P(MeshContact, MembraneFoldedOntoItselfNeverPassesThroughItself) {
  constexpr int nz = FoldedStrip::nz;
  const SceneDesc scene = FoldedStrip::scene(ContactSchedule::colored);
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const std::uint32_t first = sim->info().tri_body_first_particle[0];
  std::vector<float> x;
  int worst = 0;
  std::uint32_t most_contacts = 0;
  constexpr int total = 2 * FoldedStrip::fold_frames;
  for (int f = 0; f < total; ++f) {
    for (int k = 0; k <= nz; ++k) SINEW_ASSERT_OK(sim->set_target(k, FoldedStrip::target(f, k)));
    SINEW_ASSERT_OK(sim->step());
    most_contacts = std::max(most_contacts, sim->last_frame().mesh_contacts);
    if (f % 6 == 5 || f + 1 == total) {
      SINEW_ASSERT_OK(sim->read_positions(x));
      worst = std::max(worst, self_intersections(x, scene.tri_bodies[0].mesh, first));
    }
  }
  // The upper layer (x from 6 to 9 cm when unfolded, folded back over 1 to
  // 4.5 cm) lies on the lower one: above it (on the floor) by about the
  // thickness. (Without mesh collision it lies in it: 158 intersecting
  // triangle pairs.)
  double lowest = 1e9;
  for (int i = 12; i <= 18; ++i)
    for (int k = 0; k <= nz; ++k) lowest = std::min(lowest, at(x, first + static_cast<std::uint32_t>(i * (nz + 1) + k))[1]);
  std::printf("[%s] intersecting triangle pairs %d, most contacts %u, upper layer's lowest vertex %.2f mm\n",
              GetParam().c_str(), worst, most_contacts, lowest * 1e3);
  EXPECT_EQ(worst, 0);
  EXPECT_GT(most_contacts, 0u);
  EXPECT_GT(lowest, 0.5 * scene.mesh_collision.thickness);
  EXPECT_LT(lowest, 3.0 * scene.mesh_collision.thickness);
}

// An empty scene without gravity, 60 frames per second of `substeps`
// substeps with 2 sweeps each.
SceneDesc weightless_scene(int substeps) {
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = substeps;
  scene.solver.iterations = 2;
  return scene;
}

// Two layers of one membrane 0.4 mm apart at the start, with a 1 mm
// thickness (a fissure in an organ's surface, a pre-folded sheet): the pairs
// of triangles already closer than the thickness are neighbours, never in
// contact, so nothing moves without gravity. (Contacts between them would
// push the layers 0.6 mm apart in the first frame; on the liver_382k surface
// at 1 mm, 683 such contacts blew the organ example up.)
TEST_P(MeshContact, SurfacesCloserThanTheThicknessAtTheStartAreNotPushedApart) {
  SceneDesc scene = weightless_scene(5);
  TriBodyDesc sheet;
  const TriMesh lower = membrane(8, 4, 0.005, 0.01), upper = membrane(8, 4, 0.005, 0.0104);
  sheet.mesh = lower;
  const auto offset = static_cast<std::uint32_t>(lower.vertices.size());
  sheet.mesh.vertices.insert(sheet.mesh.vertices.end(), upper.vertices.begin(), upper.vertices.end());
  for (auto t : upper.triangles) sheet.mesh.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  sheet.thickness = 1e-3;
  sheet.distance_compliance = 1e-6;
  sheet.area_compliance = 1e-6;
  scene.tri_bodies.push_back(sheet);
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 1e-3;
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  // Every triangle of one layer is within 1 mm of several of the other's.
  EXPECT_GE(sim->info().rest_close_triangle_pairs, lower.triangles.size());
  std::vector<float> start, x;
  SINEW_ASSERT_OK(sim->read_positions(start));
  for (int f = 0; f < 30; ++f) SINEW_ASSERT_OK(sim->step());
  SINEW_ASSERT_OK(sim->read_positions(x));
  double moved = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) moved = std::max(moved, std::abs(double(x[k]) - start[k]));
  EXPECT_LT(moved, 1e-6) << "the layers were pushed apart";
}

// A slab one cell (3 mm) thick squeezed to 0.8 mm between its pinned base
// and its top (attached to targets), under a 1 mm thickness: its top and
// bottom faces come within the thickness of each other across the slab's
// own material, not across air, so they make no self-contacts and the slab
// is squeezed as far as without mesh collision. (Without the rule, those
// faces pushed each other apart from inside; in the organ example a kidney
// pressed by the probe reached 3.7 mm violations.)
TEST_P(MeshContact, ASolidSqueezedThinMakesNoContactsAcrossItsMaterial) {
  const auto top_height = [&](bool collide) {
    SceneDesc scene = weightless_scene(10);
    TetBodyDesc slab;
    slab.mesh = *make_tet_grid({.nx = 4, .ny = 1, .nz = 4, .origin = {0, 0, 0}, .cell_size = {0.005, 0.003, 0.005}});
    (void)slab.set_elastic(1e5, 0.3);
    slab.density = 1000.0;
    slab.velocity_damping = 5.0;
    for (std::uint32_t v = 0; v < slab.mesh.vertices.size(); ++v) {
      const auto& x = slab.mesh.vertices[v];
      if (x[1] < 1e-9) {
        slab.pinned.push_back(v);
      } else {
        AttachmentDesc a;
        a.vertex = {BodyKind::tet, 0, v};
        a.target = static_cast<std::uint32_t>(scene.targets.size());
        scene.targets.push_back(x);
        scene.attachments.push_back(a);
      }
    }
    scene.tet_bodies.push_back(slab);
    scene.mesh_collision.enabled = collide;
    scene.mesh_collision.thickness = 1e-3;
    auto sim = create_or_skip(scene, GetParam());
    EXPECT_TRUE(sim.ok());
    if (!sim.ok()) return std::pair{0.0, 0u};
    std::uint32_t most = 0;
    for (int f = 0; f < 40; ++f) {
      const double y = 0.003 - 0.0022 * std::min(1.0, (f + 1) / 30.0);  // down to 0.8 mm
      for (std::size_t t = 0; t < scene.targets.size(); ++t) {
        auto at = scene.targets[t];
        at[1] = y;
        EXPECT_TRUE(sim->set_target(t, at).ok());
      }
      EXPECT_TRUE(sim->step().ok());
      most = std::max(most, sim->last_frame().mesh_contacts);
    }
    std::vector<float> x;
    EXPECT_TRUE(sim->read_positions(x).ok());
    double sum = 0.0;
    const std::uint32_t first = sim->info().tet_body_first_particle[0];
    for (const auto& a : scene.attachments) sum += x[4 * std::size_t{first + a.vertex.vertex} + 1];
    return std::pair{sum / double(scene.attachments.size()), most};
  };
  const auto [with, contacts] = top_height(true);
  const auto [without, none] = top_height(false);
  std::printf("[%s] top at %.4f mm with mesh collision (%u contacts at most), %.4f mm without\n", GetParam().c_str(),
              1e3 * with, contacts, 1e3 * without);
  EXPECT_EQ(contacts, 0u);
  EXPECT_LT(with, 1e-3);  // squeezed below the thickness
  EXPECT_NEAR(with, without, 1e-6);
}

// A thread (a line body of 24 segments with bending) dropped diagonally
// across a tissue block (pinned at its base) from 5 mm: its segments and vertices meet the
// block's faces and edges (segment-triangle contacts) and it comes to rest
// on the top face, one thickness up, never through it (no segment crosses
// a boundary triangle at any 5th frame). Without mesh collision it falls
// through the block.
TEST_P(MeshContact, ThreadDroppedOnTissueRestsOnItsSurface) {
  SceneDesc scene;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 10;
  scene.solver.iterations = 2;
  scene.tet_bodies.push_back(soft_block(4, 0.01, {0.0, 0.0, 0.0}));
  scene.tet_bodies[0].pinned.clear();
  for (std::uint32_t v = 0; v < scene.tet_bodies[0].mesh.vertices.size(); ++v)
    if (scene.tet_bodies[0].mesh.vertices[v][1] < 1e-9) scene.tet_bodies[0].pinned.push_back(v);
  LineBodyDesc thread;
  constexpr int segments = 24;
  for (int i = 0; i <= segments; ++i) {
    thread.vertices.push_back({-0.01 + 0.06 * i / segments, 0.045, 0.013 + 0.011 * i / segments});
    thread.masses.push_back(1e-5);
  }
  for (int i = 0; i < segments; ++i)
    thread.segments.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i + 1)});
  thread.bending_compliance = 1e-2;
  thread.velocity_damping = 2.0;
  scene.line_bodies.push_back(thread);
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 1e-3;
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const TriMesh top = extract_boundary_surface(scene.tet_bodies[0].mesh);
  const std::uint32_t block = sim->info().tet_body_first_particle[0], line = sim->info().line_body_first_particle[0];
  std::vector<float> x;
  int crossings = 0;
  std::uint32_t most = 0;
  for (int f = 0; f < 90; ++f) {
    SINEW_ASSERT_OK(sim->step());
    most = std::max(most, sim->last_frame().mesh_contacts);
    if (f % 5 != 4) continue;
    SINEW_ASSERT_OK(sim->read_positions(x));
    for (int i = 0; i < segments; ++i)
      for (const auto& t : top.triangles)
        crossings += segment_crosses_triangle(at(x, line + i), at(x, line + i + 1), at(x, block + t[0]),
                                              at(x, block + t[1]), at(x, block + t[2]));
  }
  // The thread's vertices over the block (x in 0..4 cm) rest on its top face (4 cm).
  double lowest = 1e9, highest = -1e9;
  for (int i = 0; i <= segments; ++i) {
    const P3 p = at(x, line + i);
    if (p[0] < 0.002 || p[0] > 0.038) continue;
    lowest = std::min(lowest, p[1]);
    highest = std::max(highest, p[1]);
  }
  std::printf("[%s] thread over the block between %.2f and %.2f mm, %d crossings, most contacts %u\n",
              GetParam().c_str(), 1e3 * lowest, 1e3 * highest, crossings, most);
  EXPECT_EQ(crossings, 0);
  EXPECT_GT(most, 0u);
  EXPECT_GT(lowest, 0.04);            // above the top face
  EXPECT_LT(highest, 0.04 + 0.003);   // and resting on it, within a few thicknesses
}

// A capsule probe presses the kidney (57k tets, the mesher's order) onto the
// liver's surface (the liver_382k boundary triangles under it, fixed) and
// holds it there: the kidney flattens against the liver (its height drops
// by ~15 mm) but no edge of its surface ever crosses a liver triangle
// (checked every 5th frame, exactly, in double). Without mesh collision
// the probe pushes it through: 93 crossing pairs, its lowest point 9 mm
// deeper. On the GPU backends the CPU reference runs beside it: positions
// within 1e-5 m after the 40 frames.
TEST_P(MeshContact, CapsulePressesTheKidneyOntoTheLiverWithoutPassingThrough) {
  static const auto organs = KidneyOnLiver::load(SINEW_DATA_DIR);
  SINEW_ASSERT_OK(organs);
  const SceneDesc scene = organs->scene();
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  std::optional<Simulation> reference;  // beside a GPU backend
  if (GetParam() != "cpu") {
    auto cpu = create_or_skip(scene, "cpu");
    SINEW_ASSERT_OK(cpu);
    reference.emplace(std::move(*cpu));
  }
  const std::uint32_t kidney = sim->info().tet_body_first_particle[0], liver = sim->info().tri_body_first_particle[0];
  const auto kidney_edges = edges_of(extract_boundary_surface(organs->kidney), kidney);
  std::vector<std::array<std::uint32_t, 3>> liver_triangles;
  for (const auto& t : organs->liver.triangles) liver_triangles.push_back({liver + t[0], liver + t[1], liver + t[2]});
  std::vector<float> x;
  int worst = 0;
  std::uint32_t most = 0;
  double deepest = 0.0;
  constexpr int frames = 2 * KidneyOnLiver::press_frames;
  for (int f = 0; f < frames; ++f) {
    SINEW_ASSERT_OK(sim->set_collider_pose(0, organs->probe_at(f), scene.colliders[0].rotation));
    SINEW_ASSERT_OK(sim->step());
    if (reference) {
      SINEW_ASSERT_OK(reference->set_collider_pose(0, organs->probe_at(f), scene.colliders[0].rotation));
      SINEW_ASSERT_OK(reference->step());
    }
    most = std::max(most, sim->last_frame().mesh_contacts);
    deepest = std::max(deepest, sim->last_frame().contact_violation);
    if (f % 5 != 4) continue;
    SINEW_ASSERT_OK(sim->read_positions(x));
    worst = std::max(worst, crossings(x, kidney_edges, liver_triangles, 0.004));
  }
  // The kidney's height (its extent along y) before and after: pressed flatter.
  double top0 = -1e9, bottom0 = 1e9, top = -1e9, bottom = 1e9;
  for (std::uint32_t v = 0; v < organs->kidney.vertices.size(); ++v) {
    top0 = std::max(top0, organs->kidney.vertices[v][1]);
    bottom0 = std::min(bottom0, organs->kidney.vertices[v][1]);
    top = std::max(top, at(x, kidney + v)[1]);
    bottom = std::min(bottom, at(x, kidney + v)[1]);
  }
  std::printf("[%s] crossings %d, most contacts %u, deepest contact violation %.3f mm, kidney height %.1f -> %.1f mm, "
              "lowest point %.2f -> %.2f mm\n",
              GetParam().c_str(), worst, most, 1e3 * deepest, 1e3 * (top0 - bottom0), 1e3 * (top - bottom), 1e3 * bottom0,
              1e3 * bottom);
  EXPECT_EQ(worst, 0);
  EXPECT_GT(most, 0u);
  EXPECT_LT(top - bottom, top0 - bottom0 - 0.005);  // the probe pressed it against the liver
  if (!reference) return;
  std::vector<float> expected;
  SINEW_ASSERT_OK(reference->read_positions(expected));
  ASSERT_EQ(expected.size(), x.size());
  double difference = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) difference = std::max(difference, std::abs(double(x[i]) - expected[i]));
  std::printf("[%s] largest difference from the CPU reference %.3g m\n", GetParam().c_str(), difference);
  EXPECT_LE(difference, 1e-5);
}

// A thin probe (a capsule collider 4 mm thick, 12 mm long) pressed 15 mm
// down into the middle of one 2 cm cell of a coarse membrane (pinned at its
// border): no vertex of the membrane ever touches the probe, so only the
// triangle-shape contacts hold it. The membrane under the probe's centre
// ends below the probe (within the thickness) and the probe's axis never
// crosses a triangle. Without them the probe passes through the cell: the
// membrane there stays at its height, 10 mm above the probe.
TEST_P(MeshContact, ThinProbePressesACoarseMembraneBetweenItsVertices) {
  const SceneDesc scene = ThinProbe::scene();
  const ColliderDesc& probe = scene.colliders[0];
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const std::uint32_t first = sim->info().tri_body_first_particle[0];
  std::vector<float> x;
  int crossings = 0;
  std::array<double, 3> at_end = probe.position;
  for (int f = 0; f < ThinProbe::frames; ++f) {
    at_end = ThinProbe::probe_at(f);
    SINEW_ASSERT_OK(sim->set_collider_pose(0, at_end, probe.rotation));
    SINEW_ASSERT_OK(sim->step());
    SINEW_ASSERT_OK(sim->read_positions(x));
    const P3 axis0{at_end[0], at_end[1], at_end[2] - probe.half_height}, axis1{at_end[0], at_end[1], at_end[2] + probe.half_height};
    for (const auto& t : scene.tri_bodies[0].mesh.triangles)
      crossings += segment_crosses_triangle(axis0, axis1, at(x, first + t[0]), at(x, first + t[1]), at(x, first + t[2]));
  }
  // The membrane's height over the probe's centre: where the vertical line
  // there meets it.
  double height = 1e9;
  for (const auto& t : scene.tri_bodies[0].mesh.triangles) {
    const P3 a = at(x, first + t[0]), b = at(x, first + t[1]), c = at(x, first + t[2]);
    const P3 top{at_end[0], 1.0, at_end[2]}, bottom{at_end[0], -1.0, at_end[2]};
    if (!segment_crosses_triangle(top, bottom, a, b, c)) continue;
    const P3 n = cross(sub(b, a), sub(c, a));
    height = a[1] - (n[0] * (at_end[0] - a[0]) + n[2] * (at_end[2] - a[2])) / n[1];
  }
  const FrameStats& s = sim->last_frame();
  std::printf("[%s] membrane over the probe's centre at %.2f mm, probe's bottom at %.2f mm, %d crossings, %u contacts\n",
              GetParam().c_str(), 1e3 * height, 1e3 * (at_end[1] - probe.radius), crossings, s.mesh_contacts);
  EXPECT_EQ(crossings, 0);
  EXPECT_LT(height, at_end[1] - probe.radius + 1e-4);                  // under the probe
  EXPECT_GT(height, at_end[1] - probe.radius - scene.mesh_collision.thickness - 1e-3);  // and on it
  EXPECT_GT(s.mesh_contacts, 0u);
}

// The thread's twin: a thread of four 2 cm segments pinned at both ends,
// the thin probe (upright) pressed 15 mm down onto the middle of a segment
// (no vertex under it): the segment-shape contact holds the thread on the
// probe's tip (never into it, at most the thickness off) and pressed down
// with it. Without it the probe passes through: the thread stays straight
// at its height, 2 mm into the probe.
TEST_P(MeshContact, ThinProbePressesACoarseThreadBetweenItsVertices) {
  SceneDesc scene = ThinProbe::scene();
  scene.tri_bodies.clear();
  LineBodyDesc thread;
  for (int i = 0; i <= 4; ++i) {
    thread.vertices.push_back({0.02 + 0.02 * i, 0.0, 0.03});
    thread.masses.push_back(1e-4);
  }
  thread.pinned = {0, 4};
  for (std::uint32_t i = 0; i < 4; ++i) thread.segments.push_back({i, i + 1});
  thread.velocity_damping = 5.0;
  scene.line_bodies.push_back(thread);
  scene.colliders[0].rotation = {1.0, 0.0, 0.0, 0.0};  // the probe upright: across the thread, its tip down
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const std::uint32_t first = sim->info().line_body_first_particle[0];
  std::array<double, 3> at_end{};
  double lowest_tip = 1e9;  // the probe's tip [m]
  for (int f = 0; f < ThinProbe::frames; ++f) {
    at_end = ThinProbe::probe_at(f);
    at_end[0] = 0.05;  // over the middle of the thread's third segment (4 to 6 cm)
    at_end[1] += scene.colliders[0].half_height;
    SINEW_ASSERT_OK(sim->set_collider_pose(0, at_end, scene.colliders[0].rotation));
    SINEW_ASSERT_OK(sim->step());
    lowest_tip = std::min(lowest_tip, at_end[1] - scene.colliders[0].half_height - scene.colliders[0].radius);
  }
  std::vector<float> x;
  SINEW_ASSERT_OK(sim->read_positions(x));
  // The thread's clearance from the probe (sampled along its segments, in
  // double) and its lowest point.
  double clearance = 1e9, lowest = 1e9;
  for (int i = 0; i < 4; ++i) {
    const P3 a = at(x, first + i), b = at(x, first + i + 1);
    for (int k = 0; k <= 200; ++k) {
      const double u = k / 200.0;
      const P3 p{a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * (b[2] - a[2])};
      const double hh = scene.colliders[0].half_height;
      const double y = std::clamp(p[1], at_end[1] - hh, at_end[1] + hh);
      clearance = std::min(clearance, std::hypot(p[0] - at_end[0], p[1] - y, p[2] - at_end[2]) - scene.colliders[0].radius);
      lowest = std::min(lowest, p[1]);
    }
  }
  std::printf("[%s] thread %.2f mm clear of the probe, its lowest point at %.2f mm, probe's tip at %.2f mm, %u contacts\n",
              GetParam().c_str(), 1e3 * clearance, 1e3 * lowest, 1e3 * lowest_tip, sim->last_frame().mesh_contacts);
  EXPECT_GT(clearance, -1e-4);                                   // never into the probe
  EXPECT_LT(clearance, scene.mesh_collision.thickness + 1e-3);   // but on it
  EXPECT_LT(lowest, lowest_tip + 1e-3);                          // pressed down with it
}

// A rigid tool (the thin probe's capsule, 20 g, no gravity) held by a
// virtual coupling (ThinProbe::couple: a critically damped spring of 20 N/m,
// as a haptic device drives a tool) to a target 10 mm under the middle of
// a coarse membrane's cell (no vertex under it, the border pinned): only
// the triangles' faces can hold it. Its axis never crosses the membrane, it
// stops on the membrane well above the target, and the reaction the faces
// give it (MeshCollision::add_tool_reactions) balances the spring: over
// the last 60 frames the mean contact force is the mean spring force's
// opposite within 10%, with no sideways part to speak of. With the faces
// turned off (MeshCollisionDesc::tool_faces) the tool passes through the
// cell to the target.
TEST_P(MeshContact, AToolHeldByACouplingPressesACoarseMembraneBetweenItsVertices) {
  const double mass = 0.02;
  const SceneDesc scene = ThinProbe::tool_scene(mass);
  const double target = ThinProbe::kTarget[1];
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const std::uint32_t first = sim->info().tri_body_first_particle[0];
  const ToolDesc& tool = scene.tools[0];
  std::vector<float> x;
  int crossings = 0;
  double force[3] = {0.0, 0.0, 0.0}, spring = 0.0;
  constexpr int kFrames = 150, kAveraged = 60;
  for (int f = 0; f < kFrames; ++f) {
    std::array<double, 3> pull{};
    SINEW_ASSERT_OK(ThinProbe::couple(*sim, mass, pull));
    SINEW_ASSERT_OK(sim->step());
    SINEW_ASSERT_OK(sim->read_positions(x));
    auto state = sim->tool_state(0);
    SINEW_ASSERT_OK(state);
    const P3 c{state->position[0], state->position[1], state->position[2]};
    const P3 axis0{c[0], c[1], c[2] - tool.half_height}, axis1{c[0], c[1], c[2] + tool.half_height};
    for (const auto& t : scene.tri_bodies[0].mesh.triangles)
      crossings += segment_crosses_triangle(axis0, axis1, at(x, first + t[0]), at(x, first + t[1]), at(x, first + t[2]));
    if (f >= kFrames - kAveraged) {
      for (int k = 0; k < 3; ++k) force[k] += state->contact_force[k] / kAveraged;
      spring += pull[1] / kAveraged;
    }
  }
  auto state = sim->tool_state(0);
  SINEW_ASSERT_OK(state);
  std::printf("[%s] tool at %.2f mm (target %.2f), mean contact force (%.4f, %.4f, %.4f) N against a mean spring "
              "force of %.4f N, %d crossings, %u contacts\n",
              GetParam().c_str(), 1e3 * state->position[1], 1e3 * target, force[0], force[1], force[2], spring,
              crossings, sim->last_frame().mesh_contacts);
  EXPECT_EQ(crossings, 0);
  EXPECT_GT(state->position[1], target + 0.003) << "through the membrane";
  EXPECT_LT(spring, -0.05) << "the spring presses the tool down";
  EXPECT_NEAR(force[1], -spring, 0.1 * std::abs(spring));
  EXPECT_LT(std::hypot(force[0], force[2]), 0.1 * std::abs(spring));

  SceneDesc without = scene;
  without.mesh_collision.tool_faces = false;
  auto through = create_or_skip(without, GetParam());
  SINEW_ASSERT_OK(through);
  for (int f = 0; f < kFrames; ++f) {
    std::array<double, 3> pull{};
    SINEW_ASSERT_OK(ThinProbe::couple(*through, mass, pull));
    SINEW_ASSERT_OK(through->step());
  }
  auto passed = through->tool_state(0);
  SINEW_ASSERT_OK(passed);
  EXPECT_NEAR(passed->position[1], target, 5e-4) << "without the faces nothing holds the tool";
}

// Every backend against the CPU reference after 100 frames: the dropped
// blocks with either schedule (contacts from the third frame on), the
// folded membrane (self-contacts from about the 40th) and the thin probe
// (triangle-shape contacts) with either schedule, the coupled tool on
// the membrane (its faces' reaction moves the tool), and with
// SolverSettings::contact_sweeps the 500 g tool lying on a membrane
// (tests/contact_hold_support.h) and the blocks with the Jacobi schedule:
// positions within
// 1e-5 m (the kernels follow the CPU's operation order without fused
// multiply-adds, so they are expected to agree bitwise; the test prints how
// many coordinates do). The contacts are found on the host from each
// backend's own positions, so any difference would also change contacts.
// (The kidney pressed onto the liver is compared in its own test above.)
TEST_P(MeshContact, BackendsAgreeWithTheCpuReference) {
  if (GetParam() == "cpu") GTEST_SKIP() << "the reference itself";
  struct Case {
    const char* name;
    SceneDesc scene;
    bool fold, probe;
    bool tool = false;  // held by ThinProbe::couple
  };
  SceneDesc probe_jacobi = ThinProbe::scene();
  probe_jacobi.mesh_collision.schedule = ContactSchedule::jacobi;
  SceneDesc blocks_jacobi_swept = dropped_blocks_scene(ContactSchedule::jacobi);
  blocks_jacobi_swept.solver.contact_sweeps = 2;
  const Case cases[] = {{"blocks, colored", dropped_blocks_scene(ContactSchedule::colored), false, false},
                        {"blocks, jacobi", dropped_blocks_scene(ContactSchedule::jacobi), false, false},
                        {"fold, colored", FoldedStrip::scene(ContactSchedule::colored), true, false},
                        {"thin probe, colored", ThinProbe::scene(), false, true},
                        {"thin probe, jacobi", probe_jacobi, false, true},
                        {"coupled tool on the membrane", ThinProbe::tool_scene(0.02), false, false, true},
                        {"heavy tool on the membrane, contact sweeps", ToolOnMembrane::scene(0.5, 4), false, false},
                        {"blocks, jacobi, contact sweeps", blocks_jacobi_swept, false, false}};
  for (const Case& c : cases) {
    auto reference = create_or_skip(c.scene, "cpu");
    auto sim = create_or_skip(c.scene, GetParam());
    SINEW_ASSERT_OK(reference);
    SINEW_ASSERT_OK(sim);
    std::uint64_t contacts = 0;
    for (int f = 0; f < 100; ++f) {
      for (int k = 0; c.fold && k <= FoldedStrip::nz; ++k) {
        SINEW_ASSERT_OK(reference->set_target(k, FoldedStrip::target(f, k)));
        SINEW_ASSERT_OK(sim->set_target(k, FoldedStrip::target(f, k)));
      }
      if (c.tool) {
        std::array<double, 3> pull{};
        SINEW_ASSERT_OK(ThinProbe::couple(*reference, 0.02, pull));
        SINEW_ASSERT_OK(ThinProbe::couple(*sim, 0.02, pull));
      }
      if (c.probe) {
        const auto at = ThinProbe::probe_at(f % ThinProbe::frames);  // pressed, then again from the top
        SINEW_ASSERT_OK(reference->set_collider_pose(0, at, c.scene.colliders[0].rotation));
        SINEW_ASSERT_OK(sim->set_collider_pose(0, at, c.scene.colliders[0].rotation));
      }
      SINEW_ASSERT_OK(reference->step());
      SINEW_ASSERT_OK(sim->step());
      contacts += sim->last_frame().mesh_contacts;
      EXPECT_EQ(sim->last_frame().mesh_contacts, reference->last_frame().mesh_contacts) << c.name << ", frame " << f;
    }
    std::vector<float> a, b;
    SINEW_ASSERT_OK(reference->read_positions(a));
    SINEW_ASSERT_OK(sim->read_positions(b));
    ASSERT_EQ(a.size(), b.size());
    double worst = 0.0;
    std::size_t equal = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      worst = std::max(worst, std::abs(double(a[i]) - double(b[i])));
      equal += a[i] == b[i];
    }
    std::printf("[%s, %s] %zu of %zu words bitwise equal, largest difference %.3g m, %llu contacts in all\n",
                GetParam().c_str(), c.name, equal, a.size(), worst, static_cast<unsigned long long>(contacts));
    EXPECT_GT(contacts, 0u) << c.name;
    EXPECT_LE(worst, 1e-5) << c.name;
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, MeshContact, ::testing::ValuesIn(backends()), backend_name);

}  // namespace
}  // namespace sinew::test
