// thin_agreement_test.cpp — the thin kernels on every GPU backend against the
// CPU reference, kernel by kernel (see agreement_support.h):
// xpbd_solve_area, xpbd_solve_dihedral and xpbd_solve_line_bending
// (kernels/cpu/thin_kernels.cpp; GPU twins kernels/gpu/NAME.gpu, compiled to
// OpenCL C and SPIR-V).
//
// Inputs are built the way the scene compiler builds them
// (src/compiler/compile_thin.cpp): a rest shape in float, its rest value (area,
// dihedral angle, Kelager offset) computed from the float positions with the
// very functions of thin_kernels.h, compliances in the units of
// thin_params.h; then the movable vertices are displaced from the rest shape
// (immovable ones never move). Configurations: random triangles, slivers and
// bodies exactly at rest; flat, random, nearly folded and exactly folded or
// flat hinges, hinges pushed across the +-pi wrap; nearly straight and
// exactly straight threads; pinned vertices (inverse mass 0, some shared
// between constraints of the colour); rigid and compliant constraints; every
// combination of reset_lambda and measure_only. A second case per kernel
// drives every guard of the CPU kernel: collapsed triangles, zero-length
// hinge edges and wings on the edge line, a thread vertex exactly at its
// centroid, fully pinned rigid constraints (denominator 0), overflowing
// gradients and compliances (denominator infinite or NaN), atan2 of zeros.
// Seeds are fresh each run.
//
// Tolerance: expect_agree's 1e-5 relative. The twins use the CPU kernels'
// operation order without contraction, and the dihedral angle's atan2 is
// our own thin::atan2_portable (kernels/math/thin_math.h: + - * / and
// sqrt only), which the twins repeat operation for operation, so on PoCL and
// lavapipe every word is bitwise equal whatever the C library; the
// tolerance is left for devices whose division and sqrt are not correctly
// rounded (Vulkan allows 2.5 ulp). Each case prints how many words differ
// and by how much.
#include <cinttypes>
#include <cstdio>
#include <functional>

#include "agreement_support.h"
#include "cpu/thin_kernels.h"
#include "cpu/xpbd_kernels.h"

namespace sinew::test {
namespace {

namespace thin = kernels::thin;

constexpr float kPi = 3.14159265358979323846f;
constexpr float kRandom = std::numeric_limits<float>::quiet_NaN();  // a lambda drawn at random

// Particles and constraints of one kernel case before they are laid out in
// buffers: `rest` is the shape the rest values come from, `now` the one the
// kernel sees.
struct Thin {
  std::vector<float4> rest, now;
  std::vector<std::uint32_t> ids;  // `arity` per constraint
  std::vector<float> data;         // `stride` per constraint
  std::vector<float> lambda;       // per constraint (NaN: random), or empty: all random
  std::uint32_t shared_pin = ~0u;  // an immovable particle several constraints use

  std::uint32_t add(float4 p) {
    rest.push_back(p);
    now.push_back(p);
    return static_cast<std::uint32_t>(rest.size() - 1);
  }
};

float4 p3(float x, float y, float z, float w = 1.0f) { return {x, y, z, w}; }
float4 plus(float4 a, float4 b) { return {a.x + b.x, a.y + b.y, a.z + b.z, a.w}; }
float4 unit(float4 a) { return (1.0f / std::sqrt(dot3(a, a))) * a; }

float4 random_direction(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  for (;;) {
    const float4 d{n(rng), n(rng), n(rng), 0.0f};
    if (dot3(d, d) > 1e-4f) return unit(d);
  }
}

// An orthonormal frame (t, u, v) with t along `t`.
void frame(std::mt19937& rng, float4 t, float4& u, float4& v) {
  for (;;) {
    const float4 r = random_direction(rng);
    const float4 c = kernels::cross3(t, r);
    if (dot3(c, c) > 1e-2f) {
      u = unit(c);
      v = kernels::cross3(t, u);
      return;
    }
  }
}

// A random inverse mass, 0 (pinned) with probability `pinned`.
float inverse_mass(std::mt19937& rng, float pinned) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f), w(0.5f, 2.0f);
  return u(rng) < pinned ? 0.0f : w(rng);
}

