// contact_agreement_test.cpp — the contact kernels on every GPU backend against the
// CPU reference, kernel by kernel (see agreement_support.h), and a contact
// scene frame by frame:
//  - xpbd_solve_attachment: random particles (some immovable, some exactly on
//    their target) pulled to static and moving targets, compliances 0 and
//    not, first and later iterations, the measuring pass;
//  - xpbd_solve_point_attachment: random triangles' points at random
//    barycentric weights (on vertices and edges too), some particles or
//    whole triangles immovable, pulled to static and moving targets;
//  - xpbd_solve_contacts: random particles near and inside a plane, two
//    spheres, a capsule, a box, a cylinder, an implicit CSG shape (every
//    primitive and operation) and two tools (capsules), moving and static,
//    rotated, one rotation flipped to the other hemisphere (the shorter-arc
//    branch), particles exactly on a sphere's centre and a capsule's axis,
//    some immovable, margins, warm-started multipliers, friction off and on
//    (the static and the kinetic cone both met), the first, a middle and the
//    last substep of a frame (impulse restarts), the measuring pass;
//  - a tissue block on a plane, pressed by a moving sphere, a box wall and a
//    tool, two vertices attached to moving targets, stepped 100 frames.
// Inputs are random, from a fresh seed each run (printed on failure);
// outputs the kernel only writes are poisoned with NaN. Tolerance 1e-5
// relative as in backend_agreement_test.cpp: the GPU kernels follow the CPU
// operation order without fused multiply-add, so the results are expected
// bitwise equal (the test prints how many words are) and the tolerance only
// covers a device whose sqrt or division is not correctly rounded.
#include "agreement_support.h"

#include <cstdio>

#include "compiler/float_words.h"
#include "contact_params.h"

namespace sinew::test {
namespace {

using kernels::ColliderEntry;
using kernels::ColliderHeader;
using kernels::ImplicitEntry;
using kernels::SolveParams;
using kernels::TargetEntry;

struct Rigid {
  std::array<float, 3> p;
  std::array<float, 4> q;  // (w, x, y, z)
};

// a q + b r, normalised (in double, then rounded to float).
std::array<float, 4> blend(double a, const std::array<float, 4>& q, double b, const std::array<float, 4>& r) {
  double c[4], n = 0.0;
  for (int k = 0; k < 4; ++k) {
    c[k] = a * q[k] + b * r[k];
    n += c[k] * c[k];
  }
  n = std::sqrt(n);
  return {float(c[0] / n), float(c[1] / n), float(c[2] / n), float(c[3] / n)};
}

std::array<float, 4> random_rotation(std::mt19937& rng) {
  std::normal_distribution<float> g;
  return blend(1.0, {g(rng), g(rng), g(rng), g(rng)}, 0.0, {0.0f, 0.0f, 0.0f, 0.0f});
}

// q rotating v, in double (to place particles; the kernels never see it).
std::array<double, 3> rotated(const std::array<float, 4>& q, const std::array<double, 3>& v) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double t[3] = {2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])};
  return {v[0] + w * t[0] + (y * t[2] - z * t[1]), v[1] + w * t[1] + (z * t[0] - x * t[2]),
          v[2] + w * t[2] + (x * t[1] - y * t[0])};
}

ColliderEntry collider(std::uint32_t shape, const Rigid& start, const Rigid& end) {
  ColliderEntry e{};
  e.shape = shape;
  e.start_px = start.p[0], e.start_py = start.p[1], e.start_pz = start.p[2];
  e.start_qw = start.q[0], e.start_qx = start.q[1], e.start_qy = start.q[2], e.start_qz = start.q[3];
  e.end_px = end.p[0], e.end_py = end.p[1], e.end_pz = end.p[2];
  e.end_qw = end.q[0], e.end_qx = end.q[1], e.end_qy = end.q[2], e.end_qz = end.q[3];
  return e;
}

