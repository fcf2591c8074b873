// fem_agreement_test.cpp — the fem kernels on every GPU backend against the
// CPU reference, kernel by kernel (see agreement_support.h).
//
// xpbd_solve_neo_hookean, xpbd_solve_stvk and xpbd_solve_corotational
// (kernels/cpu/fem_kernels.cpp; GPU twins kernels/gpu/NAME.gpu, compiled to
// OpenCL C and SPIR-V),
// one dispatch each of one colour of random tets, fresh inputs each run:
// per-tet data built as src/compiler/compile_fem.cpp builds it (Dm^-1 from the
// float rest positions in double, rest volume, compliances from random E and
// nu, h0 per model), deformed near rest, rotated, stretched, strongly
// compressed, inverted, nearly flat, and the guard cases of the kernel
// (collapsed to a point, collapsed onto a line with rigid constraints:
// det = 0, all four vertices pinned with rigid constraints: total = 0, an
// inverse mass so large that total overflows); pinned vertices, realistic
// inverse masses and multipliers; plain, reset, measuring and reset +
// measuring passes. Every output the kernel may write is NaN-poisoned
// first (the residual always: outside a measuring pass it must stay
// untouched). Tolerance: expect_agree's 1e-5 relative; the twins use the
// CPU kernels' operation order without contraction, so the results are
// expected bitwise equal, and each case prints how many words differ.
#include <array>
#include <cstdio>

#include "agreement_support.h"
#include "fem_params.h"

namespace sinew::test {
namespace {

using V3 = std::array<double, 3>;
using M3 = std::array<V3, 3>;  // m[row][column]

M3 mul(const M3& a, const M3& b) {
  M3 c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[i][j] += a[i][k] * b[k][j];
  return c;
}

V3 times(const M3& a, const V3& v) {
  V3 r{};
  for (int i = 0; i < 3; ++i) r[i] = a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2];
  return r;
}

M3 diag(double a, double b, double c) { return M3{V3{a, 0, 0}, V3{0, b, 0}, V3{0, 0, c}}; }

M3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double q0 = gauss(rng), q1 = gauss(rng), q2 = gauss(rng), q3 = gauss(rng);
  const double n = std::sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3);
  const double w = q0 / n, x = q1 / n, y = q2 / n, z = q3 / n;
  return M3{V3{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
            V3{2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
            V3{2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
}

// The material of a kernel, as compile_fem.cpp turns E and nu into
// alpha = 1 / (stiffness V) and h0.
struct Material {
  double stiff_d, stiff_h, h0;
};
Material material(Kernel kernel, double young, double nu) {
  const double mu = young / (2.0 * (1.0 + nu));
  const double lame = young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  if (kernel == Kernel::xpbd_solve_neo_hookean) return {mu, lame + mu, 1.0 + mu / (lame + mu)};
  return {2.0 * mu, lame, kernel == Kernel::xpbd_solve_stvk ? 1.0 : 3.0};
}

// One tet's data row (fem_params.h) from its float rest positions, exactly as
// compile_fem.cpp computes it; false where the scene compiler would reject
// the tet (not positive or too ill-conditioned in float).
bool tet_row(const std::array<float4, 4>& rest, const Material& m, float row[SINEW_FEM_DATA_STRIDE]) {
  double dm[3][3];
  for (int k = 0; k < 3; ++k) {
    dm[0][k] = double(rest[k + 1].x) - double(rest[0].x);
    dm[1][k] = double(rest[k + 1].y) - double(rest[0].y);
    dm[2][k] = double(rest[k + 1].z) - double(rest[0].z);
  }
  const double det = dm[0][0] * (dm[1][1] * dm[2][2] - dm[1][2] * dm[2][1]) -
                     dm[0][1] * (dm[1][0] * dm[2][2] - dm[1][2] * dm[2][0]) +
                     dm[0][2] * (dm[1][0] * dm[2][1] - dm[1][1] * dm[2][0]);
  if (!(det > 0.0)) return false;
  double inv[3][3], norm_dm = 0.0, norm_inv = 0.0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    inv[i][0] = (dm[1][j] * dm[2][k] - dm[2][j] * dm[1][k]) / det;
    inv[i][1] = (dm[2][j] * dm[0][k] - dm[0][j] * dm[2][k]) / det;
    inv[i][2] = (dm[0][j] * dm[1][k] - dm[1][j] * dm[0][k]) / det;
  }
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      norm_dm += dm[r][c] * dm[r][c];
      norm_inv += inv[r][c] * inv[r][c];
    }
  if (!(std::sqrt(norm_dm * norm_inv) < 1e5)) return false;
  const double volume = det / 6.0;
  std::fill(row, row + SINEW_FEM_DATA_STRIDE, 0.0f);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) row[SINEW_FEM_DM_INV + 3 * r + c] = static_cast<float>(inv[r][c]);
  row[SINEW_FEM_REST_VOLUME] = static_cast<float>(volume);
  row[SINEW_FEM_ALPHA_D] = static_cast<float>(1.0 / (m.stiff_d * volume));
  row[SINEW_FEM_ALPHA_H] = static_cast<float>(1.0 / (m.stiff_h * volume));
  row[SINEW_FEM_H0] = static_cast<float>(m.h0);
  return true;
}