// Compliance: rigid a third of the time, else log-uniform in [lo, hi].
float compliance(std::mt19937& rng, float lo, float hi) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  if (u(rng) < 1.0f / 3.0f) return 0.0f;
  return lo * std::pow(hi / lo, u(rng));
}

// Moves the movable particles of `t.now` (from index `from` on) by up to `scale` in each coordinate.
void displace(std::mt19937& rng, Thin& t, std::uint32_t from, float scale) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (std::uint32_t k = from; k < t.now.size(); ++k)
    if (t.now[k].w > 0.0f) t.now[k] = plus(t.now[k], p3(scale * u(rng), scale * u(rng), scale * u(rng)));
}

// Vertex k of a new constraint: a fresh particle, or now and then the shared pinned one.
std::uint32_t vertex(std::mt19937& rng, Thin& t, float4 p, float pinned) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  if (t.shared_pin != ~0u && u(rng) < 0.02f) return t.shared_pin;
  return t.add({p.x, p.y, p.z, inverse_mass(rng, pinned)});
}

// ------------------------------------------------------------ generators

// A triangle as compile_thin makes one: A0 from the float rest positions,
// alpha = c_a A0 / t.
void add_triangle(std::mt19937& rng, Thin& t, const std::uint32_t v[3]) {
  const float a0 = thin::triangle_area(t.rest[v[0]], t.rest[v[1]], t.rest[v[2]]);
  t.ids.insert(t.ids.end(), {v[0], v[1], v[2]});
  const float ca = compliance(rng, 1e-7f, 1e-3f), thickness = 1e-3f;
  t.data.insert(t.data.end(), {a0, static_cast<float>(double(ca) * a0 / thickness)});
}

// `n` triangles: random ones, slivers, ones left at rest.
Thin area_constraints(std::mt19937& rng, std::uint32_t n) {
  Thin t;
  t.shared_pin = t.add(p3(0.1f, 0.2f, -0.3f, 0.0f));
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), size(0.02f, 0.5f), unit01(0.0f, 1.0f);
  for (std::uint32_t k = 0; k < n; ++k) {
    const std::uint32_t kind = k % 4;  // 0 random, 1 sliver, 2 at rest, 3 large strain
    const float4 base = p3(u(rng), u(rng), u(rng));
    const float s = size(rng);
    const float4 a = random_direction(rng);
    float4 b = random_direction(rng);
    if (kind == 1) b = unit(plus(a, 1e-3f * random_direction(rng)));  // nearly collinear edges
    const float4 x[3] = {base, plus(base, s * a), plus(base, (s * (0.3f + unit01(rng))) * b)};
    const std::uint32_t first = static_cast<std::uint32_t>(t.now.size());
    std::uint32_t v[3];
    for (int i = 0; i < 3; ++i) v[i] = vertex(rng, t, x[i], 0.15f);
    if (!(thin::triangle_area(t.rest[v[0]], t.rest[v[1]], t.rest[v[2]]) > 0.0f)) {  // compile_thin rejects these
      t.rest.resize(first);
      t.now.resize(first);
      --k;
      continue;
    }
    add_triangle(rng, t, v);
    if (kind != 2) displace(rng, t, first, kind == 3 ? 0.3f * s : 1e-3f * s);
  }
  return t;
}

// A hinge as compile_thin makes one: theta0 from the float rest positions.
void add_hinge(std::mt19937& rng, Thin& t, const std::uint32_t v[4]) {
  const float theta0 = thin::dihedral_angle(t.rest[v[0]], t.rest[v[1]], t.rest[v[2]], t.rest[v[3]]);
  t.ids.insert(t.ids.end(), {v[0], v[1], v[2], v[3]});
  t.data.insert(t.data.end(), {theta0, compliance(rng, 1e-6f, 1e-1f)});
}