// The surfaces of the contact case and, for each, the half extents of a box
// in its frame around it where particles are scattered.
struct Surfaces {
  std::vector<ColliderEntry> entries;  // colliders, then tools
  std::vector<std::array<double, 3>> around;
  std::uint32_t colliders = 0, tools = 0;
  std::vector<std::uint32_t> centres;  // entries whose exact centre a particle sits on (static sphere, capsule)
  std::vector<ImplicitEntry> nodes;    // the implicit shapes' nodes, after the entries in the buffer
};

Surfaces contact_surfaces(std::mt19937& rng, bool friction) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), mu(0.05f, 0.8f), alpha(0.0f, 2e-5f);
  Surfaces s;
  auto moved = [&](const Rigid& r, float by) {
    Rigid m = r;
    for (float& c : m.p) c += by * u(rng);
    return m;
  };
  auto add = [&](ColliderEntry e, std::array<double, 3> around) {
    const float a = mu(rng), b = mu(rng);
    e.static_friction = friction ? std::max(a, b) : 0.0f;
    e.dynamic_friction = friction ? std::min(a, b) : 0.0f;
    e.compliance = s.entries.size() % 2 == 0 ? 0.0f : alpha(rng);
    s.entries.push_back(e);
    s.around.push_back(around);
  };
  // Plane, tilting and rising a little over the frame.
  const Rigid plane{{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f, 0.0f}};
  const Rigid plane_end{{0.0f, 0.02f, 0.0f}, blend(1.0, {0.9998f, 0.02f, 0.0f, 0.0f}, 0.0, {})};
  add(collider(SINEW_SHAPE_PLANE, plane, plane_end), {1.0, 0.2, 1.0});
  // A static sphere (a particle on its centre) and a moving one.
  const Rigid sphere{{2.0f, 0.5f, 0.0f}, random_rotation(rng)};
  ColliderEntry e = collider(SINEW_SHAPE_SPHERE, sphere, sphere);
  e.radius = 0.3f;
  s.centres.push_back(static_cast<std::uint32_t>(s.entries.size()));
  add(e, {0.4, 0.4, 0.4});
  const Rigid sphere2{{-2.0f, 0.6f, -2.0f}, random_rotation(rng)};
  e = collider(SINEW_SHAPE_SPHERE, sphere2, moved(sphere2, 0.05f));
  e.radius = 0.25f;
  add(e, {0.35, 0.35, 0.35});
  // A static, rotated capsule (a particle on its axis).
  const Rigid capsule{{-2.0f, 0.5f, 0.0f}, random_rotation(rng)};
  e = collider(SINEW_SHAPE_CAPSULE, capsule, capsule);
  e.radius = 0.15f;
  e.half_height = 0.3f;
  s.centres.push_back(static_cast<std::uint32_t>(s.entries.size()));
  add(e, {0.2, 0.5, 0.2});
  // A box, moving and turning; its end rotation written in the other
  // hemisphere (-q), which the interpolation must flip back.
  const Rigid box{{0.0f, 0.5f, 2.0f}, random_rotation(rng)};
  Rigid box_end = moved(box, 0.05f);
  box_end.q = blend(-0.97, box.q, -0.03, random_rotation(rng));
  e = collider(SINEW_SHAPE_BOX, box, box_end);
  e.half_x = 0.3f;
  e.half_y = 0.2f;
  e.half_z = 0.25f;
  add(e, {0.38, 0.28, 0.33});
  // A cylinder, moving and turning (particles over its caps, its side and
  // its rims, and inside it).
  const Rigid cylinder{{2.0f, 0.5f, -2.0f}, random_rotation(rng)};
  Rigid cylinder_end = moved(cylinder, 0.05f);
  cylinder_end.q = blend(0.95, cylinder.q, 0.05, random_rotation(rng));
  e = collider(SINEW_SHAPE_CYLINDER, cylinder, cylinder_end);
  e.radius = 0.2f;
  e.half_height = 0.15f;
  add(e, {0.3, 0.3, 0.3});
  // An implicit shape, moving and turning, with every primitive and
  // operation: ((rounded box - sphere) u torus u (capsule u cylinder)) n
  // a tilted half-space, the primitives in their own poses.
  const Rigid blob{{0.0f, 0.5f, 0.0f}, random_rotation(rng)};
  Rigid blob_end = moved(blob, 0.05f);
  blob_end.q = blend(0.95, blob.q, 0.05, random_rotation(rng));
  e = collider(SINEW_SHAPE_IMPLICIT, blob, blob_end);
  e.implicit_first = static_cast<std::uint32_t>(s.nodes.size());
  auto node = [&](std::uint32_t op, std::array<float, 3> at, bool turned) {
    ImplicitEntry n{};
    n.op = op;
    n.px = at[0], n.py = at[1], n.pz = at[2];
    const std::array<float, 4> q = turned ? random_rotation(rng) : std::array<float, 4>{1.0f, 0.0f, 0.0f, 0.0f};
    n.qw = q[0], n.qx = q[1], n.qy = q[2], n.qz = q[3];
    s.nodes.push_back(n);
    return &s.nodes.back();
  };
  ImplicitEntry* n = node(SINEW_IMPLICIT_BOX, {0.0f, 0.0f, 0.0f}, true);
  n->half_x = 0.25f, n->half_y = 0.15f, n->half_z = 0.2f, n->rounding = 0.02f;
  node(SINEW_IMPLICIT_SPHERE, {0.1f, 0.15f, 0.0f}, false)->radius = 0.12f;
  node(SINEW_IMPLICIT_SUBTRACT, {}, false);
  n = node(SINEW_IMPLICIT_TORUS, {0.0f, -0.1f, 0.0f}, true);
  n->radius = 0.2f, n->minor_radius = 0.05f;
  node(SINEW_IMPLICIT_UNITE, {}, false);
  n = node(SINEW_IMPLICIT_CAPSULE, {-0.15f, 0.1f, 0.1f}, true);
  n->radius = 0.06f, n->half_height = 0.15f;
  n = node(SINEW_IMPLICIT_CYLINDER, {0.15f, -0.05f, -0.1f}, true);
  n->radius = 0.1f, n->half_height = 0.08f, n->rounding = 0.01f;
  node(SINEW_IMPLICIT_UNITE, {}, false);
  node(SINEW_IMPLICIT_UNITE, {}, false);
  // The cut only tilted a little, so that it never leaves too little of the
  // shape for the scattered particles to touch.
  n = node(SINEW_IMPLICIT_HALF_SPACE, {0.0f, 0.12f, 0.0f}, false);
  const std::array<float, 4> tilt = blend(0.95, {1.0f, 0.0f, 0.0f, 0.0f}, 0.05, random_rotation(rng));
  n->qw = tilt[0], n->qx = tilt[1], n->qy = tilt[2], n->qz = tilt[3];
  node(SINEW_IMPLICIT_INTERSECT, {}, false);
  e.implicit_count = static_cast<std::uint32_t>(s.nodes.size()) - e.implicit_first;
  add(e, {0.35, 0.3, 0.35});
  s.colliders = static_cast<std::uint32_t>(s.entries.size());
  // Tools: capsules, one moving and turning, one still.
  const Rigid tool{{0.0f, 0.5f, -2.0f}, random_rotation(rng)};
  Rigid tool_end = moved(tool, 0.05f);
  tool_end.q = blend(0.9, tool.q, 0.1, random_rotation(rng));
  e = collider(SINEW_SHAPE_CAPSULE, tool, tool_end);
  e.radius = 0.1f;
  e.half_height = 0.2f;
  add(e, {0.15, 0.35, 0.15});
  const Rigid tool2{{2.0f, 0.5f, 2.0f}, random_rotation(rng)};
  e = collider(SINEW_SHAPE_CAPSULE, tool2, tool2);
  e.radius = 0.12f;
  e.half_height = 0.1f;
  add(e, {0.17, 0.27, 0.17});
  s.tools = static_cast<std::uint32_t>(s.entries.size()) - s.colliders;
  return s;
}

