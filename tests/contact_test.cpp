// Contacts with analytic colliders, friction, attachments and tools, against
// physics on every built backend:
//  - a particle or a block dropped on a plane, sphere, capsule, box,
//    cylinder or implicit CSG shape comes to rest on it without sinking in;
//    the CPU kernel's implicit shapes match a double-precision oracle;
//  - a block on an incline sticks while tan(theta) < mu_s and otherwise
//    slides with the acceleration g (sin(theta) - mu_k cos(theta));
//  - a contact of compliance alpha under a resting weight m g gives way by
//    alpha m g (converged xPBD);
//  - a collider moved with set_collider_pose pushes particles out of its way
//    and carries what rests on it by friction, sliding or turning;
//  - attachments follow their targets; with compliance alpha the vertex
//    hangs alpha * (supported weight) below its target;
//  - a heavy tool rests on soft tissue without tunnelling or gaining energy,
//    and a pushed tool feels the tissue push back with the applied force;
//    the coupling gives bitwise the same result on any thread count;
//  - bad indices, non-finite values and non-unit quaternions are errors
//    naming the parameter.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "contact_params.h"
#include "cpu/contact_kernels.h"
#include "implicit_oracle.h"
#include "runtime/simulation_internals.h"
#include "test_support.h"

namespace sinew {
namespace {

constexpr double kG = 9.81;
constexpr double kPi = 3.14159265358979323846;

class Contact : public test::BackendTest {};

// Creates `sim` on the test's backend; fails on any error (a backend without
// the contact kernels included).
#define CONTACT_SIMULATION(sim, scene)                                  \
  auto sim##_made = test::create_or_skip(scene, GetParam());            \
  ASSERT_TRUE(sim##_made.ok()) << sim##_made.error().message();         \
  Simulation& sim = *sim##_made

using V3 = std::array<double, 3>;
using Q4 = std::array<double, 4>;

std::vector<float> positions(const Simulation& sim) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  return x;
}

V3 particle(const std::vector<float>& x, std::size_t p) { return {x[4 * p], x[4 * p + 1], x[4 * p + 2]}; }

// Rotation by `angle` about the unit axis a, as (w, x, y, z).
Q4 axis_angle(const V3& a, double angle) {
  const double s = std::sin(angle / 2);
  return {std::cos(angle / 2), a[0] * s, a[1] * s, a[2] * s};
}

V3 rotate(const Q4& q, const V3& v) {
  const V3 u{q[1], q[2], q[3]};
  auto cross = [](const V3& a, const V3& b) {
    return V3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  V3 t = cross(u, v);
  for (double& c : t) c *= 2;
  const V3 ut = cross(u, t);
  return {v[0] + q[0] * t[0] + ut[0], v[1] + q[0] * t[1] + ut[1], v[2] + q[0] * t[2] + ut[2]};
}

double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// A block of nx x ny x nz cells of edge `cell` [m], its bottom face centred at the
// origin, then rotated by q and moved to `at`.
TetBodyDesc block(int nx, int ny, int nz, double cell, const V3& at, const Q4& q = {1, 0, 0, 0}) {
  TetBodyDesc body;
  body.mesh = test::box_mesh(nx, ny, nz, cell);
  for (Vec3d& v : body.mesh.vertices) {
    const V3 local{v[0] - nx * cell / 2, v[1], v[2] - nz * cell / 2};
    const V3 r = rotate(q, local);
    v = {r[0] + at[0], r[1] + at[1], r[2] + at[2]};
  }
  body.distance_compliance = 1.0 / 1e6;  // E = 1 MPa
  body.volume_compliance = 1.0 / 1e6;
  return body;
}

LineBodyDesc one_particle(const V3& at, double mass) {
  LineBodyDesc p;
  p.vertices = {at};
  p.masses = {mass};
  return p;
}

V3 centroid(const std::vector<float>& x, std::size_t first, std::size_t count) {
  V3 c{0, 0, 0};
  for (std::size_t p = first; p < first + count; ++p)
    for (int k = 0; k < 3; ++k) c[k] += x[4 * p + k];
  for (double& v : c) v /= double(count);
  return c;
}

// ------------------------------------------------------------ resting on colliders

// Signed distance [m] of world point p to a collider (double precision).
double signed_distance(const ColliderDesc& c, const V3& p) {
  const Q4 inverse{c.rotation[0], -c.rotation[1], -c.rotation[2], -c.rotation[3]};
  const V3 l = rotate(inverse, {p[0] - c.position[0], p[1] - c.position[1], p[2] - c.position[2]});
  if (c.shape == ColliderShape::implicit) return test::oracle_implicit(c.implicit, l);
  // The analytic shapes as the oracle's primitives (tests/implicit_oracle.h).
  ImplicitNode shape;
  shape.op = c.shape == ColliderShape::plane     ? ImplicitOp::half_space
             : c.shape == ColliderShape::sphere  ? ImplicitOp::sphere
             : c.shape == ColliderShape::capsule ? ImplicitOp::capsule
             : c.shape == ColliderShape::box     ? ImplicitOp::box
                                                 : ImplicitOp::cylinder;
  shape.radius = c.radius;
  shape.half_height = c.half_height;
  shape.half_extents = c.half_extents;
  return test::oracle_primitive(shape, l);
}

ImplicitNode primitive(ImplicitOp op, const V3& at, const Q4& q = {1, 0, 0, 0}) {
  ImplicitNode n;
  n.op = op;
  n.position = at;
  n.rotation = q;
  return n;
}

ImplicitNode operation(ImplicitOp op) { return primitive(op, {0, 0, 0}); }

// Implicit shapes whose top at x = z = 0 is at y = 0 with a level normal there.
ColliderDesc implicit_collider(std::vector<ImplicitNode> nodes, const V3& at = {0, 0, 0}, const Q4& q = {1, 0, 0, 0}) {
  ColliderDesc c;
  c.shape = ColliderShape::implicit;
  c.implicit = std::move(nodes);
  c.position = at;
  c.rotation = q;
  return c;
}

// A slab (box, top at y = 0.02 in its frame) with a spherical bite whose
// bottom is at y = 0: subtract; a particle rests at the bite's bottom.
ColliderDesc bitten_slab() {
  ImplicitNode slab = primitive(ImplicitOp::box, {0, 0, 0}, axis_angle({0, 1, 0}, 0.5));
  slab.half_extents = {0.1, 0.02, 0.08};
  ImplicitNode bite = primitive(ImplicitOp::sphere, {0, 0.03, 0});
  bite.radius = 0.03;
  return implicit_collider({slab, bite, operation(ImplicitOp::subtract)}, {0, -0.0, 0});
}

// A torus ring (its tube's top at y = 0.01) around a sphere whose top is at
// y = 0, turned about y: unite, torus; the particle lands on the sphere.
ColliderDesc ringed_ball() {
  ImplicitNode ring = primitive(ImplicitOp::torus, {0, 0, 0});
  ring.radius = 0.05;
  ring.minor_radius = 0.01;
  ImplicitNode ball = primitive(ImplicitOp::sphere, {0, -0.02, 0});
  ball.radius = 0.02;
  return implicit_collider({ring, ball, operation(ImplicitOp::unite)}, {0, 0, 0}, axis_angle({0, 1, 0}, 0.7));
}

// A rounded capsule lying along x cut flat at y = 0 by a tilted-frame
// half-space (a rotation about y keeps it level): intersect, rounding.
ColliderDesc cut_capsule() {
  ImplicitNode rod = primitive(ImplicitOp::capsule, {0, -0.01, 0}, axis_angle({0, 0, 1}, kPi / 2));
  rod.radius = 0.025;
  rod.half_height = 0.05;
  rod.rounding = 0.005;
  ImplicitNode cut = primitive(ImplicitOp::half_space, {0, 0, 0}, axis_angle({0, 1, 0}, 1.1));
  return implicit_collider({rod, cut, operation(ImplicitOp::intersect)}, {0, 0, 0});
}

struct ShapeCase {
  const char* name;
  ColliderDesc collider;
  double top;  // height of the collider's top at x = z = 0 [m]
};

std::vector<ShapeCase> shape_cases() {
  ColliderDesc plane;  // y = 0
  ColliderDesc sphere;
  sphere.shape = ColliderShape::sphere;
  sphere.radius = 0.05;
  sphere.position = {0, -0.05, 0};
  ColliderDesc capsule;  // lying along x, top at y = 0
  capsule.shape = ColliderShape::capsule;
  capsule.radius = 0.03;
  capsule.half_height = 0.05;
  capsule.position = {0, -0.03, 0};
  capsule.rotation = axis_angle({0, 0, 1}, kPi / 2);
  ColliderDesc box;  // tilted about y, which keeps its top face level
  box.shape = ColliderShape::box;
  box.half_extents = {0.1, 0.02, 0.08};
  box.position = {0, -0.02, 0};
  box.rotation = axis_angle({0, 1, 0}, 0.3);
  ColliderDesc standing;  // a cylinder on its cap, tilted about y (its top stays level)
  standing.shape = ColliderShape::cylinder;
  standing.radius = 0.05;
  standing.half_height = 0.03;
  standing.position = {0, -0.03, 0};
  standing.rotation = axis_angle({0, 1, 0}, 0.4);
  ColliderDesc lying = standing;  // on its side, along x: a curved top at y = 0
  lying.position = {0, -0.05, 0};
  lying.rotation = axis_angle({0, 0, 1}, kPi / 2);
  return {{"plane", plane, 0.0},
          {"sphere", sphere, 0.0},
          {"capsule", capsule, 0.0},
          {"box", box, 0.0},
          {"cylinder on its cap", standing, 0.0},
          {"cylinder on its side", lying, 0.0},
          {"implicit: slab with a spherical bite (subtract)", bitten_slab(), 0.0},
          {"implicit: ball in a torus ring (unite)", ringed_ball(), 0.0},
          {"implicit: rounded capsule cut flat (intersect)", cut_capsule(), 0.0}};
}

// The CPU reference kernel's implicit shapes (kernels/cpu/contact_kernels.cpp)
// against the double-precision oracle (implicit_oracle.h) at 20,000 random
// points around a shape with every primitive (turned in their own frames,
// some rounded) and every operation: distances within 1e-6 m (float on a
// 0.3 m shape), and where the oracle's central-difference gradient is a
// unit vector (away from ties between primitives, edges and medial axes)
// the kernel's normal along it within 0.5 degrees. The GPU kernels equal
// this one bitwise (Agreement.ContactKernel).
TEST(ImplicitShape, CpuKernelMatchesTheDoublePrecisionOracle) {
  std::vector<ImplicitNode> nodes;
  ImplicitNode n = primitive(ImplicitOp::box, {0.0, 0.0, 0.0}, axis_angle({0.6, 0.8, 0.0}, 0.4));
  n.half_extents = {0.25, 0.15, 0.2};
  n.rounding = 0.02;
  nodes.push_back(n);
  n = primitive(ImplicitOp::sphere, {0.1, 0.15, 0.0});
  n.radius = 0.12;
  nodes.push_back(n);
  nodes.push_back(operation(ImplicitOp::subtract));
  n = primitive(ImplicitOp::torus, {0.0, -0.1, 0.0}, axis_angle({1.0, 0.0, 0.0}, 0.3));
  n.radius = 0.2;
  n.minor_radius = 0.05;
  nodes.push_back(n);
  nodes.push_back(operation(ImplicitOp::unite));
  n = primitive(ImplicitOp::capsule, {-0.15, 0.1, 0.1}, axis_angle({0.0, 0.0, 1.0}, 1.0));
  n.radius = 0.06;
  n.half_height = 0.15;
  nodes.push_back(n);
  n = primitive(ImplicitOp::cylinder, {0.15, -0.05, -0.1}, axis_angle({0.0, 0.6, 0.8}, 0.9));
  n.radius = 0.1;
  n.half_height = 0.08;
  n.rounding = 0.01;
  nodes.push_back(n);
  nodes.push_back(operation(ImplicitOp::unite));
  nodes.push_back(operation(ImplicitOp::unite));
  nodes.push_back(primitive(ImplicitOp::half_space, {0.0, 0.12, 0.0}, axis_angle({0.8, 0.0, 0.6}, 0.2)));
  nodes.push_back(operation(ImplicitOp::intersect));

  // The kernel's nodes, field by field (what compile_contacts.cpp writes).
  std::vector<kernels::ImplicitEntry> entries;
  for (const ImplicitNode& m : nodes) {
    kernels::ImplicitEntry e{};
    e.op = static_cast<std::uint32_t>(m.op);  // ImplicitOp's order is SINEW_IMPLICIT_*'s
    e.radius = float(m.radius), e.half_height = float(m.half_height), e.rounding = float(m.rounding);
    e.half_x = float(m.half_extents[0]), e.half_y = float(m.half_extents[1]), e.half_z = float(m.half_extents[2]);
    e.minor_radius = float(m.minor_radius);
    e.px = float(m.position[0]), e.py = float(m.position[1]), e.pz = float(m.position[2]);
    e.qw = float(m.rotation[0]), e.qx = float(m.rotation[1]), e.qy = float(m.rotation[2]), e.qz = float(m.rotation[3]);
    entries.push_back(e);
  }
  static_assert(SINEW_IMPLICIT_SUBTRACT == static_cast<std::uint32_t>(ImplicitOp::subtract));

  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.4f, 0.4f);
  double worst = 0.0, worst_angle = 0.0;
  int smooth = 0, inside = 0;
  constexpr int samples = 20000;
  for (int i = 0; i < samples; ++i) {
    const kernels::float4 p{u(rng), u(rng), u(rng), 0.0f};
    const V3 pd{p.x, p.y, p.z};
    const kernels::SignedDistance sd = kernels::implicit_distance(entries.data(), std::uint32_t(entries.size()), p);
    const double d = test::oracle_implicit(nodes, pd);
    worst = std::max(worst, std::abs(sd.distance - d));
    inside += d < 0;
    constexpr double h = 1e-6;
    V3 g;
    for (int k = 0; k < 3; ++k) {
      V3 a = pd, b = pd;
      a[k] += h, b[k] -= h;
      g[k] = (test::oracle_implicit(nodes, a) - test::oracle_implicit(nodes, b)) / (2 * h);
    }
    const double len = std::hypot(g[0], g[1], g[2]);
    if (std::abs(len - 1.0) > 1e-4) continue;
    ++smooth;
    const double c = (g[0] * sd.normal.x + g[1] * sd.normal.y + g[2] * sd.normal.z) / len;
    worst_angle = std::max(worst_angle, std::acos(std::clamp(c, -1.0, 1.0)));
  }
  std::printf("[ measured ] implicit: largest distance error %.3g m, largest normal error %.3g deg at %d smooth "
              "points of %d (%d inside)\n", worst, worst_angle * 180 / kPi, smooth, samples, inside);
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(worst_angle * 180 / kPi, 0.5);
  EXPECT_GT(smooth, samples / 2);
  EXPECT_GT(inside, samples / 20);
}

TEST_P(Contact, ParticleDroppedOnEachColliderComesToRestOnIt) {
  // A particle dropped from 5 cm lands on the top of each shape (where the
  // normal is vertical) and stays there: after every frame its signed
  // distance is above -1e-6 m, and at the end it rests within 1e-5 m of the
  // surface with no speed left.
  for (const ShapeCase& c : shape_cases()) {
    SCOPED_TRACE(c.name);
    SceneDesc scene;
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 2};
    scene.line_bodies.push_back(one_particle({0.0, c.top + 0.05, 0.0}, 0.01));
    scene.colliders.push_back(c.collider);
    CONTACT_SIMULATION(sim, scene);
    double lowest = 1.0;
    for (int f = 0; f < 90; ++f) {
      SINEW_ASSERT_OK(sim.step());
      lowest = std::min(lowest, signed_distance(c.collider, particle(positions(sim), 0)));
    }
    const double d = signed_distance(c.collider, particle(positions(sim), 0));
    std::vector<float> v;
    SINEW_ASSERT_OK(sim.read_velocities(v));
    EXPECT_GT(lowest, -1e-6) << "deepest penetration over the run";
    EXPECT_NEAR(d, 0.0, 1e-5) << "at rest on the surface";
    EXPECT_LT(std::hypot(v[0], v[1], v[2]), 1e-3);
    std::printf("[ measured ] particle on the %s: deepest %.3g m, rests at %.3g m, speed %.3g m/s\n", c.name, lowest, d,
                std::hypot(v[0], v[1], v[2]));
  }
}

TEST_P(Contact, BlockDroppedOnPlaneAndBoxComesToRest) {
  // A 2 cm tet block dropped from 2 cm lands flat on a plane, on the
  // (level) top face of a box collider and on a standing cylinder's cap: every vertex ends within 1e-5 m of
  // the surface, none below -1e-5 m at any frame, and the block is at rest.
  for (const ShapeCase& c : shape_cases()) {
    const bool flat_top = c.collider.shape == ColliderShape::plane || c.collider.shape == ColliderShape::box ||
                          (c.collider.shape == ColliderShape::cylinder && c.collider.position[1] == -c.collider.half_height);
    if (!flat_top) continue;
    SCOPED_TRACE(c.name);
    SceneDesc scene;
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 4};
    scene.tet_bodies.push_back(block(2, 2, 2, 0.01, {0.0, c.top + 0.02, 0.0}));
    scene.colliders.push_back(c.collider);
    CONTACT_SIMULATION(sim, scene);
    const std::size_t n = scene.tet_bodies[0].mesh.vertices.size();
    double lowest = 1.0;
    for (int f = 0; f < 90; ++f) {
      SINEW_ASSERT_OK(sim.step());
      const std::vector<float> x = positions(sim);
      for (std::size_t p = 0; p < n; ++p) lowest = std::min(lowest, signed_distance(c.collider, particle(x, p)));
    }
    const std::vector<float> x = positions(sim);
    double bottom = 1.0;
    for (std::size_t p = 0; p < n; ++p) bottom = std::min(bottom, signed_distance(c.collider, particle(x, p)));
    EXPECT_GT(lowest, -1e-5);
    EXPECT_NEAR(bottom, 0.0, 1e-5);
    EXPECT_LT(sim.last_frame().kinetic_energy, 1e-8);
    std::printf("[ measured ] block on the %s: deepest %.3g m, lowest vertex at rest %.3g m, kinetic energy %.3g J\n",
                c.name, lowest, bottom, sim.last_frame().kinetic_energy);
  }
}

