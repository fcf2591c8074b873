// body_attachment_test.cpp — attachments between bodies (BodyAttachmentDesc)
// on the CPU reference, as physics:
//  - a block hangs face to face from a pinned block: it stays up (its sag a
//    small fraction of free fall), the attached points stay together, and
//    the pinned block stretches more under it than under its own weight
//    alone (the reaction reaches it);
//  - a compliant attachment stretches by compliance x the weight it holds
//    ([m/N]);
//  - a membrane attached to a block lying on a plane lifts it when its
//    border is pulled up (tri-tet points inside tets), and without the
//    attachments the block stays on the plane;
//  - an attachment loaded by a slowly growing force lets go when the load
//    passes its break force and not before, and stays broken;
//  - bad input is refused with an error naming the field.
// The GPU kernel's agreement with the reference is in
// body_attachment_agreement_test.cpp.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "sinew/scene.h"
#include "sinew/simulation.h"
#include "test_support.h"

namespace sinew::test {
namespace {

constexpr double kCell = 0.01;  // [m]

// A tet block of nx x ny x nz cells with its lowest corner at `origin`.
TetBodyDesc block(int nx, int ny, int nz, const Vec3d& origin, double young) {
  TetBodyDesc body;
  body.mesh = box_mesh(nx, ny, nz, kCell);
  for (Vec3d& v : body.mesh.vertices) v = {v[0] + origin[0], v[1] + origin[1], v[2] + origin[2]};
  EXPECT_TRUE(body.set_elastic(young, 0.3).ok());
  body.velocity_damping = 5.0;  // settles within a second
  return body;
}

// Vertices of `mesh` at height y (within 1e-9 m).
std::vector<std::uint32_t> at_height(const TetMesh& mesh, double y) {
  std::vector<std::uint32_t> out;
  for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v)
    if (std::abs(mesh.vertices[v][1] - y) < 1e-9) out.push_back(v);
  return out;
}

// The vertex of `mesh` at `p` (within 1e-9 m); fails the test if none.
std::uint32_t vertex_at(const TetMesh& mesh, const Vec3d& p) {
  for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v)
    if (std::abs(mesh.vertices[v][0] - p[0]) < 1e-9 && std::abs(mesh.vertices[v][1] - p[1]) < 1e-9 &&
        std::abs(mesh.vertices[v][2] - p[2]) < 1e-9)
      return v;
  ADD_FAILURE() << "no vertex at (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
  return 0;
}

// The point of tet body `body` at `p`: the first tet containing it, with
// its four barycentric weights.
BarycentricPoint point_in_tets(const TetMesh& mesh, std::uint32_t body, const Vec3d& p) {
  for (const auto& t : mesh.tets) {
    const Vec3d& a = mesh.vertices[t[0]];
    Vec3d e[3], r;
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) e[k][c] = mesh.vertices[t[k + 1]][c] - a[c];
    }
    for (int c = 0; c < 3; ++c) r[c] = p[c] - a[c];
    const auto det = [](const Vec3d& u, const Vec3d& v, const Vec3d& w) {
      return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
    };
    const double d = det(e[0], e[1], e[2]);
    const double b1 = det(r, e[1], e[2]) / d, b2 = det(e[0], r, e[2]) / d, b3 = det(e[0], e[1], r) / d;
    const double b0 = 1.0 - b1 - b2 - b3;
    if (b0 >= -1e-9 && b1 >= -1e-9 && b2 >= -1e-9 && b3 >= -1e-9)
      return {BodyKind::tet, body, {t[0], t[1], t[2], t[3]}, {b0, b1, b2, b3}};
  }
  ADD_FAILURE() << "no tet contains (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
  return {};
}

SolverSettings solver() { return {.time_step = 1.0 / 60.0, .substeps = 8, .iterations = 4}; }

std::vector<float> positions(Simulation& sim) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  return x;
}

// Mean y of particles [first, first + n).
double mean_y(const std::vector<float>& x, std::size_t first, std::size_t n) {
  double s = 0.0;
  for (std::size_t p = first; p < first + n; ++p) s += x[4 * p + 1];
  return s / double(n);
}