// `n` hinges of an edge of length ~[0.02, 0.5] with wings at angle `phi`
// from the flat continuation: flat (|phi| < 1e-3), random, nearly folded
// (|phi| within 1e-3 of pi); displaced a little, a lot, or across the wrap.
Thin dihedral_constraints(std::mt19937& rng, std::uint32_t n) {
  Thin t;
  t.shared_pin = t.add(p3(-0.2f, 0.4f, 0.1f, 0.0f));
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), size(0.02f, 0.5f), along(-0.3f, 1.3f), height(0.2f, 1.0f),
      small(-1e-3f, 1e-3f), unit01(0.0f, 1.0f);
  for (std::uint32_t k = 0; k < n; ++k) {
    const std::uint32_t kind = k % 6;  // 0 flat, 1 random, 2 nearly folded, 3 folded across the wrap,
                                       // 4 flat at rest, 5 random with large displacement
    const float4 base = p3(u(rng), u(rng), u(rng));
    const float le = size(rng);
    const float4 e = random_direction(rng);
    float4 fu, fv;
    frame(rng, e, fu, fv);
    float phi = 0.0f;
    if (kind == 0 || kind == 4) phi = small(rng);
    if (kind == 1 || kind == 5) phi = kPi * u(rng);
    if (kind == 2 || kind == 3) phi = std::copysign(kPi - std::abs(small(rng)), u(rng));
    const float h2 = le * height(rng), h3 = le * height(rng), a3 = le * along(rng);
    // Wing 2 at +u; wing 3 at -u turned by phi about the edge (phi = 0: flat, +-pi: folded onto wing 2).
    const float4 w3 = plus((-std::cos(phi)) * fu, (-std::sin(phi)) * fv);
    const float4 x[4] = {base, plus(base, le * e), plus(plus(base, (le * along(rng)) * e), h2 * fu),
                         plus(plus(base, a3 * e), h3 * w3)};
    const std::uint32_t first = static_cast<std::uint32_t>(t.now.size());
    std::uint32_t v[4];
    for (int i = 0; i < 4; ++i) v[i] = vertex(rng, t, x[i], 0.15f);
    add_hinge(rng, t, v);
    if (kind == 3) {
      // Close the fold further by a little more than it is open, so theta crosses +-pi
      // (wing 3 turned on around the edge), when wing 3 may move.
      const float4 w3b = plus((-std::cos(phi + std::copysign(2e-3f, phi))) * fu,
                              (-std::sin(phi + std::copysign(2e-3f, phi))) * fv);
      const float4 moved = plus(plus(base, a3 * e), h3 * w3b);
      if (t.now[v[3]].w > 0.0f) t.now[v[3]] = {moved.x, moved.y, moved.z, t.now[v[3]].w};
      displace(rng, t, first, 1e-5f * le);
    } else if (kind == 5) {
      displace(rng, t, first, 0.3f * le);
    } else if (kind != 4) {
      displace(rng, t, first, 1e-3f * le);
    }
  }
  return t;
}

// A thread vertex as compile_thin makes one: h0 and the mean segment length
// L from the float rest positions.
void add_thread_vertex(std::mt19937& rng, Thin& t, const std::uint32_t v[3]) {
  const float4 b0 = t.rest[v[0]], x = t.rest[v[1]], b1 = t.rest[v[2]];
  const float mean_length = 0.5f * (kernels::edge_length(b0, x) + kernels::edge_length(x, b1));
  t.ids.insert(t.ids.end(), {v[0], v[1], v[2]});
  t.data.insert(t.data.end(), {thin::line_bending_offset(b0, x, b1), compliance(rng, 1e-6f, 1e-1f), mean_length, 0.0f});
}

// `n` thread vertices: nearly straight (bent by up to 1e-3 rad) or bent,
// unevenly divided; at rest, displaced a little or a lot.
Thin line_constraints(std::mt19937& rng, std::uint32_t n) {
  Thin t;
  t.shared_pin = t.add(p3(0.3f, -0.1f, 0.2f, 0.0f));
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), size(0.005f, 0.2f), ratio(0.8f, 1.25f), small(-1e-3f, 1e-3f);
  for (std::uint32_t k = 0; k < n; ++k) {
    const std::uint32_t kind = k % 4;  // 0 nearly straight, 1 nearly straight at rest, 2 bent, 3 large displacement
    const float4 base = p3(u(rng), u(rng), u(rng));
    const float l = size(rng);
    const float4 d = random_direction(rng);
    float4 fu, fv;
    frame(rng, d, fu, fv);
    const float bend = kind == 2 ? 0.5f * u(rng) : small(rng);
    const float4 d1 = plus(std::cos(bend) * d, std::sin(bend) * fu);
    const float4 x[3] = {plus(base, (-l) * d), base, plus(base, (l * ratio(rng)) * d1)};
    const std::uint32_t first = static_cast<std::uint32_t>(t.now.size());
    std::uint32_t v[3];
    for (int i = 0; i < 3; ++i) v[i] = vertex(rng, t, x[i], 0.15f);
    add_thread_vertex(rng, t, v);
    if (kind == 0) displace(rng, t, first, 1e-3f * l);
    if (kind == 2) displace(rng, t, first, 1e-2f * l);
    if (kind == 3) displace(rng, t, first, 0.3f * l);
  }
  return t;
}