// ------------------------------------------------------------ friction

struct InclineRun {
  double start_slide = 0;  // downhill displacement of the centroid from frame 10 to frame 70 [m]
  double acceleration = 0; // downhill, from the velocity change over frames 30..90 [m/s^2]
};

// A 2 cm block resting on a plane tilted by theta about z, for 1.5 s.
InclineRun incline(const std::string& backend, double theta, double mu_s, double mu_k) {
  const Q4 q = axis_angle({0, 0, 1}, theta);
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 8, .iterations = 2};
  TetBodyDesc body = block(2, 2, 2, 0.01, {0, 0, 0}, q);
  scene.tet_bodies.push_back(body);
  ColliderDesc plane;
  plane.rotation = q;
  plane.static_friction = mu_s;
  plane.dynamic_friction = mu_k;
  scene.colliders.push_back(plane);
  auto sim = test::create_or_skip(scene, backend);
  InclineRun run;
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  if (!sim.ok()) return run;
  const V3 downhill = rotate(q, {-1, 0, 0});
  const std::size_t n = body.mesh.vertices.size();
  auto along = [&] { return dot(centroid(positions(*sim), 0, n), downhill); };
  auto speed = [&] {
    std::vector<float> v;
    EXPECT_TRUE(sim->read_velocities(v).ok());
    return dot(centroid(v, 0, n), downhill);
  };
  double s10 = 0, v30 = 0;
  for (int f = 1; f <= 90; ++f) {
    EXPECT_TRUE(sim->step().ok());
    if (f == 10) s10 = along();
    if (f == 70) run.start_slide = along() - s10;
    if (f == 30) v30 = speed();
  }
  run.acceleration = (speed() - v30) / (60.0 / 60.0);
  return run;
}