// A 4 x 2 x 4 cm block A whose top is pinned, and block B below it, B's top
// face on A's bottom face, each vertex there attached to A's (1-vertex
// points); `attach` false leaves B out (A alone).
SceneDesc hanging_blocks(bool with_b, double compliance = 0.0, double break_force = INFINITY) {
  SceneDesc scene;
  scene.solver = solver();
  TetBodyDesc a = block(4, 2, 4, {0.0, 0.02, 0.0}, 5e3);
  a.pinned = at_height(a.mesh, 0.04);
  scene.tet_bodies.push_back(a);
  if (!with_b) return scene;
  TetBodyDesc b = block(4, 2, 4, {0.0, 0.0, 0.0}, 5e3);
  for (std::uint32_t v : at_height(b.mesh, 0.02)) {
    BodyAttachmentDesc link;
    link.a = {BodyKind::tet, 0, {vertex_at(a.mesh, b.mesh.vertices[v])}, {1.0}};
    link.b = {BodyKind::tet, 1, {v}, {1.0}};
    link.compliance = compliance;
    link.break_force = break_force;
    scene.body_attachments.push_back(link);
  }
  scene.tet_bodies.push_back(b);
  return scene;
}

TEST(BodyAttachments, BlockHangsFromPinnedBlock) {
  const SceneDesc alone = hanging_blocks(false), both = hanging_blocks(true);
  auto a = Simulation::create(alone, {.backend = "cpu", .quiet = true});
  auto ab = Simulation::create(both, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(a);
  SINEW_ASSERT_OK(ab);
  const double seconds = 1.0;
  for (int f = 0; f < 60; ++f) {
    SINEW_ASSERT_OK(a->step());
    SINEW_ASSERT_OK(ab->step());
  }
  const std::vector<float> xa = positions(*a), xab = positions(*ab);
  const TetMesh& ma = both.tet_bodies[0].mesh;
  const TetMesh& mb = both.tet_bodies[1].mesh;
  const std::size_t na = ma.vertices.size(), nb = mb.vertices.size();
  // B stays up: its mean drop is a small fraction of the free fall g t^2 / 2.
  double drop_b = 0.0;
  for (std::size_t v = 0; v < nb; ++v) drop_b += mb.vertices[v][1] - xab[4 * (na + v) + 1];
  drop_b /= double(nb);
  EXPECT_GT(drop_b, 0.0) << "B sags under its weight";
  EXPECT_LT(drop_b, 5e-3) << "B hangs: its mean drop stays under 5 mm (free fall: 4.9 m)";
  // The attached points stay together (compliance 0): within 0.1 mm.
  double gap = 0.0;
  for (const BodyAttachmentDesc& l : both.body_attachments) {
    const float* p = &xab[4 * l.a.vertices[0]];
    const float* q = &xab[4 * (na + l.b.vertices[0])];
    gap = std::max(gap, std::hypot(double(p[0]) - q[0], double(p[1]) - q[1], double(p[2]) - q[2]));
  }
  EXPECT_LT(gap, 1e-4);
  // The reaction: A's bottom face sinks more with B's weight on it. A
  // hanging bar's end sinks m g L / (2 E S) under its own weight and m g L /
  // (E S) more under an equal mass hung from it: 3 times as far.
  double sink_alone = 0.0, sink_loaded = 0.0;
  const std::vector<std::uint32_t> bottom = at_height(ma, 0.02);
  for (std::uint32_t v : bottom) {
    sink_alone += (0.02 - xa[4 * v + 1]) / double(bottom.size());
    sink_loaded += (0.02 - xab[4 * v + 1]) / double(bottom.size());
  }
  EXPECT_GT(sink_alone, 0.0);
  EXPECT_GT(sink_loaded, 2.0 * sink_alone) << "A feels B's weight";
  EXPECT_LT(sink_loaded, 4.0 * sink_alone);
  std::printf("[ measured ] after %.1f s: B's mean drop %.3g mm, largest gap %.3g mm; A's bottom sinks %.3g mm alone, "
              "%.3g mm holding B (ratio %.2f; a bar: 3)\n",
              seconds, drop_b * 1e3, gap * 1e3, sink_alone * 1e3, sink_loaded * 1e3, sink_loaded / sink_alone);
}

// A 2 cm cube B hung by one attachment from the centre of its top face (4
// vertices at 1/4) to a pinned vertex of A; with external forces pulling B
// down on top of gravity.
SceneDesc hung_cube(double compliance, double break_force) {
  SceneDesc scene;
  scene.solver = solver();
  scene.solver.iterations = 10;
  scene.external_forces = true;
  TetBodyDesc a = block(1, 1, 1, {0.0, 0.03, 0.0}, 5e4);
  a.pinned = {vertex_at(a.mesh, {0.0, 0.03, 0.0})};
  scene.tet_bodies.push_back(a);
  TetBodyDesc b;
  b.mesh = box_mesh(1, 1, 1, 0.02);
  for (Vec3d& v : b.mesh.vertices) v = {v[0] - 0.01, v[1] + 0.01, v[2] - 0.01};
  EXPECT_TRUE(b.set_elastic(5e4, 0.3).ok());
  b.velocity_damping = 5.0;
  scene.tet_bodies.push_back(b);
  BodyAttachmentDesc link;
  link.a = {BodyKind::tet, 0, {a.pinned[0]}, {1.0}};
  link.b = {BodyKind::tet, 1, at_height(b.mesh, 0.03), {0.25, 0.25, 0.25, 0.25}};
  link.compliance = compliance;
  link.break_force = break_force;
  scene.body_attachments.push_back(link);
  return scene;
}

TEST(BodyAttachments, CompliantAttachmentStretchesByComplianceTimesLoad) {
  const double compliance = 1e-2;  // [m/N]
  const SceneDesc scene = hung_cube(compliance, INFINITY);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  for (int f = 0; f < 120; ++f) SINEW_ASSERT_OK(sim->step());
  const std::vector<float> x = positions(*sim);
  const std::size_t na = scene.tet_bodies[0].mesh.vertices.size();
  const double weight = 1000.0 * 0.02 * 0.02 * 0.02 * 9.81;  // [N]
  double centre[3] = {0, 0, 0};
  for (std::uint32_t v : scene.body_attachments[0].b.vertices)
    for (int c = 0; c < 3; ++c) centre[c] += 0.25 * x[4 * (na + v) + c];
  const float* pin = &x[4 * scene.body_attachments[0].a.vertices[0]];
  const double stretch = std::hypot(pin[0] - centre[0], pin[1] - centre[1], pin[2] - centre[2]);
  EXPECT_NEAR(stretch, compliance * weight, 0.1 * compliance * weight);
  std::printf("[ measured ] compliance %.3g m/N holding %.4g N: stretch %.4g mm (compliance x load %.4g mm)\n",
              compliance, weight, stretch * 1e3, compliance * weight * 1e3);
}

TEST(BodyAttachments, BreaksWhenItsForcePassesBreakForceAndNotBefore) {
  const double break_force = 0.3;  // [N]
  const SceneDesc scene = hung_cube(1e-3, break_force);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const std::size_t na = scene.tet_bodies[0].mesh.vertices.size(), nb = scene.tet_bodies[1].mesh.vertices.size();
  const double weight = 1000.0 * 0.02 * 0.02 * 0.02 * 9.81;  // [N]
  // Settle for 30 frames, then pull B down with a force growing by 0.2% of
  // the break force per frame: quasi-static (B's damping time 0.2 s).
  const double rate = 0.002 * break_force;  // [N per frame]
  std::vector<float> forces(3 * (na + nb), 0.0f);
  double hanging_y = 0.0, load_at_break = -1.0, last_held_load = 0.0;
  for (int f = 0; f < 30 + 1000 && load_at_break < 0.0; ++f) {
    const double pull = f < 30 ? 0.0 : rate * (f - 30);
    for (std::size_t v = 0; v < nb; ++v) forces[3 * (na + v) + 1] = -static_cast<float>(pull / double(nb));
    SINEW_ASSERT_OK(sim->set_particle_forces(forces));
    SINEW_ASSERT_OK(sim->step());
    const double y = mean_y(positions(*sim), na, nb);
    if (f == 29) hanging_y = y;
    // Let go: B falls 5 mm below where it hung (the attachment stretches
    // 0.3 mm at the break force).
    if (f >= 30 && y < hanging_y - 5e-3) load_at_break = weight + pull;
    else last_held_load = weight + pull;
  }
  ASSERT_GT(load_at_break, 0.0) << "never broke";
  // Held up to 95% of the break force, gone by 105% (B falls 5 mm in
  // about 0.03 s, a frame or two of the ramp).
  EXPECT_GT(last_held_load, 0.95 * break_force) << "broke before its break force";
  EXPECT_LT(load_at_break, 1.05 * break_force) << "held past its break force";
  // Broken for good: with the pull gone it keeps falling.
  std::fill(forces.begin(), forces.end(), 0.0f);
  SINEW_ASSERT_OK(sim->set_particle_forces(forces));
  const double y_break = mean_y(positions(*sim), na, nb);
  for (int f = 0; f < 20; ++f) SINEW_ASSERT_OK(sim->step());
  EXPECT_LT(mean_y(positions(*sim), na, nb), y_break - 0.02) << "B falls on after the break";
  std::printf("[ measured ] break force %.3g N: held at %.4g N, broke at %.4g N\n", break_force, last_held_load,
              load_at_break);
}

// A 4 x 1 x 4 cm block on a plane and a 4 x 4 cm membrane (0.5 cm grid)
// lying on its top face; each membrane vertex attached to the block's tet
// there (4 weights; tri-tet). The membrane's border is held by targets
// raised 2 cm over a second.
SceneDesc membrane_on_block(bool attached) {
  SceneDesc scene;
  scene.solver = solver();
  ColliderDesc plane;
  scene.colliders.push_back(plane);
  TetBodyDesc organ = block(4, 1, 4, {0.0, 0.0, 0.0}, 2e4);
  scene.tet_bodies.push_back(organ);
  TriBodyDesc membrane;
  const int n = 8;  // cells a side
  for (int k = 0; k <= n; ++k)
    for (int i = 0; i <= n; ++i) membrane.mesh.vertices.push_back({0.04 * i / n, 0.01, 0.04 * k / n});
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < n; ++i) {
      const std::uint32_t v = k * (n + 1) + i;
      membrane.mesh.triangles.push_back({v, v + n + 1, v + 1});
      membrane.mesh.triangles.push_back({v + 1, v + n + 1, v + n + 2});
    }
  membrane.distance_compliance = 1e-7;
  membrane.area_compliance = 1e-7;
  membrane.velocity_damping = 5.0;
  for (std::uint32_t v = 0; v < membrane.mesh.vertices.size(); ++v) {
    const Vec3d& p = membrane.mesh.vertices[v];
    const bool border = p[0] < 1e-9 || p[0] > 0.04 - 1e-9 || p[2] < 1e-9 || p[2] > 0.04 - 1e-9;
    if (border) {
      scene.targets.push_back({p[0], p[1], p[2]});
      scene.attachments.push_back({{BodyKind::tri, 0, v}, static_cast<std::uint32_t>(scene.targets.size() - 1), 0.0});
    } else if (attached) {
      BodyAttachmentDesc link;
      link.a = {BodyKind::tri, 0, {v}, {1.0}};
      link.b = point_in_tets(organ.mesh, 0, p);
      scene.body_attachments.push_back(link);
    }
  }
  scene.tri_bodies.push_back(membrane);
  return scene;
}