struct ContactSetup {
  std::vector<float> x, prev, margin, lambda, impulses, colliders;
  std::vector<std::uint32_t> idx;
  Surfaces surfaces;
  std::uint32_t constraints = 0;
};

// Particles scattered around every surface (inside and outside), every 5th
// immovable, previous positions a little behind, warm multipliers.
ContactSetup contact_setup(std::mt19937& rng, bool friction, float substep_fraction) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), w(0.5, 2.0), step(0.0, 0.03);
  std::uniform_real_distribution<float> uf(-1.0f, 1.0f), lam(0.0f, 0.05f), margin(0.0f, 0.02f);
  ContactSetup c;
  c.surfaces = contact_surfaces(rng, friction);
  const Surfaces& s = c.surfaces;
  const auto surfaces = static_cast<std::uint32_t>(s.entries.size());
  const std::uint32_t n = 700 + rng() % 50;
  for (std::uint32_t p = 0; p < n; ++p) {
    const std::uint32_t k = p % surfaces;
    const ColliderEntry& e = s.entries[k];
    const std::array<float, 4> q{e.end_qw, e.end_qx, e.end_qy, e.end_qz};
    std::array<double, 3> local{u(rng) * s.around[k][0], u(rng) * s.around[k][1], u(rng) * s.around[k][2]};
    const std::array<double, 3> r = rotated(q, local);
    std::array<float, 3> at{float(e.end_px + r[0]), float(e.end_py + r[1]), float(e.end_pz + r[2])};
    for (std::uint32_t centre : s.centres)  // exactly on a static sphere's centre or capsule's axis
      if (p == 2 * surfaces + centre) at = {s.entries[centre].end_px, s.entries[centre].end_py, s.entries[centre].end_pz};
    const float inverse_mass = p % 5 == 3 ? 0.0f : float(w(rng));  // 5: prime to the surfaces' count
    c.x.insert(c.x.end(), {at[0], at[1], at[2], inverse_mass});
    // Where it was at the substep's start: up to 3 cm away.
    c.prev.insert(c.prev.end(), {at[0] - float(step(rng) * u(rng)), at[1] - float(step(rng) * u(rng)),
                                 at[2] - float(step(rng) * u(rng)), inverse_mass});
  }
  c.constraints = n;  // one per particle, in a shuffled order (one colour)
  c.idx = one_colour(rng, n, 1);
  for (std::uint32_t i = 0; i < n; ++i) {
    c.margin.push_back(i % 3 == 0 ? 0.0f : margin(rng));
    for (std::uint32_t k = 0; k < surfaces; ++k) {
      const bool warm = rng() % 2 == 0;
      c.lambda.insert(c.lambda.end(), {warm ? lam(rng) : 0.0f, 0.02f * uf(rng), 0.02f * uf(rng), 0.02f * uf(rng)});
    }
  }
  append_words(c.colliders, ColliderHeader{s.colliders, s.tools, substep_fraction, 0});
  for (const ColliderEntry& e : s.entries) append_words(c.colliders, e);
  for (const ImplicitEntry& entry : s.nodes) append_words(c.colliders, entry);
  c.impulses.resize(std::size_t{n} * s.tools * SINEW_CONTACT_IMPULSE_FLOAT4S * 4);
  for (float& v : c.impulses) v = uf(rng);
  return c;
}