// What is done to a tet's rest shape (x_i = c + F (X_i - X_0), F below).
enum class Shape {
  near_rest,     // R (I + 0.05 G): strains of a few percent, any rotation
  at_rest,       // the rest positions themselves (F = I up to rounding)
  large,         // F with Gaussian entries: large strains, either sign of det
  stretched,     // R diag(s) Q, s in [1.5, 3]
  compressed,    // R diag(s) Q, s in [0.05, 0.3]: volume 1e-4 to 3e-2 of rest
  inverted,      // R diag(s1, s2, -s3) Q, s in [0.3, 1.5]
  nearly_flat,   // R diag(s1, s2, +-1e-4) Q
  point,         // all four vertices at one point (F = 0)
  line_rigid,    // on one axis-aligned line (cof F = 0, <b', b'> = 0), alpha = 0: det = 0
  pinned_rigid,  // all four pinned, alpha = 0: total = 0
  heavy_w,       // one inverse mass of 3e38: total overflows to inf
};
constexpr Shape kShapes[] = {Shape::near_rest, Shape::near_rest, Shape::near_rest, Shape::at_rest,
                             Shape::large,     Shape::large,     Shape::stretched, Shape::compressed,
                             Shape::compressed, Shape::inverted, Shape::inverted,  Shape::nearly_flat,
                             Shape::point,     Shape::line_rigid, Shape::pinned_rigid, Shape::heavy_w};