double lift_of_block(bool attached) {
  const SceneDesc scene = membrane_on_block(attached);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  EXPECT_TRUE(sim.ok()) << (sim.ok() ? "" : sim.error().message());
  if (!sim.ok()) return NAN;
  const std::size_t n = scene.tet_bodies[0].mesh.vertices.size();
  double start = 0.0;
  for (int f = 0; f < 90; ++f) {
    if (f == 10) start = mean_y(positions(*sim), 0, n);
    const double rise = f < 10 ? 0.0 : std::min(0.02, 0.02 * (f - 10) / 60.0);
    for (std::size_t t = 0; t < scene.targets.size(); ++t) {
      const auto& p = scene.targets[t];
      EXPECT_TRUE(sim->set_target(t, {p[0], p[1] + rise, p[2]}).ok());
    }
    EXPECT_TRUE(sim->step().ok());
  }
  return mean_y(positions(*sim), 0, n) - start;
}

TEST(BodyAttachments, PulledMembraneLiftsTheBlockItIsAttachedTo) {
  const double lift = lift_of_block(true), without = lift_of_block(false);
  EXPECT_GT(lift, 2e-3) << "the membrane lifts the block by 2 mm or more";
  EXPECT_LT(std::abs(without), 1e-3) << "without attachments the block stays on the plane";
  std::printf("[ measured ] membrane border raised 20 mm: the block rises %.3g mm attached, %.3g mm not\n",
              lift * 1e3, without * 1e3);
}