KernelCase contact_case(const ContactSetup& c, float substep_end, bool reset, bool measure) {
  const std::uint32_t first = 3, count = c.constraints - 8;  // items outside [first, first + count) untouched
  KernelCase k{Kernel::xpbd_solve_contacts, count, {}, {}};
  k.bindings.push_back({c.x, false, 4});
  k.bindings.push_back({as_words(c.idx), false});
  k.bindings.push_back({c.margin, false});
  k.bindings.push_back({c.lambda, reset && !measure, 4});  // lambda_n, lambda_t per surface
  k.bindings.push_back({std::vector<float>(c.constraints, 0.0f), measure});
  k.bindings.push_back({c.prev, false, 4});
  k.bindings.push_back({c.colliders, false});
  k.bindings.push_back({c.impulses, false, 4});
  k.bindings.push_back({std::vector<float>(4, 0.0f), false});  // no level-set grids (level_set_contact_test.cpp)
  const float h = 1.0f / 240.0f;
  k.params = bytes_of(SolveParams{first, count, 1.0f / (h * h), reset ? 1u : 0u, h, substep_end, measure ? 1u : 0u, 0});
  return k;
}

TEST_P(Agreement, ContactKernel) {
  const unsigned seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  struct Pass {
    float substep_end;
    bool reset, measure;
  };
  // The frame's first substep (restarts the frame's impulse sums), a middle
  // one, the last (restarts and writes the last substep's), each with the
  // first iteration (reset) and a later one; measuring passes.
  const Pass passes[] = {{0.25f, true, false}, {0.25f, false, false}, {0.5f, true, false}, {0.5f, false, false},
                         {1.0f, true, false},  {1.0f, false, false},  {1.0f, false, true}, {0.5f, false, true},
                         {1.0f, true, true}};
  for (bool friction : {false, true}) {
    const ContactSetup setup = contact_setup(rng, friction, 0.25f);
    const std::uint32_t surfaces = setup.surfaces.colliders + setup.surfaces.tools;
    for (const Pass& pass : passes) {
      const std::string what = std::string("contacts") + (friction ? " friction" : " frictionless") + " t " +
                               std::to_string(pass.substep_end) + (pass.reset ? " reset" : "") +
                               (pass.measure ? " measure" : "");
      const KernelCase c = contact_case(setup, pass.substep_end, pass.reset, pass.measure);
      const auto ref = run_on("cpu", c);
      const auto gpu = run_on(GetParam(), c);
      expect_agree(c, ref, gpu, what);
      report_difference(c, ref, gpu, GetParam() + " " + what);
      if (pass.measure || ref.size() != c.bindings.size()) continue;
      // The case reaches what it should: every surface touched; with
      // friction, particles held in the static cone and sliding in the
      // kinetic one (|lambda_t| = mu_k lambda_n).
      std::vector<std::uint32_t> touching(surfaces, 0);
      std::uint32_t sticking = 0, sliding = 0;
      for (std::uint32_t i = 3; i < 3 + c.count; ++i)
        for (std::uint32_t k = 0; k < surfaces; ++k) {
          const float* l = &ref[3][(std::size_t{i} * surfaces + k) * 4];
          if (!(l[0] > 0.0f)) continue;
          ++touching[k];
          const double t = std::hypot(double(l[1]), double(l[2]), double(l[3]));
          const double mu_k = setup.surfaces.entries[k].dynamic_friction;
          if (std::abs(t - mu_k * l[0]) <= 1e-5 * mu_k * l[0]) ++sliding;
          else if (t < 0.999 * mu_k * l[0]) ++sticking;
        }
      for (std::uint32_t k = 0; k < surfaces; ++k) EXPECT_GT(touching[k], 0u) << what << ": surface " << k;
      if (friction) {
        EXPECT_GT(sticking, 0u) << what;
        EXPECT_GT(sliding, 0u) << what;
      }
    }
  }
}