TEST_P(Contact, FrictionHoldsABlockBelowTheFrictionAngleAndLetsItSlideAbove) {
  // Coulomb: a block on an incline sticks while tan(theta) <= mu_s and then
  // slides with a = g (sin(theta) - mu_k cos(theta)). Sticking: it moves less
  // than 20 um in a second (after the first frames settle the contact);
  // sliding: its acceleration is within 5% of Coulomb's.
  struct Case {
    double tan_theta, mu_s, mu_k;
  };
  for (const Case c : {Case{0.45, 0.5, 0.5}, Case{0.55, 0.5, 0.5}, Case{0.3, 0.5, 0.4}, Case{0.8, 0.5, 0.4}}) {
    SCOPED_TRACE("tan(theta) = " + std::to_string(c.tan_theta) + ", mu_s = " + std::to_string(c.mu_s) +
                 ", mu_k = " + std::to_string(c.mu_k));
    const double theta = std::atan(c.tan_theta);
    const InclineRun run = incline(GetParam(), theta, c.mu_s, c.mu_k);
    if (c.tan_theta < c.mu_s) {
      EXPECT_LT(std::abs(run.start_slide), 2e-5) << "should stick";
      std::printf("[ measured ] tan(theta) %.2f, mu_s %.2f: moved %.3g m in 1 s\n", c.tan_theta, c.mu_s,
                  run.start_slide);
    } else {
      const double expected = kG * (std::sin(theta) - c.mu_k * std::cos(theta));
      EXPECT_NEAR(run.acceleration, expected, 0.05 * expected) << "should slide as Coulomb says";
      std::printf("[ measured ] tan(theta) %.2f, mu_k %.2f: acceleration %.4g m/s^2, Coulomb %.4g\n", c.tan_theta,
                  c.mu_k, run.acceleration, expected);
    }
  }
}