std::string error_of(const SceneDesc& scene) {
  const Status s = check_scene(scene);
  return s.ok() ? std::string("accepted") : s.error().message();
}

// Block B hung 5 mm below pinned block A, each vertex of B's top face
// attached to the A vertex 5 mm above it with that rest length: connective
// tissue bridging a gap. B hangs at the gap instead of being pulled shut,
// and A still carries B's weight.
TEST(BodyAttachments, ARestLengthHoldsTheGapBetweenTheBodies) {
  constexpr double kGap = 0.005;
  SceneDesc scene;
  scene.solver = solver();
  TetBodyDesc a = block(4, 2, 4, {0.0, 0.02, 0.0}, 5e3);
  a.pinned = at_height(a.mesh, 0.04);
  scene.tet_bodies.push_back(a);
  TetBodyDesc b = block(4, 2, 4, {0.0, -kGap, 0.0}, 5e3);
  for (std::uint32_t v : at_height(b.mesh, 0.02 - kGap)) {
    BodyAttachmentDesc link;
    const Vec3d above{b.mesh.vertices[v][0], 0.02, b.mesh.vertices[v][2]};
    link.a = {BodyKind::tet, 0, {vertex_at(a.mesh, above)}, {1.0}};
    link.b = {BodyKind::tet, 1, {v}, {1.0}};
    link.rest_length = kGap;
    scene.body_attachments.push_back(link);
  }
  scene.tet_bodies.push_back(b);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  for (int f = 0; f < 60; ++f) SINEW_ASSERT_OK(sim->step());
  const std::vector<float> x = positions(*sim);
  const std::size_t na = a.mesh.vertices.size();
  double lo = INFINITY, hi = 0.0;
  for (const BodyAttachmentDesc& l : scene.body_attachments) {
    const float* p = &x[4 * l.a.vertices[0]];
    const float* q = &x[4 * (na + l.b.vertices[0])];
    const double gap = std::hypot(double(p[0]) - q[0], double(p[1]) - q[1], double(p[2]) - q[2]);
    lo = std::min(lo, gap);
    hi = std::max(hi, gap);
  }
  std::printf("[ measured ] rest length %.1f mm: the attached points %.4f to %.4f mm apart after 1 s\n", kGap * 1e3,
              lo * 1e3, hi * 1e3);
  EXPECT_NEAR(lo, kGap, 1e-4);
  EXPECT_NEAR(hi, kGap, 1e-4);
  double drop_b = 0.0;
  const std::size_t nb = b.mesh.vertices.size();
  for (std::size_t v = 0; v < nb; ++v) drop_b += (b.mesh.vertices[v][1] - x[4 * (na + v) + 1]) / double(nb);
  EXPECT_GT(drop_b, 0.0);
  EXPECT_LT(drop_b, 5e-3) << "B hangs from A at the gap";
}