// `n` targets (TargetEntry words) in [-1, 1]^3, every fourth still, the
// others moving up to 0.1 along each axis.
std::vector<float> random_targets(std::mt19937& rng, std::uint32_t n) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> words;
  for (std::uint32_t t = 0; t < n; ++t) {
    TargetEntry e{};
    e.start_x = u(rng), e.start_y = u(rng), e.start_z = u(rng);
    const bool still = t % 4 == 0;
    e.end_x = still ? e.start_x : e.start_x + 0.1f * u(rng);
    e.end_y = still ? e.start_y : e.start_y + 0.1f * u(rng);
    e.end_z = still ? e.start_z : e.start_z + 0.1f * u(rng);
    append_words(words, e);
  }
  return words;
}

TEST_P(Agreement, AttachmentKernel) {
  const unsigned seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), alpha(0.0f, 1e-4f), lam(-1e-2f, 1e-2f);
  const std::uint32_t targets = 40, first = 3, count = 500 + rng() % 50, total = first + count + 5;
  const std::vector<float> target_data = random_targets(rng, targets);
  for (bool reset : {false, true}) {
    for (bool measure : {false, true}) {
      for (float substep_end : {0.5f, 1.0f}) {
        std::vector<float> x = random_particles(rng, total);
        const std::vector<std::uint32_t> idx = one_colour(rng, total, 1);
        std::vector<float> data, lambda;
        for (std::uint32_t i = 0; i < total; ++i) {
          const std::uint32_t t = rng() % targets;
          data.insert(data.end(), {float(t), i % 3 == 0 ? 0.0f : alpha(rng)});
          lambda.push_back(lam(rng));
          // Some particles near their target, a few exactly on it where the
          // target is still (C = 0: nothing to do).
          const float* e = &target_data[t * 8];
          float* p = &x[4 * idx[i]];
          if (i % 5 == 1)
            for (int k = 0; k < 3; ++k) p[k] = e[4 + k] + 0.01f * u(rng);
          if (i % 11 == 2 && t % 4 == 0)
            for (int k = 0; k < 3; ++k) p[k] = e[k];
        }
        KernelCase c{Kernel::xpbd_solve_attachment, count, {}, {}};
        c.bindings.push_back({x, false, 4});
        c.bindings.push_back({as_words(idx), false});
        c.bindings.push_back({data, false, 2});
        c.bindings.push_back({lambda, reset && !measure});
        c.bindings.push_back({std::vector<float>(total, 0.0f), measure});
        c.bindings.push_back({target_data, false, 4});
        c.params = bytes_of(SolveParams{first, count, 3600.0f, reset ? 1u : 0u, 1.0f / 60.0f, substep_end,
                                        measure ? 1u : 0u, 0});
        const std::string what = std::string("attachment t ") + std::to_string(substep_end) +
                                 (reset ? " reset" : "") + (measure ? " measure" : "");
        const auto ref = run_on("cpu", c);
        const auto gpu = run_on(GetParam(), c);
        expect_agree(c, ref, gpu, what);
        report_difference(c, ref, gpu, GetParam() + " " + what);
      }
    }
  }
}