// `count` tets of `kernel` from `first` on (plus some before and after that
// the dispatch must leave alone), one colour: no two share a particle.
KernelCase fem_case(std::mt19937& rng, Kernel kernel, std::uint32_t count, bool reset, bool measure) {
  std::uniform_real_distribution<double> unit(0.0, 1.0), centre(-1.0, 1.0), nu_nh(-0.3, 0.49), nu_pos(0.05, 0.49);
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(rng)); };
  const double h = log_uniform(1e-4, 1.0 / 60.0);
  const float inv_h2 = static_cast<float>(1.0 / (h * h));
  const std::uint32_t first = 3, total = first + count + 5;
  const std::vector<std::uint32_t> idx = one_colour(rng, total, 4);
  std::vector<float> x(4 * 4 * total), data, lambda;
  for (std::uint32_t t = 0; t < total; ++t) {
    const Shape shape = kShapes[rng() % std::size(kShapes)];
    const Material m =
        material(kernel, log_uniform(1e3, 1e7), kernel == Kernel::xpbd_solve_neo_hookean ? nu_nh(rng) : nu_pos(rng));
    const double cell = log_uniform(2e-3, 0.1), density = log_uniform(100.0, 3000.0);
    // A well-shaped rest tet of edge ~ cell, at a random place.
    std::array<float4, 4> rest;
    float row[SINEW_FEM_DATA_STRIDE];
    for (;;) {
      const V3 c0{centre(rng), centre(rng), centre(rng)};
      V3 p[4];
      for (V3& q : p) q = {c0[0] + cell * centre(rng), c0[1] + cell * centre(rng), c0[2] + cell * centre(rng)};
      V3 e[3];
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a) e[k][a] = p[k + 1][a] - p[0][a];
      const double vol = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                         e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                         e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
      auto len = [](const V3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); };
      if (!(vol > 0.2 * len(e[0]) * len(e[1]) * len(e[2]))) continue;
      for (int k = 0; k < 4; ++k)
        rest[k] = {static_cast<float>(p[k][0]), static_cast<float>(p[k][1]), static_cast<float>(p[k][2]), 0.0f};
      if (tet_row(rest, m, row)) break;
    }
    if (shape == Shape::line_rigid || shape == Shape::pinned_rigid) row[SINEW_FEM_ALPHA_D] = row[SINEW_FEM_ALPHA_H] = 0.0f;
    data.insert(data.end(), row, row + SINEW_FEM_DATA_STRIDE);

    // Deformed positions.
    M3 f = diag(1, 1, 1);
    auto sv = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
    switch (shape) {
      case Shape::near_rest: {
        M3 g;
        for (auto& r : g)
          for (double& v : r) v = 0.05 * gauss(rng);
        for (int a = 0; a < 3; ++a) g[a][a] += 1.0;
        f = mul(random_rotation(rng), g);
        break;
      }
      case Shape::large:
        for (auto& r : f)
          for (double& v : r) v = gauss(rng);
        break;
      case Shape::stretched:
        f = mul(random_rotation(rng), mul(diag(sv(1.5, 3), sv(1.5, 3), sv(1.5, 3)), random_rotation(rng)));
        break;
      case Shape::compressed:
        f = mul(random_rotation(rng), mul(diag(sv(0.05, 0.3), sv(0.05, 0.3), sv(0.05, 0.3)), random_rotation(rng)));
        break;
      case Shape::inverted:
        f = mul(random_rotation(rng), mul(diag(sv(0.3, 1.5), sv(0.3, 1.5), -sv(0.3, 1.5)), random_rotation(rng)));
        break;
      case Shape::nearly_flat:
        f = mul(random_rotation(rng),
                mul(diag(sv(0.5, 1.5), sv(0.5, 1.5), (rng() % 2 ? 1e-4 : -1e-4) * sv(0.5, 1.0)), random_rotation(rng)));
        break;
      case Shape::point: f = diag(0, 0, 0); break;
      default: break;
    }
    const V3 shift{0.1 * gauss(rng), 0.1 * gauss(rng), 0.1 * gauss(rng)};
    const double w_tet = 4.0 / (density * double(row[SINEW_FEM_REST_VOLUME]));  // a quarter of the mass each
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t pi = idx[4 * t + k];
      float4 q = rest[k];
      if (shape == Shape::line_rigid) {
        // On the line through x0 along x: Ds has zero y and z rows.
        q = {rest[0].x + static_cast<float>(cell * centre(rng)), rest[0].y, rest[0].z, 0.0f};
      } else if (shape != Shape::at_rest) {
        const V3 d = times(f, V3{double(rest[k].x) - rest[0].x, double(rest[k].y) - rest[0].y,
                                 double(rest[k].z) - rest[0].z});
        q = {static_cast<float>(rest[0].x + shift[0] + d[0]), static_cast<float>(rest[0].y + shift[1] + d[1]),
             static_cast<float>(rest[0].z + shift[2] + d[2]), 0.0f};
      }
      // Inverse masses with some spread, ~1 in 7 pinned.
      float w = static_cast<float>(w_tet * sv(0.5, 2.0));
      if (rng() % 7 == 3 || shape == Shape::pinned_rigid) w = 0.0f;
      if (shape == Shape::heavy_w && k == 1) w = 3e38f;
      q.w = w;
      std::memcpy(&x[4 * pi], &q, sizeof q);
    }
    // Multipliers of the size a substep reaches: |alpha~ lambda| ~ |C|.
    for (int k : {SINEW_FEM_ALPHA_D, SINEW_FEM_ALPHA_H}) {
      const double alpha_t = double(row[k]) * inv_h2;
      lambda.push_back(static_cast<float>(centre(rng) * (alpha_t > 0.0 ? 2.0 / alpha_t : 1e-3)));
    }
    // Corotational tets keep a rotation (fem_params.h): none yet (zero,
    // the exact rotation is taken), or a unit quaternion to refine.
    if (kernel == Kernel::xpbd_solve_corotational) {
      double q[4] = {gauss(rng), gauss(rng), gauss(rng), gauss(rng)};
      const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      const bool kept = rng() % 3 != 0;
      for (double c : q) lambda.push_back(kept ? static_cast<float>(c / len) : 0.0f);
    }
  }
  KernelCase c{kernel, count, {}, {}};
  c.bindings.push_back({x, false});
  c.bindings.push_back({as_words(idx), false});
  c.bindings.push_back({data, false});
  c.bindings.push_back({lambda, reset});                         // not read after a reset
  c.bindings.push_back({std::vector<float>(total, 0.0f), true});  // written in a measuring pass only
  kernels::SolveParams p{first, count, inv_h2, reset ? 1u : 0u, static_cast<float>(h), 1.0f, measure ? 1u : 0u, 0};
  c.params = bytes_of(p);
  return c;
}