// ------------------------------------------------------------ edge cases

// Every guard of the CPU kernels, a constraint each: collapsed elements
// (exact zeros), fully pinned rigid ones (denominator 0), overflowing
// gradients or compliances (denominator infinite or NaN); the last one is
// healthy (padded() copies it). Rest values mostly as if the shape had been
// healthy at rest (theta0 = 0.3, A0 = 0.1, h0 = 0).
Thin area_edge_cases() {
  Thin t;
  const auto tri = [&](float4 a, float4 b, float4 c, float a0, float alpha, float lambda = kRandom) {
    t.ids.insert(t.ids.end(), {t.add(a), t.add(b), t.add(c)});
    t.data.insert(t.data.end(), {a0, alpha});
    t.lambda.push_back(lambda);
  };
  tri(p3(0, 0, 0), p3(1, 0, 0), p3(0.5f, 0, 0), 0.1f, 1e-4f);        // collinear: area exactly 0
  tri(p3(0.2f, 0.3f, 0.4f), p3(0.2f, 0.3f, 0.4f), p3(1, 1, 1), 0.1f, 0);  // two vertices coincide
  tri(p3(0, 0, 0), p3(0, 0, 0), p3(0, 0, 0), 0.1f, 1e-3f);           // a point
  tri(p3(0, 0, 0, 0), p3(1, 0, 0, 0), p3(0, 1, 0, 0), 0.4f, 0);      // all pinned, rigid: total 0
  tri(p3(0, 0, 0, 0), p3(1, 0, 0, 0), p3(0, 1, 0, 0), 0.4f, 1e-3f);  // all pinned, compliant
  tri(p3(0, 0, 0), p3(4e19f, 0, 0), p3(4e19f, 1e-10f, 0), 2e9f, 0);  // |grad|^2 overflows: total inf
  // alpha / h^2 overflows: total inf. With lambda 0 (alpha~ lambda = NaN, so no
  // infinite residual, which expect_agree cannot compare) the step would be NaN.
  tri(p3(0, 0, 0), p3(1, 0, 0), p3(0, 1.5f, 0), 0.4f, 1e36f, 0.0f);
  tri(p3(1, 2, 3, 0), p3(1.5f, 2, 3), p3(1, 2.5f, 3.25f), 0.125f, 0);  // healthy, one pinned
  return t;
}