// ------------------------------------------------------------ compliance

TEST_P(Contact, CompliantContactGivesWayByAlphaTimesTheWeight) {
  // One particle of mass m resting on a plane of compliance alpha: at rest
  // the converged xPBD contact holds C + alpha~ lambda = 0 with the weight's
  // lambda = m g h^2, so it sinks alpha m g (about 1 mm here), within 1%.
  const double m = 0.01, alpha = 0.01;
  for (const double y0 : {0.0, 0.02}) {
    SceneDesc scene;
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 1};
    scene.line_bodies.push_back(one_particle({0, y0, 0}, m));
    ColliderDesc plane;
    plane.compliance = alpha;
    scene.colliders.push_back(plane);
    CONTACT_SIMULATION(sim, scene);
    for (int f = 0; f < 120; ++f) SINEW_ASSERT_OK(sim.step());
    EXPECT_NEAR(-positions(sim)[1], alpha * m * kG, 0.01 * alpha * m * kG) << "dropped from " << y0 << " m";
    std::printf("[ measured ] compliant contact: sinks %.5g m, alpha m g = %.5g m\n", -positions(sim)[1],
                alpha * m * kG);
  }
}

// ------------------------------------------------------------ kinematic colliders

TEST_P(Contact, MovingColliderPushesParticlesAndCarriesThemByFriction) {
  // (1) A wall (box collider) moved 3 cm along +x in half a second into a
  // block resting on a frictionless floor pushes it: at no frame is a
  // vertex behind the wall's face (beyond 10 um), and the block leaves with
  // between the wall's speed (pushed along) and twice it (an elastic bounce
  // off the moving wall, which acts as infinitely heavy).
  // (2) A block resting on a platform (box) that slides 5 cm along +z is
  // carried along by static friction: it moves with the platform to 0.1 mm.
  // (3) below: a turntable.
  {
    SceneDesc scene;
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 4};
    scene.tet_bodies.push_back(block(2, 2, 2, 0.01, {0, 0, 0}));
    ColliderDesc floor;
    floor.static_friction = floor.dynamic_friction = 0.0;
    scene.colliders.push_back(floor);
    ColliderDesc wall;
    wall.shape = ColliderShape::box;
    wall.half_extents = {0.01, 0.03, 0.03};
    wall.position = {-0.02, 0.02, 0};  // its +x face at x = -0.01, where the block starts
    wall.static_friction = wall.dynamic_friction = 0.0;
    scene.colliders.push_back(wall);
    CONTACT_SIMULATION(sim, scene);
    const std::size_t n = scene.tet_bodies[0].mesh.vertices.size();
    for (int f = 1; f <= 30; ++f) {
      SINEW_ASSERT_OK(sim.set_collider_pose(1, {-0.02 + 0.001 * f, 0.02, 0}, {1, 0, 0, 0}));
      SINEW_ASSERT_OK(sim.step());
      const std::vector<float> x = positions(sim);
      const double face = -0.01 + 0.001 * f;
      for (std::size_t p = 0; p < n; ++p) ASSERT_GT(x[4 * p], face - 1e-5) << "vertex " << p << ", frame " << f;
    }
    std::vector<float> v;
    SINEW_ASSERT_OK(sim.read_velocities(v));
    const double speed = centroid(v, 0, n)[0], wall_speed = 0.001 * 60;
    EXPECT_GT(speed, 0.9 * wall_speed) << "the block moves at least as fast as the wall pushed it";
    EXPECT_LT(speed, 2.1 * wall_speed) << "and at most bounced off it elastically";
    std::printf("[ measured ] wall at %.3g m/s: the block leaves at %.3g m/s\n", wall_speed, speed);
  }
  {
    SceneDesc scene;
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 8, .iterations = 2};
    scene.tet_bodies.push_back(block(2, 2, 2, 0.01, {0, 0, 0}));
    ColliderDesc platform;
    platform.shape = ColliderShape::box;
    platform.half_extents = {0.05, 0.01, 0.05};
    platform.position = {0, -0.01, 0};
    platform.static_friction = 0.8;
    platform.dynamic_friction = 0.7;
    scene.colliders.push_back(platform);
    CONTACT_SIMULATION(sim, scene);
    const std::size_t n = scene.tet_bodies[0].mesh.vertices.size();
    for (int f = 0; f < 10; ++f) SINEW_ASSERT_OK(sim.step());  // settle
    const V3 start = centroid(positions(sim), 0, n);
    // 5 cm in 1 s, starting and stopping gently (smoothstep) so that the
    // acceleration, at most 0.15 m/s^2, stays far inside the friction cone.
    const int frames = 60;
    for (int f = 1; f <= frames + 20; ++f) {
      const double s = std::min(1.0, double(f) / frames);
      const double z = 0.05 * s * s * (3 - 2 * s);
      SINEW_ASSERT_OK(sim.set_collider_pose(0, {0, -0.01, z}, {1, 0, 0, 0}));
      SINEW_ASSERT_OK(sim.step());
    }
    const V3 end = centroid(positions(sim), 0, n);
    EXPECT_NEAR(end[2] - start[2], 0.05, 1e-4) << "carried by the platform";
    EXPECT_NEAR(end[0] - start[0], 0.0, 1e-5);
    std::printf("[ measured ] platform moved 0.05 m: the block %.6g m\n", end[2] - start[2]);
  }
  {
    // (3) A turntable (box) turned a quarter turn about y in a second
    // carries a block resting 3 cm off its axis round with it: the rotation
    // is interpolated across the substeps and friction follows the surface.
    SceneDesc scene;
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 8, .iterations = 2};
    scene.tet_bodies.push_back(block(2, 2, 2, 0.01, {0.03, 0, 0}));
    ColliderDesc table;
    table.shape = ColliderShape::box;
    table.half_extents = {0.08, 0.01, 0.08};
    table.position = {0, -0.01, 0};
    table.static_friction = 0.8;
    table.dynamic_friction = 0.7;
    scene.colliders.push_back(table);
    CONTACT_SIMULATION(sim, scene);
    const std::size_t n = scene.tet_bodies[0].mesh.vertices.size();
    for (int f = 0; f < 10; ++f) SINEW_ASSERT_OK(sim.step());  // settle
    const V3 start = centroid(positions(sim), 0, n);
    const int frames = 60;
    for (int f = 1; f <= frames + 20; ++f) {
      const double s = std::min(1.0, double(f) / frames);
      SINEW_ASSERT_OK(sim.set_collider_pose(0, {0, -0.01, 0}, axis_angle({0, 1, 0}, kPi / 2 * s * s * (3 - 2 * s))));
      SINEW_ASSERT_OK(sim.step());
    }
    const V3 end = centroid(positions(sim), 0, n);
    const V3 expected = rotate(axis_angle({0, 1, 0}, kPi / 2), start);  // (x, y, z) -> (z, y, -x)
    EXPECT_LT(std::hypot(end[0] - expected[0], end[1] - expected[1], end[2] - expected[2]), 2e-4)
        << "carried round: (" << end[0] << ", " << end[1] << ", " << end[2] << ")";
    std::printf("[ measured ] turntable a quarter turn: the block is %.3g m from where the turn takes it\n",
                std::hypot(end[0] - expected[0], end[1] - expected[1], end[2] - expected[2]));
  }
}