// expect_agree's tolerance is relative to the largest value of a whole
// binding, which here is loose: the position binding holds the inverse
// masses too (up to 1e8 1/kg, and 3e38), and multipliers of different tets
// span many decades. So every word is also held to 1e-5 of its own scale:
// a moved coordinate to 1e-5 of its displacement (plus 2 ulp of the
// position), a multiplier to 1e-5 of the larger of its old and new values,
// a residual to 1e-5 of itself; inverse masses, indices, per-tet data and
// whatever the kernel must not write, exactly.
void expect_agree_per_word(const KernelCase& c, const std::vector<std::vector<float>>& ref,
                           const std::vector<std::vector<float>>& gpu, const std::string& what) {
  ASSERT_EQ(ref.size(), c.bindings.size());
  ASSERT_EQ(gpu.size(), c.bindings.size());
  auto ulp = [](float v) { return std::nextafter(std::abs(v), std::numeric_limits<float>::infinity()) - std::abs(v); };
  for (std::size_t b = 0; b < ref.size(); ++b) {
    ASSERT_EQ(ref[b].size(), gpu[b].size());
    for (std::size_t i = 0; i < ref[b].size(); ++i) {
      const float r = ref[b][i], g = gpu[b][i], in = c.bindings[b].data[i];
      if (std::isnan(r) && std::isnan(g)) continue;
      ASSERT_EQ(std::isnan(r), std::isnan(g)) << what << ": binding " << b << " word " << i << ": " << g << " vs " << r;
      float tol = 0.0f;
      if (b == 0 && i % 4 != 3) tol = 1e-5f * std::abs(r - in) + 2.0f * ulp(r);
      else if (b == 3) tol = 1e-5f * std::max(std::abs(r), c.bindings[b].output_only ? 0.0f : std::abs(in));
      else if (b == 4) tol = 1e-5f * std::abs(r);
      if (tol == 0.0f)
        ASSERT_EQ(g, r) << what << ": binding " << b << " word " << i;
      else
        ASSERT_NEAR(g, r, tol) << what << ": binding " << b << " word " << i << " (input " << in << ")";
    }
  }
}

TEST_P(Agreement, FemKernels) {
  std::mt19937 rng(std::random_device{}());
  for (Kernel kernel : {Kernel::xpbd_solve_neo_hookean, Kernel::xpbd_solve_stvk, Kernel::xpbd_solve_corotational}) {
    for (bool reset : {false, true}) {
      for (bool measure : {false, true}) {
        const KernelCase c = fem_case(rng, kernel, 600 + rng() % 50, reset, measure);
        const std::string what =
            std::string(kernel_name(kernel)) + (reset ? " reset" : "") + (measure ? " measure" : "");
        const auto ref = run_on("cpu", c), gpu = run_on(GetParam(), c);
        expect_agree(c, ref, gpu, what);
        expect_agree_per_word(c, ref, gpu, what);
        report_difference(c, ref, gpu, GetParam() + " " + what);
      }
    }
  }
}

// The CPU backend's AVX2 Neo-Hookean and StVK solves (fem_kernels_avx2.cpp)
// against its scalar reference on the same random cases (every shape above:
// near rest, stretched, inverted, flat, collapsed to a point, rigid, pinned,
// huge inverse masses), split over 1 and 2 threads: every word of positions,
// multipliers and residuals bitwise equal. Counts not multiples of 8 leave
// a scalar tail in each chunk.
// Corotational: a third of fem_case's tets keep no rotation yet, so few
// groups of eight run the AVX2 path; `all_kept` gives every tet a kept
// unit quaternion (one fixed turn, far from most tets' rotation: the
// Newton step's fallback branch runs too) so that every group does.
TEST(CpuSimdFem, SolvesAreBitwiseTheScalarOnes) {
  std::mt19937 rng(std::random_device{}());
  for (Kernel kernel : {Kernel::xpbd_solve_neo_hookean, Kernel::xpbd_solve_stvk, Kernel::xpbd_solve_corotational}) {
    for (bool reset : {false, true}) {
      for (int variant = 0; variant < (kernel == Kernel::xpbd_solve_corotational ? 4 : 2); ++variant) {
        const bool measure = variant % 2 == 1, all_kept = variant >= 2;
        KernelCase c = fem_case(rng, kernel, 600 + rng() % 50, reset, measure);
        if (all_kept) {
          auto& lambda = c.bindings[3].data;
          for (std::size_t t = 0; t + SINEW_FEM_COROTATIONAL_LAMBDA_STRIDE <= lambda.size();
               t += SINEW_FEM_COROTATIONAL_LAMBDA_STRIDE) {
            float* q = &lambda[t + SINEW_FEM_ROTATION];
            if (q[0] == 0.0f && q[1] == 0.0f && q[2] == 0.0f && q[3] == 0.0f) q[0] = q[1] = q[2] = q[3] = 0.5f;
          }
        }
        const auto scalar = run_on("cpu", c, false, 1);
        for (int threads : {1, 2}) {
          const auto simd = run_on("cpu", c, true, threads);
          ASSERT_EQ(scalar.size(), simd.size());
          for (std::size_t b = 0; b < scalar.size(); ++b)
            EXPECT_EQ(0, std::memcmp(scalar[b].data(), simd[b].data(), scalar[b].size() * 4))
                << kernel_name(kernel) << (reset ? " reset" : "") << (measure ? " measure" : "")
                << (all_kept ? " all kept" : "") << ", binding " << b
                << ", " << threads << " threads";
        }
      }
    }
  }
}

}  // namespace
}  // namespace sinew::test