Thin dihedral_edge_cases() {
  Thin t;
  const auto hinge = [&](float4 a, float4 b, float4 c, float4 d, float theta0, float alpha, float lambda = kRandom) {
    t.ids.insert(t.ids.end(), {t.add(a), t.add(b), t.add(c), t.add(d)});
    t.data.insert(t.data.end(), {theta0, alpha});
    t.lambda.push_back(lambda);
  };
  hinge(p3(0, 0, 0), p3(0, 0, 0), p3(0, 1, 0), p3(0, -1, 0.5f), 0.3f, 1e-3f);      // zero-length edge
  hinge(p3(0, 0, 0), p3(1, 0, 0), p3(0.5f, 0, 0), p3(0.5f, -1, 0), 0.3f, 0);       // wing 2 on the edge line
  hinge(p3(0, 0, 0), p3(1, 0, 0), p3(0.5f, 1, 0), p3(2, 0, 0), 0.3f, 1e-3f);       // wing 3 on the edge line
  hinge(p3(0, 0, 0), p3(1, 0, 0), p3(0.3f, 0.5f, 0), p3(0.6f, -0.4f, 0), 0.3f, 0);  // exactly flat (sin = 0)
  hinge(p3(0, 0, 0), p3(1, 0, 0), p3(0.3f, 0.5f, 0), p3(0.6f, -0.4f, 0), 0.0f, 0);  // exactly flat at rest
  hinge(p3(0, 0, 0), p3(1, 0, 0), p3(0.3f, 0.5f, 0), p3(0.6f, 0.4f, 0), kPi, 0);    // exactly folded (theta = +-pi)
  hinge(p3(0, 0, 0), p3(1, 0, 0), p3(0.3f, 0.5f, 0), p3(0.6f, 0.4f, 0), -kPi, 1e-3f);
  hinge(p3(0, 0, 0), p3(1, 0, 0), p3(0.3f, 0.5f, 0), p3(0.6f, 0.4f, 0), 3.0f, 1e-3f);
  hinge(p3(0, 0, 0, 0), p3(1, 0, 0, 0), p3(0.3f, 0.5f, 0, 0), p3(0.6f, -0.4f, 1, 0), 0.3f, 0);      // all pinned, rigid
  hinge(p3(0, 0, 0, 0), p3(1, 0, 0, 0), p3(0.3f, 0.5f, 0, 0), p3(0.6f, -0.4f, 1, 0), 0.3f, 1e-2f);  // all pinned
  // |e| / |N1|^2 overflows: the gradient has inf and NaN, total NaN; theta = atan2(-1, +0).
  // (No subnormal input: devices that flush them to zero would see a degenerate wing.)
  hinge(p3(0, 0, 0), p3(1e18f, 0, 0), p3(0, 1e-30f, 0), p3(0, 0, 1e-10f), 0.3f, 1e-3f);
  // The same with |e|^2 overflowing too: theta = atan2(-0, +0), which is -0 by C's
  // convention (atan2_portable's too) and undefined for GLSL's atan (lavapipe's gives
  // about -3 pi / 4).
  hinge(p3(0, 0, 0), p3(1e20f, 0, 0), p3(0, 1e-31f, 0), p3(0, 0, 1e-10f), 0.3f, 1e-3f);
  hinge(p3(0, 0, 0), p3(1, 0, 0), p3(0.3f, 0.5f, 0), p3(0.6f, -0.4f, 0.2f), 0.3f, 1e36f, 0.0f);  // total inf
  // Healthy, one wing pinned.
  hinge(p3(0.1f, 0.2f, 0.3f), p3(0.6f, 0.2f, 0.3f), p3(0.3f, 0.7f, 0.3f, 0), p3(0.2f, -0.1f, 0.5f), 0.1f, 0);
  return t;
}

Thin line_edge_cases() {
  Thin t;
  const auto vertex3 = [&](float4 a, float4 b, float4 c, float h0, float alpha, float lambda = kRandom) {
    t.ids.insert(t.ids.end(), {t.add(a), t.add(b), t.add(c)});
    t.data.insert(t.data.end(), {h0, alpha, 1.0f, 0.0f});
    t.lambda.push_back(lambda);
  };
  vertex3(p3(-1, 0, 0), p3(0, 0, 0), p3(1, 0, 0), 0.0f, 1e-3f);              // exactly at the centroid
  vertex3(p3(-1, 0, 0), p3(0, 0, 0), p3(1, 0, 0), 0.01f, 0);                 // ... with a rest offset
  vertex3(p3(0.5f, 0.5f, 0.5f), p3(0.5f, 0.5f, 0.5f), p3(0.5f, 0.5f, 0.5f), 0, 0);  // all in one point
  vertex3(p3(-1, 0, 0, 0), p3(0, 0.2f, 0, 0), p3(1, 0, 0, 0), 0.0f, 0);      // all pinned, rigid: total 0
  vertex3(p3(-1, 0, 0, 0), p3(0, 0.2f, 0, 0), p3(1, 0, 0, 0), 0.0f, 1e-3f);  // all pinned, compliant
  vertex3(p3(-1, 0, 0), p3(0, 0.2f, 0), p3(1, 0, 0), 0.0f, 1e36f, 0.0f);     // total inf
  vertex3(p3(-1, 0, 0, 0), p3(0, 0.2f, 0), p3(1, 0, 0, 0), 0.0f, 0);         // ends pinned
  return t;
}

// ------------------------------------------------------------ the cases