TEST(BodyAttachments, BadInputNamesTheField) {
  const SceneDesc good = hanging_blocks(true);
  ASSERT_EQ(error_of(good), "accepted");
  const auto spoiled = [&](auto&& spoil) {
    SceneDesc s = good;
    spoil(s.body_attachments[0]);
    return error_of(s);
  };
  const auto has = [](const std::string& message, const std::string& what) {
    return message.find(what) != std::string::npos;
  };
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.a.weights = {0.5}; }), "body_attachments[0].a.weights");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.b.weights = {NAN}; }), "body_attachments[0].b.weights[0]");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.b.weights = {0.5, 0.5}; }), "body_attachments[0].b.weights");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.a.vertices = {}; a.a.weights = {}; }),
               "body_attachments[0].a.vertices");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.a.vertices = {0, 1, 2, 3, 4}; a.a.weights = {0.2, 0.2, 0.2, 0.2, 0.2}; }),
               "body_attachments[0].a.vertices");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.a.vertices = {7, 7}; a.a.weights = {0.5, 0.5}; }),
               "body_attachments[0].a.vertices[1]");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.b.vertices = {100000}; }), "body_attachments[0].b.vertices[0]");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.b.body = 5; }), "body_attachments[0].b.body");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.b.body_kind = BodyKind::tri; }), "body_attachments[0].b.body");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.compliance = -1.0; }), "body_attachments[0].compliance");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.break_force = 0.0; }), "body_attachments[0].break_force");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.break_force = NAN; }), "body_attachments[0].break_force");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.break_force = 1e300; }), "body_attachments[0].break_force");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.b = a.a; }), "body_attachments[0]: vertex");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.rest_length = -1e-3; }), "body_attachments[0].rest_length");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.rest_length = NAN; }), "body_attachments[0].rest_length");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.rest_length = 1e300; }), "body_attachments[0].rest_length");
  EXPECT_PRED2(has, spoiled([](BodyAttachmentDesc& a) { a.rest_length = 1e-300; }), "body_attachments[0].rest_length");
  // And the Simulation refuses it the same way (nothing crashes).
  SceneDesc s = good;
  s.body_attachments[0].a.weights = {2.0};
  auto sim = Simulation::create(s, {.backend = "cpu", .quiet = true});
  ASSERT_FALSE(sim.ok());
  EXPECT_PRED2(has, sim.error().message(), "body_attachments[0].a.weights");
}

}  // namespace
}  // namespace sinew::test