TEST_P(Agreement, PointAttachmentKernel) {
  // Random triangles of one colour (some particles immovable, a few
  // triangles wholly so), points at random barycentric weights (some on a
  // vertex or an edge), pulled to static and moving targets; a few points
  // exactly on their still target (C = 0).
  const unsigned seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), unit(0.0f, 1.0f), alpha(0.0f, 1e-4f), lam(-1e-2f, 1e-2f);
  const std::uint32_t targets = 40, first = 3, count = 300 + rng() % 50, total = first + count + 5;
  const std::vector<float> target_data = random_targets(rng, targets);
  for (bool reset : {false, true}) {
    for (bool measure : {false, true}) {
      for (float substep_end : {0.5f, 1.0f}) {
        std::vector<float> x = random_particles(rng, 3 * total);
        const std::vector<std::uint32_t> idx = one_colour(rng, total, 3);
        std::vector<float> data, lambda;
        for (std::uint32_t i = 0; i < total; ++i) {
          const std::uint32_t t = rng() % targets;
          float w[3] = {unit(rng), unit(rng), unit(rng)};
          if (i % 7 == 0) w[0] = 1.0f, w[1] = w[2] = 0.0f;  // on a vertex
          if (i % 7 == 1) w[2] = 0.0f;                       // on an edge
          const float sum = w[0] + w[1] + w[2];
          for (float& k : w) k /= sum;
          data.insert(data.end(), {w[0], w[1], w[2], i % 3 == 0 ? 0.0f : alpha(rng), float(t), 0.0f, 0.0f, 0.0f});
          lambda.push_back(lam(rng));
          if (i % 13 == 5)  // a wholly immovable triangle
            for (int k = 0; k < 3; ++k) x[4 * idx[3 * i + k] + 3] = 0.0f;
          if (i % 11 == 2 && t % 4 == 0) {  // the point exactly on its still target: put the vertex there, w = (1, 0, 0)
            const float* e = &target_data[t * 8];
            data[8 * i] = 1.0f, data[8 * i + 1] = data[8 * i + 2] = 0.0f;
            for (int k = 0; k < 3; ++k) x[4 * idx[3 * i] + k] = e[k];
          }
        }
        KernelCase c{Kernel::xpbd_solve_point_attachment, count, {}, {}};
        c.bindings.push_back({x, false, 4});
        c.bindings.push_back({as_words(idx), false});
        c.bindings.push_back({data, false, 4});
        c.bindings.push_back({lambda, reset && !measure});
        c.bindings.push_back({std::vector<float>(total, 0.0f), measure});
        c.bindings.push_back({target_data, false, 4});
        c.params = bytes_of(SolveParams{first, count, 3600.0f, reset ? 1u : 0u, 1.0f / 60.0f, substep_end,
                                        measure ? 1u : 0u, 0});
        const std::string what = std::string("point attachment t ") + std::to_string(substep_end) +
                                 (reset ? " reset" : "") + (measure ? " measure" : "");
        const auto ref = run_on("cpu", c);
        const auto gpu = run_on(GetParam(), c);
        expect_agree(c, ref, gpu, what);
        report_difference(c, ref, gpu, GetParam() + " " + what);
      }
    }
  }
}