// ------------------------------------------------------------ attachments

TEST_P(Contact, AttachedVertexFollowsItsTarget) {
  // Compliance 0: after every frame the vertex is on its target (float
  // rounding), while the target goes round a circle and gravity pulls.
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 2, .iterations = 2};
  scene.line_bodies.push_back(one_particle({0.1, 0, 0}, 0.05));
  scene.targets = {{0.1, 0, 0}};
  scene.attachments.push_back({.vertex = {.body_kind = BodyKind::line, .body = 0, .vertex = 0}, .target = 0});
  CONTACT_SIMULATION(sim, scene);
  for (int f = 1; f <= 60; ++f) {
    const V3 t{0.1 * std::cos(0.1 * f), 0.1 * std::sin(0.1 * f), 0.02 * f / 60.0};
    SINEW_ASSERT_OK(sim.set_target(0, t));
    SINEW_ASSERT_OK(sim.step());
    const V3 x = particle(positions(sim), 0);
    ASSERT_NEAR(std::hypot(x[0] - t[0], x[1] - t[1], x[2] - t[2]), 0.0, 1e-6) << "frame " << f;
  }
}

TEST_P(Contact, BodyHangsFromTwoAttachedVertices) {
  // A 1 x 4 x 1 cell bar hangs from its two top corners on one edge, held
  // by rigid attachments at their start positions: those vertices stay on
  // their targets, the bar does not fall, and after its sway dies down it
  // hangs still, lower than it started.
  const double cell = 0.01;
  TetBodyDesc bar = block(1, 4, 1, cell, {0, -4 * cell, 0});
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 8, .iterations = 2};
  std::vector<std::uint32_t> top;
  for (std::uint32_t v = 0; v < bar.mesh.vertices.size(); ++v)
    if (bar.mesh.vertices[v][1] > -1e-9 && bar.mesh.vertices[v][2] < 0) top.push_back(v);
  ASSERT_EQ(top.size(), 2u);
  for (std::uint32_t v : top) {
    scene.attachments.push_back({.vertex = {.body_kind = BodyKind::tet, .body = 0, .vertex = v},
                                 .target = static_cast<std::uint32_t>(scene.targets.size())});
    scene.targets.push_back(bar.mesh.vertices[v]);
  }
  scene.tet_bodies.push_back(bar);
  CONTACT_SIMULATION(sim, scene);
  const std::size_t n = bar.mesh.vertices.size();
  const double start = centroid(positions(sim), 0, n)[1];
  for (int f = 0; f < 240; ++f) SINEW_ASSERT_OK(sim.step());
  const std::vector<float> x = positions(sim);
  for (std::size_t k = 0; k < top.size(); ++k) {
    const V3 p = particle(x, top[k]);
    const V3& t = scene.targets[k];
    EXPECT_NEAR(std::hypot(p[0] - t[0], p[1] - t[1], p[2] - t[2]), 0.0, 1e-6);
  }
  const double y = centroid(x, 0, n)[1];
  EXPECT_LT(y, start) << "hangs lower than it started";
  EXPECT_GT(y, start - 2 * cell) << "but it is held up";
  EXPECT_LT(sim.last_frame().kinetic_energy, 1e-6) << "and has come to rest";
}

TEST_P(Contact, CompliantAttachmentHangsAlphaTimesTheSupportedWeightBelowItsTarget) {
  // A chain of three particles of mass m on rigid links hangs from its top
  // particle, attached with compliance alpha: at rest the top particle is
  // alpha * 3 m g below its target, within 1%. (One substep of many
  // iterations: converged implicit Euler, which damps the bouncing.)
  const double m = 0.02, alpha = 0.005;
  LineBodyDesc chain;
  chain.vertices = {{0, 0, 0}, {0, -0.05, 0}, {0, -0.1, 0}};
  chain.masses = {m, m, m};
  chain.segments = {{0, 1}, {1, 2}};
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 1, .iterations = 50};
  scene.line_bodies.push_back(chain);
  scene.targets = {{0, 0, 0}};
  scene.attachments.push_back({.vertex = {.body_kind = BodyKind::line}, .target = 0, .compliance = alpha});
  CONTACT_SIMULATION(sim, scene);
  for (int f = 0; f < 300; ++f) SINEW_ASSERT_OK(sim.step());
  const double expected = alpha * 3 * m * kG;
  EXPECT_NEAR(-positions(sim)[1], expected, 0.01 * expected);
  std::printf("[ measured ] compliant attachment: %.5g m below the target, alpha 3 m g = %.5g m\n",
              -positions(sim)[1], expected);
}

TEST_P(Contact, ParticleAttachedToTwoTargetsSettlesBetweenThem) {
  // Two attachments of equal compliance on one particle (so in two colours)
  // pull it to the midpoint of their targets; with compliances alpha and
  // 3 alpha it settles a quarter of the way from the stiffer one's target
  // (forces C_k / alpha_k balance).
  for (const double ratio : {1.0, 3.0}) {
    SceneDesc scene;
    scene.gravity = {0, 0, 0};
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 1, .iterations = 100};
    scene.line_bodies.push_back(one_particle({0, 0.05, 0}, 0.01));
    scene.targets = {{0, 0, 0}, {0.1, 0, 0}};
    scene.attachments.push_back({.vertex = {.body_kind = BodyKind::line}, .target = 0, .compliance = 1e-2});
    scene.attachments.push_back({.vertex = {.body_kind = BodyKind::line}, .target = 1, .compliance = ratio * 1e-2});
    CONTACT_SIMULATION(sim, scene);
    EXPECT_EQ(SimulationInternals::program(sim).dispatch_count(Kernel::xpbd_solve_attachment), 100u * 2u + 1u)
        << "two colours per iteration, plus the measuring pass";
    for (int f = 0; f < 120; ++f) SINEW_ASSERT_OK(sim.step());
    const V3 x = particle(positions(sim), 0);
    EXPECT_NEAR(x[0], 0.1 / (1 + ratio), 1e-5) << "compliance ratio " << ratio;
    EXPECT_NEAR(x[1], 0.0, 1e-5);
  }
}