// Lays `t` out in buffers with particles in random order, `first` = 3 and
// five constraints after the dispatched ones (neither may change).
KernelCase thin_case(std::mt19937& rng, Kernel kernel, std::uint32_t arity, const Thin& t, bool reset, bool measure) {
  const std::uint32_t n = static_cast<std::uint32_t>(t.ids.size() / arity);
  const std::uint32_t first = 3, count = n - 8;
  std::vector<std::uint32_t> where(t.now.size());
  std::iota(where.begin(), where.end(), 0u);
  std::shuffle(where.begin(), where.end(), rng);
  std::vector<float> x(4 * t.now.size());
  for (std::size_t k = 0; k < t.now.size(); ++k)
    std::memcpy(&x[4 * where[k]], &t.now[k], sizeof(float4));
  std::vector<std::uint32_t> idx(t.ids.size());
  for (std::size_t k = 0; k < idx.size(); ++k) idx[k] = where[t.ids[k]];
  std::uniform_real_distribution<float> lam(-1e-3f, 1e-3f);
  std::vector<float> lambda(n), residual(n, 0.0f);
  for (std::uint32_t k = 0; k < n; ++k)
    lambda[k] = k < t.lambda.size() && !std::isnan(t.lambda[k]) ? t.lambda[k] : lam(rng);
  KernelCase c{kernel, count, {}, {}};
  c.bindings.push_back({x, false});
  c.bindings.push_back({as_words(idx), false});
  c.bindings.push_back({t.data, false});
  c.bindings.push_back({lambda, reset && !measure});  // written before it is read
  c.bindings.push_back({residual, measure});
  const kernels::SolveParams p{first, count, 3600.0f, reset ? 1u : 0u, 1.0f / 60.0f, 1.0f, measure ? 1u : 0u, 0};
  c.params = bytes_of(p);
  return c;
}

// Pads an edge-case set with three constraints before and five after the
// dispatched ones (copies of its last, healthy one).
Thin padded(Thin t, std::uint32_t arity) {
  const std::size_t n = t.ids.size() / arity, stride = t.data.size() / n;
  const std::vector<std::uint32_t> last_ids(t.ids.end() - arity, t.ids.end());
  const std::vector<float> last_data(t.data.end() - static_cast<std::ptrdiff_t>(stride), t.data.end());
  for (int k = 0; k < 3; ++k) {
    t.ids.insert(t.ids.begin(), last_ids.begin(), last_ids.end());
    t.data.insert(t.data.begin(), last_data.begin(), last_data.end());
    t.lambda.insert(t.lambda.begin(), kRandom);
  }
  for (int k = 0; k < 5; ++k) {
    t.ids.insert(t.ids.end(), last_ids.begin(), last_ids.end());
    t.data.insert(t.data.end(), last_data.begin(), last_data.end());
    t.lambda.push_back(kRandom);
  }
  return t;
}

// Runs every reset/measure variant of the random set and of the edge cases.
void agree_on(const std::string& backend, Kernel kernel, std::uint32_t arity,
              const std::function<Thin(std::mt19937&, std::uint32_t)>& make, const Thin& edge) {
  std::mt19937 rng(std::random_device{}());
  for (bool reset : {false, true})
    for (bool measure : {false, true}) {
      const std::string variant =
          std::string(kernel_name(kernel)) + (reset ? " reset" : "") + (measure ? " measure" : "");
      const KernelCase random = thin_case(rng, kernel, arity, make(rng, 600 + rng() % 50), reset, measure);
      const auto ref = run_on("cpu", random), gpu = run_on(backend, random);
      expect_agree(random, ref, gpu, variant);
      report_difference(random, ref, gpu, backend + " " + variant + " random");
      const KernelCase edges = thin_case(rng, kernel, arity, padded(edge, arity), reset, measure);
      const auto ref_e = run_on("cpu", edges), gpu_e = run_on(backend, edges);
      expect_agree(edges, ref_e, gpu_e, variant + " edge cases");
      report_difference(edges, ref_e, gpu_e, backend + " " + variant + " edge cases");
    }
}

TEST_P(Agreement, AreaKernel) {
  agree_on(GetParam(), Kernel::xpbd_solve_area, 3, area_constraints, area_edge_cases());
}

TEST_P(Agreement, DihedralKernel) {
  agree_on(GetParam(), Kernel::xpbd_solve_dihedral, 4, dihedral_constraints, dihedral_edge_cases());
}

TEST_P(Agreement, LineBendingKernel) {
  agree_on(GetParam(), Kernel::xpbd_solve_line_bending, 3, line_constraints, line_edge_cases());
}

}  // namespace
}  // namespace sinew::test