// A 6 x 3 x 6 cm tissue block (distance and volume constraints, 1 cm cells)
// dropped 1 mm onto a plane with friction, pressed from above by a sphere
// that moves down and sideways, pushed by a box wall from the side, loaded
// by a tool lying across its top (pushed down with 0.3 N), and held at its
// two top corners on the +x side by attachments (one rigid, one compliant)
// whose targets circle.
SceneDesc contact_scene() {
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 8, .iterations = 3};
  TetBodyDesc body;
  body.mesh = test::box_mesh(6, 3, 6, 0.01);
  for (Vec3d& v : body.mesh.vertices) v = {v[0] - 0.03, v[1] + 0.001, v[2] - 0.03};
  EXPECT_TRUE(body.set_elastic(2e5, 0.3).ok());
  scene.tet_bodies.push_back(body);
  ColliderDesc plane;
  plane.static_friction = 0.6;
  plane.dynamic_friction = 0.4;
  scene.colliders.push_back(plane);
  ColliderDesc sphere;
  sphere.shape = ColliderShape::sphere;
  sphere.radius = 0.015;
  sphere.position = {0.015, 0.031 + 0.015, 0.015};
  scene.colliders.push_back(sphere);
  ColliderDesc wall;
  wall.shape = ColliderShape::box;
  wall.half_extents = {0.01, 0.04, 0.04};  // reaching below the plane: no vertex slips under it
  wall.position = {-0.041, 0.02, 0.0};
  wall.compliance = 1e-6;
  scene.colliders.push_back(wall);
  ToolDesc tool;
  tool.radius = 0.012;
  tool.half_height = 0.02;
  tool.mass = 0.05;
  tool.gravity = false;  // pushed down by a force instead (see the test)
  const double m = tool.mass, r2 = tool.radius * tool.radius, l2 = 4 * tool.half_height * tool.half_height;
  tool.inertia = {m * (3 * r2 + l2) / 12, m * r2 / 2, m * (3 * r2 + l2) / 12};
  tool.position = {-0.012, 0.031 + tool.radius + 0.0005, -0.01};  // 0.5 mm above the block
  tool.rotation = {std::sqrt(0.5), std::sqrt(0.5), 0.0, 0.0};  // its axis along z
  scene.tools.push_back(tool);
  // The two top corners at x = +0.03 (z = -0.03 and +0.03) on targets.
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v) {
    const Vec3d& p = body.mesh.vertices[v];
    if (p[1] > 0.0305 && p[0] > 0.0299 && std::abs(std::abs(p[2]) - 0.03) < 1e-6) {
      scene.attachments.push_back({.vertex = {.body_kind = BodyKind::tet, .body = 0, .vertex = v},
                                   .target = static_cast<std::uint32_t>(scene.targets.size()),
                                   .compliance = scene.targets.empty() ? 0.0 : 1e-4});
      scene.targets.push_back({p[0], p[1], p[2]});
    }
  }
  EXPECT_EQ(scene.targets.size(), 2u);
  return scene;
}