// ------------------------------------------------------------ tools

// A soft block 6 x 2 x 6 cm (5 mm cells; edge network c_d = 1/(300 kPa), an
// effective E of ~75 kPa, docs/materials.md) pinned at its bottom,
// and a tool (radius 1 cm, 5 cm long) lying along z 1 mm above the middle
// of its top face, 10^4 times as heavy as the block's mean particle.
// 20 substeps: a tool M times as heavy as the N particles it rests on
// pushes them about (M / (N m)) g h^2 / iterations into the tissue per
// substep before the tissue's response reaches it; with much larger
// substeps it pushes the vertices apart and sinks between them.
SceneDesc tool_on_block(bool gravity) {
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 20, .iterations = 2};
  TetBodyDesc body = block(12, 4, 12, 0.005, {0, 0, 0});
  // The tissue these settings were tuned on: compliances set by hand
  // (c_d = 1/E, c_v = 3 (1 - 2 nu) / E at 300 kPa). With set_elastic(300
  // kPa, 0.3), 4x stiffer, the pushed tool of PushedToolFeelsTheTissue-
  // PushBack went through the block at 20 substeps x 2 iterations (at 40
  // x 2 and at set_elastic(75 kPa) too; at 20 x 8 it holds, 5.00 N): an
  // open problem of stiffer tissue under a heavy tool at few iterations,
  // not of what these tests check.
  body.distance_compliance = 1.0 / 3e5;
  body.volume_compliance = 3.0 * (1.0 - 2.0 * 0.3) / 3e5;
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] < 1e-9) body.pinned.push_back(v);
  const double block_mass = body.density * 0.06 * 0.02 * 0.06;
  const double particle_mass = block_mass / double(body.mesh.vertices.size());
  scene.tet_bodies.push_back(body);
  ToolDesc tool;
  tool.radius = 0.01;
  tool.half_height = 0.015;
  tool.mass = 1e4 * particle_mass;
  const double m = tool.mass, r2 = tool.radius * tool.radius, l2 = 4 * tool.half_height * tool.half_height;
  tool.inertia = {m * (3 * r2 + l2) / 12, m * r2 / 2, m * (3 * r2 + l2) / 12};  // a solid cylinder
  tool.position = {0, 0.02 + tool.radius + 0.001, 0};
  tool.rotation = axis_angle({1, 0, 0}, kPi / 2);  // its axis (y) along z
  tool.gravity = gravity;
  scene.tools.push_back(tool);
  return scene;
}

double norm(const V3& v) { return std::sqrt(dot(v, v)); }

// The least clearance [m] between a tool's capsule and a shape: the least
// signed distance over 1,001 points of its segment, less its radius.
double clearance(const ToolDesc& t, const Simulation::ToolState& s, const ColliderDesc& other) {
  double least = 1e9;
  for (int k = 0; k <= 1000; ++k) {
    const V3 axis = rotate(s.rotation, {0.0, t.half_height * (2.0 * k / 1000 - 1.0), 0.0});
    least = std::min(least, signed_distance(other, {s.position[0] + axis[0], s.position[1] + axis[1], s.position[2] + axis[2]}));
  }
  return least - t.radius;
}

ToolDesc falling_tool(const V3& at, const Q4& rotation) {
  ToolDesc tool;
  tool.radius = 0.005;
  tool.half_height = 0.04;
  tool.mass = 0.1;
  const double m = tool.mass, r2 = tool.radius * tool.radius, l2 = 4 * tool.half_height * tool.half_height;
  tool.inertia = {m * (3 * r2 + l2) / 12, m * r2 / 2, m * (3 * r2 + l2) / 12};  // a solid cylinder
  tool.position = at;
  tool.rotation = rotation;
  return tool;
}

// Shape against shape: a tool (a capsule 8 cm long, 1 cm thick, 100 g)
// dropped lying from 3 cm above the shape's top onto a plane, a turned box,
// a standing cylinder and two implicit shapes (a slab with a bite it
// bridges, a rounded capsule cut flat) comes to rest on it: at every frame
// its capsule is never more than 1 mm inside the shape (the oracle of
// 1,001 points along its axis), at the end it touches it within 1e-4 m and
// has stopped. Without the tool-collider contacts it falls through them.
TEST_P(Contact, ToolDroppedOnEachColliderComesToRestOnIt) {
  for (const ShapeCase& c : shape_cases()) {
    const std::string name = c.name;
    if (name == "sphere" || name == "capsule" || name == "cylinder on its side" ||
        name.find("torus") != std::string::npos)
      continue;  // a lying tool balances on a curved top only by symmetry
    SCOPED_TRACE(c.name);
    SceneDesc scene;
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 2};
    scene.colliders.push_back(c.collider);
    scene.tools.push_back(falling_tool({0.0, 0.05, 0.0}, axis_angle({0, 0, 1}, kPi / 2)));
    CONTACT_SIMULATION(sim, scene);
    double deepest = 1.0;
    Simulation::ToolState s;
    for (int f = 0; f < 120; ++f) {
      SINEW_ASSERT_OK(sim.step());
      auto state = sim.tool_state(0);
      SINEW_ASSERT_OK(state);
      s = *state;
      deepest = std::min(deepest, clearance(scene.tools[0], s, c.collider));
    }
    const double gap = clearance(scene.tools[0], s, c.collider);
    const double speed = std::hypot(s.velocity[0], s.velocity[1], s.velocity[2]);
    std::printf("[ measured ] tool on the %s: deepest %.3g m, rests %.3g m off it, speed %.3g m/s, centre at %.4f m\n",
                c.name, deepest, gap, speed, s.position[1]);
    EXPECT_GT(deepest, -1e-3);
    EXPECT_NEAR(gap, 0.0, 1e-4);
    EXPECT_LT(speed, 1e-2);
  }
}

// A tool's capsule as a collider shape at the tool's pose (for the oracle).
ColliderDesc tool_capsule(const ToolDesc& t, const Simulation::ToolState& s) {
  ColliderDesc c;
  c.shape = ColliderShape::capsule;
  c.radius = t.radius;
  c.half_height = t.half_height;
  c.position = s.position;
  c.rotation = s.rotation;
  return c;
}

// Tool against tool: two tools lie side by side on the floor along z, 3 cm
// apart; the light one (100 g) is pushed against the heavy one (10 kg) with
// 0.5 N for a second, then let go. It rolls over and stays against it:
// their capsules touch within 1e-4 m at the end and never overlap by more
// than 0.1 mm, and the push passes on (the heavy one rolls away: capsules
// roll without resistance). Without tool-tool contacts the light one rolls
// through it.
TEST_P(Contact, ToolPushedAgainstAnotherStopsAtIt) {
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 2};
  scene.colliders.push_back(ColliderDesc{});  // the floor
  const Q4 along_z = axis_angle({1, 0, 0}, kPi / 2);
  scene.tools.push_back(falling_tool({0.0, 0.005, 0.0}, along_z));
  scene.tools[0].mass = 10.0;
  for (auto& i : scene.tools[0].inertia) i *= 100.0;
  scene.tools.push_back(falling_tool({0.04, 0.005, 0.0}, along_z));
  CONTACT_SIMULATION(sim, scene);
  double deepest = 1.0;
  Simulation::ToolState heavy, light;
  for (int f = 0; f < 90; ++f) {
    if (f < 60) SINEW_ASSERT_OK(sim.apply_tool_force(1, {-0.5, 0.0, 0.0}, {0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim.step());
    auto a = sim.tool_state(0), b = sim.tool_state(1);
    SINEW_ASSERT_OK(a);
    SINEW_ASSERT_OK(b);
    heavy = *a, light = *b;
    deepest = std::min(deepest, clearance(scene.tools[1], light, tool_capsule(scene.tools[0], heavy)));
  }
  const double gap = clearance(scene.tools[1], light, tool_capsule(scene.tools[0], heavy));
  std::printf("[ measured ] tool pushed against a tool: deepest %.3g m, ends %.3g m off it, the heavy one moved %.3g m, "
              "the light one's x %.4f m\n", deepest, gap, std::abs(heavy.position[0]), light.position[0]);
  EXPECT_GT(deepest, -1e-4);
  EXPECT_NEAR(gap, 0.0, 1e-4);
  EXPECT_GT(light.position[0], heavy.position[0]);  // still on its own side
  EXPECT_LT(heavy.position[0], -1e-3);              // and the push passed on: the heavy one rolls away
}

TEST_P(Contact, HeavyToolRestsOnSoftTissue) {
  // Dropped from 1 mm, the tool is held up: its lowest point never goes
  // into the block's bottom layer of cells (no tunnelling), its energy (kinetic +
  // potential, from where it started) never exceeds what it had, it does
  // not spin up or roll away, and over the last 100 of 500 frames it rests
  // in the surface with the contact force carrying its weight (mean within
  // 2%; the tool keeps a small jitter, so averages are compared).
  SceneDesc scene = tool_on_block(true);
  const ToolDesc& tool = scene.tools[0];
  const double m = tool.mass;
  CONTACT_SIMULATION(sim, scene);
  double highest_energy = -1e30, lowest = 1e30, fastest_spin = 0, mean_force = 0, mean_y = 0, y_lo = 1, y_hi = -1;
  for (int f = 1; f <= 500; ++f) {
    SINEW_ASSERT_OK(sim.step());
    auto s = sim.tool_state(0);
    ASSERT_TRUE(s.ok()) << s.error().message();
    const V3 w_body = rotate({s->rotation[0], -s->rotation[1], -s->rotation[2], -s->rotation[3]}, s->angular_velocity);
    double energy = 0.5 * m * dot(s->velocity, s->velocity) + m * kG * (s->position[1] - tool.position[1]);
    for (int k = 0; k < 3; ++k) energy += 0.5 * tool.inertia[k] * w_body[k] * w_body[k];
    highest_energy = std::max(highest_energy, energy);
    // The capsule's lowest point: its axis end that is lower, minus the radius.
    const V3 axis = rotate(s->rotation, {0, tool.half_height, 0});
    lowest = std::min(lowest, s->position[1] - std::abs(axis[1]) - tool.radius);
    if (f > 100) fastest_spin = std::max(fastest_spin, norm(s->angular_velocity));
    if (f > 400) {
      mean_force += s->contact_force[1] / 100;
      mean_y += s->position[1] / 100;
      y_lo = std::min(y_lo, s->position[1]);
      y_hi = std::max(y_hi, s->position[1]);
    }
  }
  auto s = sim.tool_state(0);
  ASSERT_TRUE(s.ok());
  EXPECT_LT(highest_energy, 0.0) << "the tool never gains energy";
  EXPECT_GT(lowest, 0.005) << "its lowest point stays above the block's bottom layer of cells";
  EXPECT_LT(mean_y - tool.radius, 0.02) << "it rests pressed into the surface";
  EXPECT_LT(y_hi - y_lo, 1e-3) << "and stays there";
  EXPECT_LT(std::hypot(s->position[0], s->position[2]), 0.01) << "without rolling or sliding away";
  EXPECT_LT(fastest_spin, 1.0) << "nor spinning up [rad/s]";
  EXPECT_NEAR(mean_force, m * kG, 0.02 * m * kG) << "the tissue carries its weight";
  std::printf("[ measured ] tool %.3g kg: lowest point %.4g m, rests at %.4g m (range %.2g m), energy max %.3g J, "
              "spin max %.3g rad/s, contact force %.4g N for a weight of %.4g N\n",
              m, lowest, mean_y - tool.radius, y_hi - y_lo, highest_energy, fastest_spin, mean_force, m * kG);
}

TEST_P(Contact, PushedToolFeelsTheTissuePushBack) {
  // Without gravity, a tool pushed down with 5 N presses into the block;
  // at equilibrium (mean over the last 100 of 400 frames) the tissue's
  // contact force balances the push within 2%, the tool is below the
  // block's original surface, and the torque about its centre is small
  // (below 5 N x 1 mm: the mesh is not quite symmetric).
  SceneDesc scene = tool_on_block(false);
  scene.gravity = {0, 0, 0};
  CONTACT_SIMULATION(sim, scene);
  const V3 push{0, -5, 0};
  V3 force{0, 0, 0}, torque{0, 0, 0};
  double y = 0;
  for (int f = 1; f <= 400; ++f) {
    SINEW_ASSERT_OK(sim.apply_tool_force(0, push, {0, 0, 0}));
    SINEW_ASSERT_OK(sim.step());
    auto s = sim.tool_state(0);
    ASSERT_TRUE(s.ok()) << s.error().message();
    if (f > 300)
      for (int k = 0; k < 3; ++k) {
        force[k] += s->contact_force[k] / 100;
        torque[k] += s->contact_torque[k] / 100;
        y += k == 0 ? s->position[1] / 100 : 0;
      }
  }
  EXPECT_LT(y - scene.tools[0].radius, 0.02) << "pressed into the tissue";
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(force[k], -push[k], 0.02 * 5.0) << "component " << k;
  EXPECT_LT(norm(torque), 5.0 * 1e-3);
  std::printf("[ measured ] pushed with 5 N: bottom at %.4g m, contact force (%.4g, %.4g, %.4g) N, torque %.3g N m\n",
              y - scene.tools[0].radius, force[0], force[1], force[2], norm(torque));
}

TEST_P(Contact, ToolCouplingIsTheSameOnAnyThreadCount) {
  // Every particle's contacts are solved by one work item and the tool's
  // reaction is reduced on the host in particle order: one, two and three
  // threads give bitwise the same tool and tissue.
  SceneDesc scene = tool_on_block(true);
  std::vector<std::vector<double>> runs;
  for (int threads : {1, 2, 3}) {
    auto made = test::create_or_skip(scene, GetParam(), threads);
    ASSERT_TRUE(made.ok()) << made.error().message();
    for (int f = 0; f < 30; ++f) SINEW_ASSERT_OK(made->step());
    auto s = made->tool_state(0);
    ASSERT_TRUE(s.ok());
    std::vector<double> state(s->position.begin(), s->position.end());
    for (double c : s->rotation) state.push_back(c);
    for (double c : s->contact_force) state.push_back(c);
    for (double c : s->contact_torque) state.push_back(c);
    for (float c : positions(*made)) state.push_back(c);
    runs.push_back(state);
  }
  EXPECT_TRUE(runs[0] == runs[1]) << "1 vs 2 threads";
  EXPECT_TRUE(runs[0] == runs[2]) << "1 vs 3 threads";
}

// ------------------------------------------------------------ errors

TEST_P(Contact, BadArgumentsAreErrorsNamingTheParameter) {
  SceneDesc scene = tool_on_block(true);
  scene.colliders.push_back(ColliderDesc{});
  scene.targets = {{0, 0, 0}};
  CONTACT_SIMULATION(sim, scene);
  auto says = [](const Status& s, const std::string& words) {
    if (s.ok()) return ::testing::AssertionFailure() << "expected an error mentioning '" << words << "'";
    if (s.error().message().find(words) == std::string::npos)
      return ::testing::AssertionFailure() << "'" << s.error().message() << "' does not mention '" << words << "'";
    return ::testing::AssertionSuccess();
  };
  const double nan = std::nan("");
  EXPECT_TRUE(says(sim.set_collider_pose(1, {0, 0, 0}, {1, 0, 0, 0}), "index 1"));
  EXPECT_TRUE(says(sim.set_collider_pose(0, {0, nan, 0}, {1, 0, 0, 0}), "position[1]"));
  EXPECT_TRUE(says(sim.set_collider_pose(0, {0, 0, 0}, {1, 1, 0, 0}), "rotation"));
  EXPECT_TRUE(says(sim.set_collider_pose(0, {0, 0, 0}, {0, 0, 0, 0}), "unit quaternion"));
  EXPECT_TRUE(says(sim.set_target(3, {0, 0, 0}), "index 3"));
  EXPECT_TRUE(says(sim.set_target(0, {INFINITY, 0, 0}), "position[0]"));
  EXPECT_TRUE(says(sim.apply_tool_force(1, {0, 0, 0}, {0, 0, 0}), "index 1"));
  EXPECT_TRUE(says(sim.apply_tool_force(0, {0, 0, nan}, {0, 0, 0}), "force[2]"));
  EXPECT_TRUE(says(sim.apply_tool_force(0, {0, 0, 0}, {nan, 0, 0}), "torque[0]"));
  auto state = sim.tool_state(2);
  ASSERT_FALSE(state.ok());
  EXPECT_NE(state.error().message().find("index 2"), std::string::npos) << state.error().message();
  // A cylinder needs a radius and a height.
  SceneDesc bad = scene;
  bad.colliders[0].shape = ColliderShape::cylinder;
  bad.colliders[0].radius = 0.1;
  EXPECT_TRUE(says(check_scene(bad), "colliders[0].half_height"));
  bad.colliders[0].half_height = 0.1;
  bad.colliders[0].radius = -1.0;
  EXPECT_TRUE(says(check_scene(bad), "colliders[0].radius"));
  bad.colliders[0].radius = 0.1;
  EXPECT_TRUE(check_scene(bad).ok());
  // Implicit shapes: nodes only with that shape, a balanced postfix
  // expression within 64 nodes and 8 pending values, valid primitives.
  bad.colliders[0].implicit = bitten_slab().implicit;
  EXPECT_TRUE(says(check_scene(bad), "colliders[0].implicit has nodes but the shape is not"));
  bad.colliders[0] = bitten_slab();
  EXPECT_TRUE(check_scene(bad).ok());
  bad.colliders[0].implicit.clear();
  EXPECT_TRUE(says(check_scene(bad), "colliders[0].implicit is empty"));
  bad.colliders[0] = bitten_slab();
  bad.colliders[0].implicit.pop_back();
  EXPECT_TRUE(says(check_scene(bad), "leaves 2 values"));
  bad.colliders[0].implicit = {operation(ImplicitOp::unite)};
  EXPECT_TRUE(says(check_scene(bad), "colliders[0].implicit[0] is an operation with 0 value(s)"));
  bad.colliders[0] = bitten_slab();
  bad.colliders[0].implicit[1].radius = std::nan("");
  EXPECT_TRUE(says(check_scene(bad), "colliders[0].implicit[1].radius"));
  bad.colliders[0] = bitten_slab();
  bad.colliders[0].implicit[0].rotation = {1, 1, 0, 0};
  EXPECT_TRUE(says(check_scene(bad), "colliders[0].implicit[0].rotation"));
  bad.colliders[0] = ringed_ball();
  bad.colliders[0].implicit[0].minor_radius = 0.0;
  EXPECT_TRUE(says(check_scene(bad), "colliders[0].implicit[0].minor_radius"));
  bad.colliders[0] = cut_capsule();
  bad.colliders[0].implicit[0].rounding = -0.001;
  EXPECT_TRUE(says(check_scene(bad), "colliders[0].implicit[0].rounding"));
  bad.colliders[0].implicit.assign(9, bitten_slab().implicit[1]);  // nine spheres pending at once
  EXPECT_TRUE(says(check_scene(bad), "colliders[0].implicit[8] makes 9 values pending"));
  bad.colliders[0].implicit.clear();
  for (int k = 0; k < 33; ++k) {
    bad.colliders[0].implicit.push_back(bitten_slab().implicit[1]);
    if (k > 0) bad.colliders[0].implicit.push_back(operation(ImplicitOp::unite));
  }
  EXPECT_TRUE(says(check_scene(bad), "has 65 nodes, more than the 64"));
  bad.colliders[0].implicit.resize(63);  // 32 spheres, 31 unions
  EXPECT_TRUE(check_scene(bad).ok());
  // Rejected calls change nothing; good ones still work.
  SINEW_ASSERT_OK(sim.set_collider_pose(0, {0, -0.5, 0}, {std::sqrt(0.5), 0, std::sqrt(0.5), 0}));
  SINEW_ASSERT_OK(sim.set_target(0, {1, 2, 3}));
  SINEW_ASSERT_OK(sim.step());
}

INSTANTIATE_TEST_SUITE_P(Backends, Contact, ::testing::ValuesIn(test::backends()), test::backend_name);

}  // namespace
}  // namespace sinew