TEST_P(Agreement, ContactSceneAfter100Frames) {
  const SceneDesc scene = contact_scene();
  std::vector<float> x[2];
  std::array<double, 3> tool_at[2];
  double tool_push = 0.0;  // the tissue's upward force on the tool, summed over the frames [N]
  int k = 0;
  for (const std::string& backend : {std::string("cpu"), GetParam()}) {
    auto sim = test::create_or_skip(scene, backend);
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    for (int f = 1; f <= 100; ++f) {
      const double s = f / 100.0;
      // The sphere presses 5 mm down and slides 1 cm; the wall advances 4 mm.
      ASSERT_TRUE(sim->set_collider_pose(1, {0.015 - 0.01 * s, 0.046 - 0.005 * s, 0.015}, {1, 0, 0, 0}).ok());
      ASSERT_TRUE(sim->set_collider_pose(2, {-0.041 + 0.004 * s, 0.02, 0.0}, {1, 0, 0, 0}).ok());
      for (std::size_t t = 0; t < scene.targets.size(); ++t) {
        const auto& o = scene.targets[t];
        const double a = 0.2 * f;
        ASSERT_TRUE(sim->set_target(t, {o[0] + 0.002 * std::cos(a) - 0.002, o[1] + 0.002 * std::sin(a), o[2]}).ok());
      }
      ASSERT_TRUE(sim->apply_tool_force(0, {0.0, -0.3, 0.0}, {0.0, 0.0, 0.0}).ok());
      ASSERT_TRUE(sim->step().ok());
      auto tool = sim->tool_state(0);
      ASSERT_TRUE(tool.ok());
      if (k == 0) tool_push += tool->contact_force[1];
    }
    ASSERT_TRUE(sim->read_positions(x[k]).ok());
    auto tool = sim->tool_state(0);
    ASSERT_TRUE(tool.ok());
    tool_at[k++] = tool->position;
  }
  // The scene does what it should (on the CPU): the block rests on the
  // plane, the sphere and the wall press into it, the tool presses on it.
  // Signed distances at the end: plane y, sphere (centre (0.005, 0.041,
  // 0.015), radius 0.015), wall face x = -0.027.
  double plane = 1.0, sphere = 1.0, wall = 1.0;
  for (std::size_t i = 0; i < x[0].size(); i += 4) {
    plane = std::min(plane, double(x[0][i + 1]));
    sphere = std::min(sphere, std::hypot(x[0][i] - 0.005, x[0][i + 1] - 0.041, x[0][i + 2] - 0.015) - 0.015);
    wall = std::min(wall, x[0][i] + 0.027);
  }
  EXPECT_NEAR(plane, 0.0, 1e-4) << "resting on the plane";
  EXPECT_NEAR(sphere, 0.0, 1e-4) << "pressed by the sphere";
  EXPECT_NEAR(wall, 0.0, 1e-4) << "pushed by the wall";
  EXPECT_GT(tool_push / 100, 0.1) << "the tissue pushes the tool up";
  std::printf("[ measured ] contact scene on cpu: nearest vertex to the plane %.3g m, sphere %.3g m, wall %.3g m; "
              "mean upward force on the tool %.3g N\n",
              plane, sphere, wall, tool_push / 100);
  const double diagonal = std::sqrt(0.06 * 0.06 + 0.031 * 0.031 + 0.06 * 0.06);
  double worst = 0.0;
  for (std::size_t i = 0; i < x[0].size(); i += 4)
    worst = std::max(worst, std::hypot(double(x[0][i]) - x[1][i], double(x[0][i + 1]) - x[1][i + 1], double(x[0][i + 2]) - x[1][i + 2]));
  const double tool = std::hypot(tool_at[0][0] - tool_at[1][0], tool_at[0][1] - tool_at[1][1], tool_at[0][2] - tool_at[1][2]);
  EXPECT_LT(worst, 1e-4 * diagonal) << "largest position difference " << worst << " m";
  EXPECT_LT(tool, 1e-4 * diagonal) << "tool position difference " << tool << " m";
  std::printf("[ agree    ] contact scene 100 frames, %s vs cpu: largest difference %.3e m (%.2e of the diagonal), "
              "tool %.3e m\n",
              GetParam().c_str(), worst, worst / diagonal, tool);
}

}  // namespace
}  // namespace sinew::test
