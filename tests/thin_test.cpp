// Thin tissue (triangle bodies: distance, area and dihedral-bending
// constraints) and threads (Kelager bending), against physics:
//  - the constraint gradients against central differences in double, at
//    random and near-degenerate configurations (flat and folded hinges,
//    slivers, nearly straight threads);
//  - the kernels: the measuring pass changes nothing, pins are never
//    written, momentum is kept, a rigid constraint is driven to C = 0;
//  - scenes: bodies at rest stay bitwise at rest; a hinge and a thread
//    settle exactly where their compliance balances gravity (closed forms
//    below); a falling membrane keeps its area; bending keeps cantilevers
//    up and reduces the sag of a thread; a body started away from its rest
//    shape returns to it; bad input is named.
//
// Closed forms used:
//  - hinge: a wing vertex of mass m at distance r from a horizontal hinge
//    line, held by rigid edges, with dihedral compliance alpha [1/(N m)]:
//    the energy C^2 / (2 alpha) with C = the angle beta of the wing below
//    the horizontal balances gravity's torque when beta / alpha =
//    m g r cos(beta);
//  - thread: three particles, the outer two pinned a straight line apart
//    (h0 = 0), the middle one of mass m: C = |x_v - c| = (2/3) |x_v - mid|
//    and grad_v C = (2/3) n, so the constraint is a linear spring of
//    stiffness 4 / (9 alpha) and the middle sags 9 alpha m g / 4 (the
//    segments, nearly free here, add a force of order delta^3 only).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cpu/thin_kernels.h"
#include "cpu/xpbd_kernels.h"
#include "test_support.h"
#include "thin_params.h"
#include "xpbd_params.h"

namespace sinew {
namespace {

using kernels::double4;
using kernels::float4;
namespace thin = kernels::thin;

constexpr double kPi = 3.14159265358979323846;
constexpr double kEps = std::numeric_limits<double>::epsilon();

// ------------------------------------------------------------------ helpers

// A simulation of `scene` on the test's backend; every backend has the
// thin-body kernels, so a backend without one fails here.
#define THIN_SIMULATION(sim, scene)                                 \
  auto sim##_made = test::create_or_skip(scene, GetParam());        \
  ASSERT_TRUE(sim##_made.ok()) << sim##_made.error().message();     \
  Simulation& sim = *sim##_made

class Thin : public test::BackendTest {};
class Thread : public test::BackendTest {};

std::vector<float> positions(const Simulation& sim) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  return x;
}

// + 0.0 turns -0.0 into +0.0: a coordinate of -0 would become +0 after an
// update by a zero correction, so bitwise-at-rest checks start from +0.
Vec3d point(double x, double y, double z) { return {x + 0.0, y + 0.0, z + 0.0}; }

// A sheet of nx x ny cells on the parameter square [0, 1]^2 mapped to 3D by
// `at`; vertex (i, j) is i + (nx + 1) j; two triangles per cell, wound alike.
TriMesh sheet(int nx, int ny, const std::function<Vec3d(double, double)>& at) {
  TriMesh m;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.vertices.push_back(at(double(i) / nx, double(j) / ny));
  const auto id = [&](int i, int j) { return static_cast<std::uint32_t>(i + (nx + 1) * j); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
      m.triangles.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

double total_area(const std::vector<float>& x, std::uint32_t first, const TriMesh& m) {
  double a = 0.0;
  const auto p = [&](std::uint32_t v) {
    const float* q = &x[4 * (first + v)];
    return double4{q[0], q[1], q[2], 0.0};
  };
  for (const auto& t : m.triangles) a += thin::triangle_area(p(t[0]), p(t[1]), p(t[2]));
  return a;
}

// ------------------------------------------------------------------- atan2

// The ulp of the float nearest to v: 2^(e - 23) for it in [2^e, 2^(e+1)),
// 2^-149 below the normal range.
double float_ulp(double v) {
  const double a = std::abs(double(float(v)));
  if (a == 0.0) return std::ldexp(1.0, -149);
  int e;
  std::frexp(a, &e);  // a = m 2^e, m in [0.5, 1)
  return std::ldexp(1.0, std::max(e - 24, -149));
}

// C's atan2 conventions (C11 F.10.1.4), bit for bit with the C library's
// atan2 for these arguments (whose results are pi, pi/2, pi/4, 3 pi/4
// rounded, or signed zeros), and NaN in, NaN out.
template <class T>
void check_atan2_conventions() {
  const T inf = std::numeric_limits<T>::infinity(), nan = std::numeric_limits<T>::quiet_NaN();
  const auto bits = [](T v) {
    std::uint64_t b = 0;
    std::memcpy(&b, &v, sizeof v);
    return b;
  };
  const auto same = [&](T y, T x) {
    EXPECT_EQ(bits(thin::atan2_portable(y, x)), bits(std::atan2(y, x)))
        << sizeof(T) * 8 << "-bit atan2(" << y << ", " << x << ") = " << thin::atan2_portable(y, x) << ", C: "
        << std::atan2(y, x);
  };
  const T pi = thin::pi<T>;
  // Signed zeros: atan2(+-0, +0) = +-0, atan2(+-0, -0) = +-pi.
  EXPECT_EQ(bits(thin::atan2_portable(T(0), T(0))), bits(T(0)));
  EXPECT_EQ(bits(thin::atan2_portable(-T(0), T(0))), bits(-T(0)));
  EXPECT_EQ(bits(thin::atan2_portable(T(0), -T(0))), bits(pi));
  EXPECT_EQ(bits(thin::atan2_portable(-T(0), -T(0))), bits(-pi));
  EXPECT_EQ(bits(thin::atan2_portable(T(1), T(0))), bits(pi / T(2)));
  for (T s : {T(1), T(-1)})
    for (T v : {T(0), std::numeric_limits<T>::denorm_min(), std::numeric_limits<T>::min(), T(1e-20), T(1), T(3),
                T(1e20), std::numeric_limits<T>::max(), inf}) {
      same(s * v, T(0));   // +-pi/2 (+-0 for v = 0)
      same(s * v, -T(0));  // +-pi/2 (+-pi for v = 0)
      same(T(0) * s, v);   // +-0
      same(T(0) * s, -v);  // +-pi
      same(s * v, inf);    // +-0 (+-pi/4 for v = inf)
      same(s * v, -inf);   // +-pi (+-3 pi/4 for v = inf)
      same(s * inf, v);    // +-pi/2
      same(s * inf, -v);   // +-pi/2
      same(s * v, v);      // +-pi/4: equal magnitudes
      same(s * v, -v);     // +-3 pi/4
    }
  for (T v : {T(0), T(1), -T(1), inf, -inf, nan}) {
    EXPECT_TRUE(std::isnan(thin::atan2_portable(nan, v))) << v;
    EXPECT_TRUE(std::isnan(thin::atan2_portable(v, nan))) << v;
  }
}

TEST(ThinMath, PortableAtan2MatchesTheLibraryAndItsConventions) {
  // thin::atan2_portable (the dihedral angle's atan2 on every backend)
  // against the C library: float against double atan2 of the same
  // arguments, double against long double atan2, over random pairs in all
  // four quadrants: a third with exponents anywhere in +-120 (ratios from
  // overflow to underflow: results 0, pi/2, pi, subnormal), a third within
  // +-8, a third within +-1 (the ratios near 1, where the reduction's
  // roundings count most). Bounds just above the maxima measured over 2e8
  // pairs: 3.9 ulp (float), 2.2 eps relative (double).
  std::mt19937_64 rng(std::random_device{}());
  std::uniform_real_distribution<double> mantissa(1.0, 2.0);
  std::uniform_int_distribution<int> coin(0, 1);
  double max_ulp = 0.0, max_rel = 0.0;
  float worst_y = 0, worst_x = 0;
  for (int n = 0; n < 1'000'000; ++n) {
    const int span = n % 3 == 0 ? 120 : (n % 3 == 1 ? 8 : 1);
    std::uniform_int_distribution<int> exponent(-span, span);
    const auto draw = [&] { return std::ldexp(mantissa(rng), exponent(rng)) * (coin(rng) ? -1.0 : 1.0); };
    const float y = static_cast<float>(draw()), x = static_cast<float>(draw());
    const float f = thin::atan2_portable(y, x);
    const double exact = std::atan2(double(y), double(x));
    const double ulps = std::abs(double(f) - exact) / float_ulp(exact);
    if (ulps > max_ulp) max_ulp = ulps, worst_y = y, worst_x = x;
    // Odd in y, bit for bit.
    const float minus_g = -thin::atan2_portable(-y, x);
    ASSERT_EQ(std::memcmp(&minus_g, &f, sizeof f), 0) << y << ", " << x;

    const double yd = draw(), xd = draw();
    const long double exact_d = std::atan2(static_cast<long double>(yd), static_cast<long double>(xd));
    const double rel = static_cast<double>(std::abs(thin::atan2_portable(yd, xd) - exact_d) / std::abs(exact_d));
    max_rel = std::max(max_rel, rel);
  }
  std::printf("atan2_portable: float max error %.3f ulp (at y = %a, x = %a), double max %.3g relative (%.2f eps)\n",
              max_ulp, worst_y, worst_x, max_rel, max_rel / kEps);
  EXPECT_LE(max_ulp, 4.0) << "at y = " << worst_y << ", x = " << worst_x;
  // A long double reference (x87: 64 bits) adds nothing; a double one up to 1 ulp.
  EXPECT_LE(max_rel, (std::numeric_limits<long double>::digits > 53 ? 3.0 : 4.0) * kEps);

  check_atan2_conventions<float>();
  check_atan2_conventions<double>();

  // The angle of (sin theta, cos theta) on a fine grid over (-pi, pi] is
  // theta, +pi included (sin(pi) = +1.2e-16 in double), never -pi.
  constexpr int kSteps = 100'000;
  for (int k = -kSteps + 1; k <= kSteps; ++k) {
    const double theta = kPi * k / kSteps;
    const double s = std::sin(theta), c = std::cos(theta);
    const double td = thin::atan2_portable(s, c);
    ASSERT_NEAR(td, theta, 4 * kEps * std::max(1.0, std::abs(theta))) << k;
    // In float, the arguments' rounding moves the angle by up to 2^-25.
    const float tf = thin::atan2_portable(float(s), float(c));
    ASSERT_NEAR(tf, theta, 4 * float_ulp(theta) + std::ldexp(1.0, -25)) << k;
  }
  EXPECT_EQ(thin::atan2_portable(float(std::sin(kPi)), -1.0f), thin::pi<float>);
  EXPECT_EQ(thin::atan2_portable(std::sin(kPi), -1.0), kPi);
}

// ------------------------------------------- gradients against differences

double4 random_point(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng), 0.0};
}
double4 unit(double4 v) { return (1.0 / std::sqrt(dot3(v, v))) * v; }
double component(const double4& v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
void nudge(double4& v, int k, double d) { (k == 0 ? v.x : (k == 1 ? v.y : v.z)) += d; }

// Checks g[i] = grad_{x_i} f against central differences of f with step
// `step`; `wrap` wraps the difference of two values (angles) first.
template <int N, class F>
void check_gradient(F&& f, std::array<double4, N> p, const double4* g, double step, double tol, bool wrap,
                    const std::string& what) {
  for (int i = 0; i < N; ++i)
    for (int k = 0; k < 3; ++k) {
      nudge(p[i], k, step);
      const double plus = f(p);
      nudge(p[i], k, -2.0 * step);
      const double minus = f(p);
      nudge(p[i], k, step);
      const double diff = wrap ? thin::wrap_angle(plus - minus) : plus - minus;
      EXPECT_NEAR(diff / (2.0 * step), component(g[i], k), tol) << what << ": d/dx" << i << "_" << k;
    }
  // Translation invariance: the gradients sum to zero.
  double4 sum{0, 0, 0, 0};
  for (int i = 0; i < N; ++i) sum = sum + g[i];
  EXPECT_NEAR(std::sqrt(dot3(sum, sum)), 0.0, 1e-3 * tol) << what << ": gradients do not sum to 0";
}

double gradient_scale(const double4* g, int n) {
  double s = 0.0;
  for (int i = 0; i < n; ++i) s = std::max(s, std::sqrt(dot3(g[i], g[i])));
  return s;
}

void check_area(double4 x0, double4 x1, double4 x2, const std::string& what) {
  double4 g[3];
  ASSERT_TRUE(thin::triangle_area_gradients(x0, x1, x2, g)) << what;
  const auto f = [](const std::array<double4, 3>& p) { return thin::triangle_area(p[0], p[1], p[2]); };
  const double len = std::sqrt(std::max({dot3(x1 - x0, x1 - x0), dot3(x2 - x0, x2 - x0), dot3(x2 - x1, x2 - x1)}));
  // Steps relative to the triangle's height (a sliver's normal turns fast):
  // truncation ~ (step / height)^2, cancellation ~ eps |x|^2 / step (|x| <~ 2).
  const double height = 2.0 * thin::triangle_area(x0, x1, x2) / len;
  const double step = 1e-3 * height;
  check_gradient<3>(f, {x0, x1, x2}, g, step, 1e-6 * gradient_scale(g, 3) + 32 * kEps / step, false, what);
}

void check_dihedral(double4 x0, double4 x1, double4 x2, double4 x3, const std::string& what) {
  double4 g[4];
  ASSERT_TRUE(thin::dihedral_angle_gradients(x0, x1, x2, x3, g)) << what;
  const auto f = [](const std::array<double4, 4>& p) { return thin::dihedral_angle(p[0], p[1], p[2], p[3]); };
  const double edge = std::sqrt(dot3(x1 - x0, x1 - x0));
  const double h2 = std::sqrt(dot3(cross3(x1 - x0, x2 - x0), cross3(x1 - x0, x2 - x0))) / edge;
  const double h3 = std::sqrt(dot3(cross3(x1 - x0, x3 - x0), cross3(x1 - x0, x3 - x0))) / edge;
  check_gradient<4>(f, {x0, x1, x2, x3}, g, 1e-5 * std::min({h2, h3, edge}), 1e-6 * gradient_scale(g, 4), true,
                    what);
}

void check_line_bending(double4 b0, double4 v, double4 b1, const std::string& what) {
  double4 g[3];
  ASSERT_TRUE(thin::line_bending_gradients(b0, v, b1, g)) << what;
  const auto f = [](const std::array<double4, 3>& p) { return thin::line_bending_offset(p[0], p[1], p[2]); };
  // |x_v - c| is a cone at 0: steps well below the offset itself.
  const double offset = thin::line_bending_offset(b0, v, b1);
  const double step = 1e-3 * offset;
  check_gradient<3>(f, {b0, v, b1}, g, step, 1e-5 + 8 * kEps / step, false, what);
}

TEST(ThinConstraints, AreaGradientMatchesFiniteDifferences) {
  std::mt19937 rng(std::random_device{}());
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 200; ++n) {
    const double4 x0 = random_point(rng, 1.0), x1 = random_point(rng, 1.0), x2 = random_point(rng, 1.0);
    if (thin::triangle_area(x0, x1, x2) < 1e-3) continue;
    check_area(x0, x1, x2, "random triangle " + std::to_string(n));
  }
  // Slivers: the third vertex within 1e-3 .. 1e-6 of the line through the
  // first two, anywhere along it (also past its ends).
  for (double height : {1e-3, 1e-5, 1e-6})
    for (int n = 0; n < 20; ++n) {
      const double4 x0 = random_point(rng, 1.0), x1 = random_point(rng, 1.0);
      const double4 e = x1 - x0;
      const double4 side = unit(cross3(e, random_point(rng, 1.0)));
      const double4 x2 = x0 + (2.0 * u(rng) - 0.5) * e + (height * std::sqrt(dot3(e, e))) * side;
      check_area(x0, x1, x2, "sliver of relative height " + std::to_string(height));
    }
  // Collapsed to a line: no direction, and the gradient says so.
  double4 g[3];
  EXPECT_FALSE(thin::triangle_area_gradients(double4{0, 0, 0, 0}, double4{1, 1, 1, 0}, double4{2, 2, 2, 0}, g));
}

// A hinge on the edge x0 = 0, x1 = (0, 0, L) with wings at distances r2, r3
// from it, at along-edge offsets s2, s3 (fractions of L), wing 2 in the
// half-plane of +x and wing 3 rotated from the continuation of wing 2's
// half-plane (the flat position) by `fold` about the edge.
std::array<double4, 4> hinge(double L, double r2, double r3, double s2, double s3, double fold) {
  const double a = kPi + fold;  // flat: wing 3 at angle pi from wing 2
  return {double4{0, 0, 0, 0}, double4{0, 0, L, 0}, double4{r2, 0, s2 * L, 0},
          double4{r3 * std::cos(a), r3 * std::sin(a), s3 * L, 0}};
}

TEST(ThinConstraints, DihedralAngleIsTheSignedAngleBetweenTheNormals) {
  // Flat: 0; wing 3 rotated by phi about the edge: |theta| = phi, with one
  // sign for each direction; folded shut: pi.
  for (double phi : {0.0, 1e-6, 0.3, 1.0, 2.5, kPi - 1e-6}) {
    const auto p = hinge(1.0, 0.5, 0.7, 0.3, 0.6, phi);
    const auto q = hinge(1.0, 0.5, 0.7, 0.3, 0.6, -phi);
    const double tp = thin::dihedral_angle(p[0], p[1], p[2], p[3]), tq = thin::dihedral_angle(q[0], q[1], q[2], q[3]);
    EXPECT_NEAR(std::abs(tp), phi, 1e-12) << phi;
    EXPECT_NEAR(tq, -tp, 1e-12) << phi;
  }
  const auto shut = hinge(1.0, 0.5, 0.7, 0.3, 0.6, kPi);
  EXPECT_NEAR(std::abs(thin::dihedral_angle(shut[0], shut[1], shut[2], shut[3])), kPi, 1e-12);
  // Moving wing 2 along +N1 decreases theta (as the gradient says).
  auto p = hinge(1.0, 0.5, 0.7, 0.3, 0.6, 0.4);
  const double before = thin::dihedral_angle(p[0], p[1], p[2], p[3]);
  const double4 n1 = cross3(p[1] - p[0], p[2] - p[0]);
  p[2] = p[2] + 1e-3 * unit(n1);
  EXPECT_LT(thin::dihedral_angle(p[0], p[1], p[2], p[3]), before);

  // In float, atan2 keeps the angle near 0 and pi to float precision, where
  // acos(n1 . n2) would return 0 for any |theta| < ~3e-4.
  for (double phi : {1e-4, kPi - 1e-4}) {
    const auto d = hinge(0.01, 0.005, 0.007, 0.3, 0.6, phi);
    const auto f = [](const double4& v) { return float4{float(v.x), float(v.y), float(v.z), 0.0f}; };
    const float t = thin::dihedral_angle(f(d[0]), f(d[1]), f(d[2]), f(d[3]));
    EXPECT_NEAR(std::abs(double(t)), phi, 1e-6) << phi;
  }
  // wrap_angle: differences across +-pi become small.
  EXPECT_NEAR(thin::wrap_angle(kPi - 0.1 - (-kPi + 0.1)), -0.2, 1e-12);
  EXPECT_NEAR(thin::wrap_angle(-kPi + 0.1 - (kPi - 0.1)), 0.2, 1e-12);
  EXPECT_EQ(thin::wrap_angle(0.5), 0.5);
}

TEST(ThinConstraints, DihedralGradientMatchesFiniteDifferences) {
  std::mt19937 rng(std::random_device{}());
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Random hinges, in random places and orientations.
  for (int n = 0; n < 200; ++n) {
    const double4 x0 = random_point(rng, 1.0), x1 = random_point(rng, 1.0);
    const double4 x2 = random_point(rng, 1.0), x3 = random_point(rng, 1.0);
    const double4 e = x1 - x0;
    const double le = std::sqrt(dot3(e, e));
    const auto height = [&](double4 w) { return std::sqrt(dot3(cross3(e, w - x0), cross3(e, w - x0))) / le; };
    if (le < 0.1 || height(x2) < 0.05 || height(x3) < 0.05) continue;
    check_dihedral(x0, x1, x2, x3, "random hinge " + std::to_string(n));
  }
  // Flat hinges (theta = 0 exactly and nearly), nearly and fully folded
  // (theta = +-pi), with wings projecting inside and outside the edge.
  for (double fold : {0.0, 1e-9, -1e-6, 1e-3, kPi - 1e-3, -(kPi - 1e-6), kPi})
    for (int n = 0; n < 10; ++n) {
      const auto p = hinge(0.5 + u(rng), 0.1 + u(rng), 0.1 + u(rng), 2.0 * u(rng) - 0.5, 2.0 * u(rng) - 0.5, fold);
      check_dihedral(p[0], p[1], p[2], p[3], "hinge folded by " + std::to_string(fold));
    }
  // A degenerate wing: no direction.
  double4 g[4];
  EXPECT_FALSE(thin::dihedral_angle_gradients(double4{0, 0, 0, 0}, double4{0, 0, 1, 0}, double4{0, 0, 2, 0},
                                              double4{1, 0, 0, 0}, g));
}

TEST(ThinConstraints, LineBendingGradientMatchesFiniteDifferences) {
  std::mt19937 rng(std::random_device{}());
  for (int n = 0; n < 200; ++n) {
    const double4 b0 = random_point(rng, 1.0), v = random_point(rng, 1.0), b1 = random_point(rng, 1.0);
    if (thin::line_bending_offset(b0, v, b1) < 1e-2) continue;
    check_line_bending(b0, v, b1, "random " + std::to_string(n));
  }
  // Nearly straight: the middle vertex 1e-3 .. 1e-7 (of the segment length)
  // off the straight, evenly divided position.
  for (double off : {1e-3, 1e-5, 1e-7})
    for (int n = 0; n < 20; ++n) {
      const double4 b0 = random_point(rng, 1.0), b1 = random_point(rng, 1.0);
      const double4 mid = 0.5 * (b0 + b1);
      const double len = 0.5 * std::sqrt(dot3(b1 - b0, b1 - b0));
      check_line_bending(b0, mid + (off * len) * unit(random_point(rng, 1.0)), b1,
                         "nearly straight, offset " + std::to_string(off));
    }
  // Straight and evenly divided: offset 0, no direction.
  double4 g[3];
  EXPECT_EQ(thin::line_bending_offset(double4{0, 0, 0, 0}, double4{1, 0, 0, 0}, double4{2, 0, 0, 0}), 0.0);
  EXPECT_FALSE(thin::line_bending_gradients(double4{0, 0, 0, 0}, double4{1, 0, 0, 0}, double4{2, 0, 0, 0}, g));
}

// ------------------------------------------------------------------ kernels

// One constraint of one thin kernel, with its bound buffers.
struct OneConstraint {
  std::vector<float4> x;
  alignas(16) std::uint32_t idx[4] = {0, 1, 2, 3};
  alignas(16) float data[4] = {0, 0, 0, 0};
  float lambda = 0.0f;
  float residual = -1.0f;
  kernels::CpuKernelFn fn = nullptr;
  int arity = 3;

  void run(const kernels::SolveParams& p) {
    std::byte* b[5] = {reinterpret_cast<std::byte*>(x.data()), reinterpret_cast<std::byte*>(idx),
                       reinterpret_cast<std::byte*>(data), reinterpret_cast<std::byte*>(&lambda),
                       reinterpret_cast<std::byte*>(&residual)};
    fn(&p, b, 0, 1);
  }
  // C in double from the float positions, and its normalisation.
  double c() const {
    const auto d = [&](int k) { return double4{x[k].x, x[k].y, x[k].z, 0.0}; };
    if (fn == kernels::xpbd_solve_area) return thin::triangle_area(d(0), d(1), d(2)) - data[0];
    if (fn == kernels::xpbd_solve_dihedral)
      return thin::wrap_angle(thin::dihedral_angle(d(0), d(1), d(2), d(3)) - double(data[0]));
    return thin::line_bending_offset(d(0), d(1), d(2)) - data[0];
  }
  double norm() const {
    if (fn == kernels::xpbd_solve_area) return data[0];
    if (fn == kernels::xpbd_solve_dihedral) return 1.0;
    return data[2];
  }
  const char* name() const {
    return fn == kernels::xpbd_solve_area ? "area" : fn == kernels::xpbd_solve_dihedral ? "dihedral" : "line bending";
  }
};

// The three kernels on random, deformed configurations of size ~1 cm,
// masses 1e-3 .. 4e-3 kg; rest values from the undeformed positions.
std::vector<OneConstraint> random_constraints(std::mt19937& rng, float alpha) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), w(250.0f, 1000.0f);
  std::vector<OneConstraint> out(3);
  const float4 base[4] = {{0, 0, 0, 0}, {0.01f, 0, 0, 0}, {0.003f, 0.008f, 0, 0}, {0.006f, -0.009f, 0.002f, 0}};
  for (int k = 0; k < 3; ++k) {
    OneConstraint& c = out[k];
    c.fn = k == 0 ? kernels::xpbd_solve_area : k == 1 ? kernels::xpbd_solve_dihedral : kernels::xpbd_solve_line_bending;
    c.arity = k == 1 ? 4 : 3;
    for (int i = 0; i < c.arity; ++i) c.x.push_back(float4{base[i].x, base[i].y, base[i].z, w(rng)});
    if (k == 0) c.data[0] = thin::triangle_area(c.x[0], c.x[1], c.x[2]);
    if (k == 1) c.data[0] = thin::dihedral_angle(c.x[0], c.x[1], c.x[2], c.x[3]);
    if (k == 2) {
      c.x[1] = float4{0.01f, 0.001f, 0.0f, c.x[1].w};  // the middle vertex of (b0, v, b1)
      c.x[2] = float4{0.02f, 0.0f, 0.0f, c.x[2].w};
      c.data[0] = thin::line_bending_offset(c.x[0], c.x[1], c.x[2]);
      c.data[2] = 0.01f;
    }
    c.data[1] = alpha;
    for (float4& p : c.x) p = float4{p.x + 0.002f * u(rng), p.y + 0.002f * u(rng), p.z + 0.002f * u(rng), p.w};
  }
  return out;
}

TEST(ThinKernels, MeasuringPassWritesTheResidualAndChangesNothingElse) {
  std::mt19937 rng(std::random_device{}());
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (OneConstraint& c : random_constraints(rng, 1e-6f)) {
    c.lambda = 1e-3f * u(rng);
    const std::vector<float4> x = c.x;
    const float lambda = c.lambda;
    kernels::SolveParams p{};
    p.count = 1;
    p.inv_h2 = 1e4f;
    p.measure_only = 1;
    c.run(p);
    EXPECT_EQ(0, std::memcmp(x.data(), c.x.data(), x.size() * sizeof(float4))) << c.name();
    EXPECT_EQ(lambda, c.lambda) << c.name();
    const double expected = std::abs(c.c() + double(c.data[1]) * 1e4 * lambda) / c.norm();
    EXPECT_NEAR(c.residual, expected, 1e-4 * expected + 1e-6) << c.name();
  }
}

TEST(ThinKernels, RigidConstraintConvergesKeepsMomentumAndNeverWritesPins) {
  std::mt19937 rng(std::random_device{}());
  for (int pinned = -1; pinned < 3; ++pinned)
    for (OneConstraint& c : random_constraints(rng, 0.0f)) {
      if (pinned >= 0) c.x[pinned].w = 0.0f;
      const std::vector<float4> start = c.x;
      kernels::SolveParams p{};
      p.count = 1;
      p.inv_h2 = 1e6f;
      for (int it = 0; it < 20; ++it) {
        p.reset_lambda = it == 0;
        c.run(p);
      }
      const std::string what = std::string(c.name()) + ", pinned " + std::to_string(pinned);
      // Gauss-Newton on one constraint: converged to float rounding.
      EXPECT_LT(std::abs(c.c()) / c.norm(), 1e-5) << what;
      if (pinned >= 0) {
        EXPECT_EQ(0, std::memcmp(&start[pinned], &c.x[pinned], sizeof(float4))) << what;
      } else {
        // Every particle movable: sum_i m_i dx_i = sum_i grad_i C dlambda = 0.
        // Each of the 20 updates rounds the stored position to float, by up
        // to half an ulp of its coordinate however small the step: that
        // bounds the momentum the rounding alone can show (the old 1e-12
        // floor failed about 2 in 1000 random draws with tiny corrections).
        double mom[3] = {0, 0, 0}, scale = 0.0, rounding = 0.0;
        for (std::size_t i = 0; i < c.x.size(); ++i) {
          const double m = 1.0 / c.x[i].w;
          mom[0] += m * (double(c.x[i].x) - start[i].x);
          mom[1] += m * (double(c.x[i].y) - start[i].y);
          mom[2] += m * (double(c.x[i].z) - start[i].z);
          scale += m * std::hypot(double(c.x[i].x) - start[i].x, double(c.x[i].y) - start[i].y,
                                  double(c.x[i].z) - start[i].z);
          rounding += m * 20 * 0.5 * std::numeric_limits<float>::epsilon() *
                      (std::abs(double(c.x[i].x)) + std::abs(double(c.x[i].y)) + std::abs(double(c.x[i].z)));
        }
        EXPECT_LT(std::hypot(mom[0], mom[1], mom[2]), 1e-4 * scale + rounding) << what;
        EXPECT_GT(scale, 0.0) << what << ": nothing moved";
      }
    }
}

// ------------------------------------------------------------------- scenes

TEST_P(Thin, TriangleBodiesAndThreadsAtRestWithoutGravityStayBitwiseAtRest) {
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 2, .iterations = 3};
  // A curved, bumpy sheet (rest dihedral angles of both signs), rigid
  // bending and stretch; a flat one with compliant bending and two pins; a
  // nearly closed tube (a vessel wall); two hinges folded shut (rest angle
  // pi) and nearly shut; and a helix thread with rigid bending.
  TriBodyDesc bumpy;
  bumpy.mesh = sheet(8, 6, [](double u, double v) {
    return point(0.08 * u, 0.004 * std::sin(7.0 * u) * std::cos(5.0 * v) + 0.01 * u * v, 0.06 * v);
  });
  bumpy.distance_compliance = 0.0;
  bumpy.area_compliance = 0.0;
  bumpy.bending_compliance = 0.0;
  scene.tri_bodies.push_back(bumpy);
  TriBodyDesc flat;
  flat.mesh = sheet(5, 5, [](double u, double v) { return point(0.05 * u, 0.1, 0.05 * v); });
  flat.bending_compliance = 10.0;
  flat.pinned = {0, 5};
  scene.tri_bodies.push_back(flat);
  TriBodyDesc tube;
  tube.mesh = sheet(12, 4, [](double u, double v) {
    const double a = 0.999 * 2.0 * kPi * u;
    return point(0.01 * std::cos(a), 0.2 + 0.01 * std::sin(a), 0.04 * v);
  });
  tube.bending_compliance = 1.0;
  scene.tri_bodies.push_back(tube);
  for (double lift : {0.0, 1e-4}) {
    TriBodyDesc shut;
    shut.mesh.vertices = {point(0, -0.2, 0), point(0, -0.2, 0.01), point(0.005, -0.2, 0.003),
                          point(0.007, -0.2 + lift, 0.006)};
    shut.mesh.triangles = {{0, 1, 2}, {1, 0, 3}};
    shut.bending_compliance = 0.0;
    scene.tri_bodies.push_back(shut);
  }
  LineBodyDesc helix;
  for (int i = 0; i <= 30; ++i) {
    const double a = 0.4 * i;
    helix.vertices.push_back(point(0.01 * std::cos(a), -0.1 + 0.002 * i, 0.01 * std::sin(a)));
    helix.masses.push_back(1e-4);
    if (i > 0) helix.segments.push_back({std::uint32_t(i - 1), std::uint32_t(i)});
  }
  helix.bending_compliance = 0.0;
  helix.pinned = {0};
  scene.line_bodies.push_back(helix);

  THIN_SIMULATION(sim, scene);
  EXPECT_GT(sim.info().other_constraints, 0u);
  const std::vector<float> start = positions(sim);
  for (int f = 0; f < 100; ++f) SINEW_ASSERT_OK(sim.step());
  const std::vector<float> end = positions(sim);
  ASSERT_EQ(start.size(), end.size());
  EXPECT_EQ(0, std::memcmp(start.data(), end.data(), start.size() * sizeof(float)))
      << "positions changed although every constraint is at rest and there is no gravity";
  std::vector<float> v;
  SINEW_ASSERT_OK(sim.read_velocities(v));
  for (float c : v) ASSERT_EQ(c, 0.0f);
  EXPECT_EQ(sim.last_frame().max_residual, 0.0);
}

// The angle [rad] of wing vertex x3 below the horizontal hinge line along z.
double wing_angle(const std::vector<float>& x, std::uint32_t wing) {
  return std::atan2(-double(x[4 * wing + 1]), double(x[4 * wing + 0]));
}

TEST_P(Thin, HingeSettlesWhereBendingBalancesGravity) {
  // Two triangles on a hinge along z: wing (0, 1, 2) pinned, wing vertex 3
  // of mass m = rho t A / 3 at r = 5 cm from the hinge, rigid edges, so
  // only the dihedral compliance alpha resists gravity: at rest
  // beta / alpha = m g r cos(beta).
  const double r = 0.05, len = 0.1, rho = 1000.0, t = 1e-3, g = 9.81;
  const double m = rho * t * (0.5 * len * r) / 3.0;
  const double alpha = 0.5 / (m * g * r * std::cos(0.5));  // beta ~ 0.5 rad
  double beta = 0.5;  // Newton on beta - alpha m g r cos(beta) = 0
  for (int i = 0; i < 50; ++i)
    beta -= (beta - alpha * m * g * r * std::cos(beta)) / (1.0 + alpha * m * g * r * std::sin(beta));
  TriBodyDesc hinge;
  hinge.mesh.vertices = {point(0, 0, 0), point(0, 0, len), point(-r, 0, 0.5 * len), point(r, 0, 0.5 * len)};
  hinge.mesh.triangles = {{0, 1, 2}, {1, 0, 3}};
  hinge.thickness = t;
  hinge.density = rho;
  hinge.distance_compliance = 0.0;
  hinge.area_compliance = 0.0;
  hinge.bending_compliance = alpha;
  hinge.pinned = {0, 1, 2};
  SceneDesc scene;
  scene.gravity = {0.0, -g, 0.0};
  // Substeps of h = 1/600 s: xPBD linearises each constraint where the
  // substep's prediction put the wing, g h^2 below its circle, which biases
  // the balance by ~ g h^2 sin(beta) / r (2.6% at h = 1/60 s, 0.03% here).
  // Implicit Euler damps the swing (omega h ~ 0.03) within 40 s.
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 10};
  scene.tri_bodies.push_back(hinge);
  THIN_SIMULATION(sim, scene);
  for (int f = 0; f < 2400; ++f) SINEW_ASSERT_OK(sim.step());
  const std::vector<float> x = positions(sim);
  EXPECT_NEAR(wing_angle(x, 3), beta, 1e-3 * beta) << "closed form beta / alpha = m g r cos(beta)";
  EXPECT_NEAR(std::hypot(x[12], x[13]), r, 1e-5 * r) << "rigid edges keep the wing's distance from the hinge";
  for (int v = 0; v < 3; ++v)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(x[4 * v + k], float(hinge.mesh.vertices[v][k])) << "pinned vertex " << v;

  // Without bending constraints it hangs straight down.
  scene.tri_bodies[0].bending_compliance = -1.0;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 1, .iterations = 10};  // omega h ~ 1: damps fast
  THIN_SIMULATION(loose, scene);
  for (int f = 0; f < 600; ++f) SINEW_ASSERT_OK(loose.step());
  EXPECT_NEAR(wing_angle(positions(loose), 3), kPi / 2, 1e-3);
}

TEST_P(Thin, BodyStartedAwayFromItsRestShapeReturnsToIt) {
  // A hinge whose rest shape is folded by +-60 degrees starts flat
  // (initial_vertices); rigid bending and edges, no gravity: it folds back,
  // whether or not its two triangles are wound alike.
  for (bool alike : {true, false}) {
    for (double rest : {kPi / 3, -kPi / 3}) {
      const double r = 0.05, len = 0.1;
      TriBodyDesc hinge;
      hinge.mesh.vertices = {point(0, 0, 0), point(0, 0, len), point(-r, 0, 0.5 * len),
                             point(r * std::cos(rest), -r * std::sin(rest), 0.5 * len)};
      // Wound alike across the edge, or not (the angle is defined by the
      // hinge's geometry either way).
      hinge.mesh.triangles = {{0, 1, 2}, {1, 0, 3}};
      if (!alike) hinge.mesh.triangles[1] = {0, 1, 3};
      hinge.initial_vertices = hinge.mesh.vertices;
      hinge.initial_vertices[3] = point(r, 0, 0.5 * len);
      hinge.distance_compliance = 0.0;
      hinge.area_compliance = 0.0;
      hinge.bending_compliance = 0.0;
      hinge.pinned = {0, 1, 2};
      SceneDesc scene;
      scene.gravity = {0.0, 0.0, 0.0};
      scene.solver = {.time_step = 1.0 / 60.0, .substeps = 1, .iterations = 20};
      scene.tri_bodies.push_back(hinge);
      THIN_SIMULATION(sim, scene);
      EXPECT_EQ(wing_angle(positions(sim), 3), 0.0) << "it starts flat";
      for (int f = 0; f < 5; ++f) SINEW_ASSERT_OK(sim.step());
      EXPECT_NEAR(wing_angle(positions(sim), 3), rest, 1e-4)
          << "rest angle " << rest << (alike ? "" : ", triangles wound apart");
    }
  }
}

TEST_P(Thin, FallingMembranePinnedAlongOneEdgeKeepsItsArea) {
  // A 10 x 10 cm membrane (E ~ 1 MPa: c_d = c_a = 1e-6 /Pa, 1 mm thick)
  // held horizontally along one edge falls and swings for 1.5 s. Its load
  // is its weight plus the swing's centripetal force, about 3 rho g H at the
  // pinned edge, a strain of 3 rho g H / E ~ 0.3%: its area (the sum of its
  // triangles' areas, which wrinkling keeps) stays within 1% every frame
  // (0.4% measured at 10 substeps of 5 iterations, 0.1% when converged).
  const double side = 0.1;
  TriBodyDesc sheet_body;
  sheet_body.mesh = sheet(10, 10, [&](double u, double v) { return point(side * u, 0.0, side * v); });
  sheet_body.distance_compliance = 1e-6;
  sheet_body.area_compliance = 1e-6;
  for (std::uint32_t j = 0; j <= 10; ++j) sheet_body.pinned.push_back(11 * j);  // u = 0
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 5};
  scene.tri_bodies.push_back(sheet_body);
  THIN_SIMULATION(sim, scene);
  const double rest = total_area(positions(sim), 0, sheet_body.mesh);
  EXPECT_NEAR(rest, side * side, 1e-6 * side * side);
  double lowest = 0.0, worst = 0.0;
  for (int f = 0; f < 90; ++f) {
    SINEW_ASSERT_OK(sim.step());
    const std::vector<float> x = positions(sim);
    worst = std::max(worst, std::abs(total_area(x, 0, sheet_body.mesh) / rest - 1.0));
    for (std::size_t p = 0; p < x.size(); p += 4) lowest = std::min(lowest, double(x[p + 1]));
  }
  EXPECT_LT(worst, 0.01) << "largest relative area change over the run";
  EXPECT_LT(lowest, -0.8 * side) << "the membrane should have swung down";
}

// The lowest y [m] of body vertices [first, first + n) over a run of frames.
double lowest_over_run(Simulation& sim, std::uint32_t first, std::uint32_t n, int frames) {
  double lowest = 0.0;
  for (int f = 0; f < frames; ++f) {
    EXPECT_TRUE(sim.step().ok());
    const std::vector<float> x = positions(sim);
    for (std::uint32_t p = first; p < first + n; ++p) lowest = std::min(lowest, double(x[4 * p + 1]));
  }
  return lowest;
}

TEST_P(Thin, CantileverSheetDroopsLessWithBending) {
  // A 10 x 2 cm strip of 5 x 2 cells clamped (two columns of vertices
  // pinned) at one end, horizontal: without bending it swings down like
  // cloth; with rigid bending its free end stays near the horizontal over
  // the whole second; compliant bending lies in between. (Gauss-Seidel
  // spreads a hinge's correction one triangle per sweep, so the stiffness
  // that bending reaches in a fixed number of iterations falls with the
  // number of cells along the strip: with 20 cells and 4 iterations rigid
  // bending barely holds it up. See README, "Thin tissue and threads".)
  const double len = 0.1;
  TriBodyDesc strip;
  strip.mesh = sheet(5, 2, [&](double u, double v) { return point(len * u, 0.0, 0.02 * v); });
  strip.distance_compliance = 1e-6;
  strip.area_compliance = 1e-6;
  for (std::uint32_t j = 0; j <= 2; ++j) strip.pinned.insert(strip.pinned.end(), {6 * j, 6 * j + 1});
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 4};
  scene.tri_bodies.push_back(strip);
  const auto n = static_cast<std::uint32_t>(strip.mesh.vertices.size());
  THIN_SIMULATION(loose, scene);
  const double droop_loose = -lowest_over_run(loose, 0, n, 60);
  scene.tri_bodies[0].bending_compliance = 0.0;
  THIN_SIMULATION(stiff, scene);
  const double droop_stiff = -lowest_over_run(stiff, 0, n, 60);
  EXPECT_GT(droop_loose, 0.8 * len) << "without bending the strip hangs down";
  EXPECT_LT(droop_stiff, 0.05 * len) << "with rigid bending the strip stays nearly horizontal";
  scene.tri_bodies[0].bending_compliance = 100.0;
  THIN_SIMULATION(soft, scene);
  const double droop_soft = -lowest_over_run(soft, 0, n, 60);
  EXPECT_GT(droop_soft, droop_stiff);
  EXPECT_LT(droop_soft, droop_loose);
}

LineBodyDesc straight_thread(int segments, double len, double mass, double compliance, double bending) {
  LineBodyDesc t;
  for (int i = 0; i <= segments; ++i) {
    t.vertices.push_back(point(len * i / segments, 0.0, 0.0));
    t.masses.push_back(mass);
    if (i > 0) t.segments.push_back({std::uint32_t(i - 1), std::uint32_t(i)});
  }
  t.compliance = compliance;
  t.bending_compliance = bending;
  return t;
}

TEST_P(Thread, MiddleOfThreeSagsByNineAlphaMgOverFour) {
  // (See the top of this file.) Segments of compliance 1 m/N: nearly free.
  const double m = 0.01, g = 9.81, alpha = 4.5e-3;
  LineBodyDesc t = straight_thread(2, 0.2, m, 1.0, alpha);
  t.pinned = {0, 2};
  SceneDesc scene;
  scene.gravity = {0.0, -g, 0.0};
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 1, .iterations = 20};
  scene.line_bodies.push_back(t);
  THIN_SIMULATION(sim, scene);
  EXPECT_EQ(sim.info().other_constraints, 1u) << "one bending constraint, at the middle vertex";
  for (int f = 0; f < 300; ++f) SINEW_ASSERT_OK(sim.step());
  const std::vector<float> x = positions(sim);
  const double sag = 9.0 * alpha * m * g / 4.0;
  EXPECT_NEAR(-double(x[5]), sag, 0.01 * sag);
  EXPECT_NEAR(x[4], 0.1, 1e-6);
}

TEST_P(Thread, ShortRigidCantileverStaysNearlyStraight) {
  // 5 cm of thread in 5 segments, clamped (its first two vertices pinned),
  // horizontal: with rigid stretch and rigid bending it stays straight to
  // 1% of its length over a second under gravity (0.5% measured; as for
  // sheets, a longer chain of segments needs more iterations for the same
  // stiffness); without bending it falls.
  const double len = 0.05;
  LineBodyDesc t = straight_thread(5, len, 1e-4, 0.0, 0.0);
  t.pinned = {0, 1};
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 10};
  scene.line_bodies.push_back(t);
  THIN_SIMULATION(stiff, scene);
  EXPECT_LT(-lowest_over_run(stiff, 0, 6, 60), 0.01 * len);
  scene.line_bodies[0].bending_compliance = -1.0;
  THIN_SIMULATION(loose, scene);
  EXPECT_GT(-lowest_over_run(loose, 0, 6, 60), 0.7 * len);
}

TEST_P(Thread, PinnedAtBothEndsSagsLessWithBending) {
  // L = 20 cm of thread in N = 20 segments of compliance alpha = 1e-3 m/N,
  // 1 g per vertex (weight per length w), pinned at both ends at its rest
  // length. A shallow elastic string takes a parabola of sag s with
  // horizontal tension H = w L^2 / (8 s), is 8 s^2 / (3 L) longer than the
  // span, and stretches by H N alpha: s^3 = 3 N alpha w L^3 / 64 (1.9 cm).
  // The parabola and a uniform tension hold to O((s / L)^2) ~ 1%: within
  // 5%. With bending it sags less.
  const double len = 0.2, m = 1e-3, g = 9.81, alpha = 1e-3;
  const int n = 20;
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 10};
  LineBodyDesc t = straight_thread(n, len, m, alpha, -1.0);
  t.pinned = {0, std::uint32_t(n)};
  scene.line_bodies.push_back(t);
  THIN_SIMULATION(loose, scene);
  for (int f = 0; f < 300; ++f) SINEW_ASSERT_OK(loose.step());
  const double sag_loose = -double(positions(loose)[4 * (n / 2) + 1]);
  const double w = (n - 1) * m * g / len;
  const double sag = std::cbrt(3.0 * n * alpha * w * len * len * len / 64.0);
  EXPECT_NEAR(sag_loose, sag, 0.05 * sag) << "shallow elastic string";
  scene.line_bodies[0].bending_compliance = 1e-5;
  THIN_SIMULATION(stiff, scene);
  for (int f = 0; f < 300; ++f) SINEW_ASSERT_OK(stiff.step());
  const double sag_stiff = -double(positions(stiff)[4 * (n / 2) + 1]);
  EXPECT_GT(sag_stiff, 0.0);
  EXPECT_LT(sag_stiff, 0.8 * sag_loose) << "bending should carry part of the weight";
}

INSTANTIATE_TEST_SUITE_P(Backends, Thin, ::testing::ValuesIn(test::backends()), test::backend_name);
INSTANTIATE_TEST_SUITE_P(Backends, Thread, ::testing::ValuesIn(test::backends()), test::backend_name);

// ---------------------------------------------------------------- bad input

SceneDesc membrane_scene() {
  SceneDesc scene;
  TriBodyDesc body;
  body.mesh = sheet(2, 2, [](double u, double v) { return point(0.01 * u, 0.0, 0.01 * v); });
  body.bending_compliance = 0.0;
  scene.tri_bodies.push_back(body);
  scene.tri_bodies.push_back(body);
  LineBodyDesc thread = straight_thread(3, 0.03, 1e-4, 0.0, 0.0);
  scene.line_bodies.push_back(thread);
  return scene;
}

void expect_error(const std::function<void(SceneDesc&)>& spoil, const std::string& needle) {
  SceneDesc scene = membrane_scene();
  spoil(scene);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_FALSE(sim.ok()) << "expected an error mentioning '" << needle << "'";
  EXPECT_NE(sim.error().message().find(needle), std::string::npos) << sim.error().message();
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(ThinScene, ValidSceneIsAcceptedWithEveryConstraint) {
  auto sim = Simulation::create(membrane_scene(), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  // Per sheet of 2 x 2 cells: 16 edges, 8 triangles, 8 interior edges; the
  // thread: 3 segments, 2 bending vertices.
  EXPECT_EQ(sim->info().distance_constraints, 2u * 16u + 3u);
  EXPECT_EQ(sim->info().other_constraints, 2u * (8u + 8u) + 2u);
  EXPECT_EQ(sim->info().particles, 2u * 9u + 4u);
}

TEST(ThinScene, ErrorsNameTheBodyAndParameter) {
  expect_error([](SceneDesc& s) { s.tri_bodies[1].thickness = 0.0; }, "tri_bodies[1].thickness");
  expect_error([](SceneDesc& s) { s.tri_bodies[0].thickness = kNaN; }, "tri_bodies[0].thickness");
  expect_error([](SceneDesc& s) { s.tri_bodies[0].density = -1.0; }, "tri_bodies[0].density");
  expect_error([](SceneDesc& s) { s.tri_bodies[0].distance_compliance = -1e-6; }, "tri_bodies[0].distance_compliance");
  expect_error([](SceneDesc& s) { s.tri_bodies[0].area_compliance = kInf; }, "tri_bodies[0].area_compliance");
  expect_error([](SceneDesc& s) { s.tri_bodies[0].bending_compliance = kNaN; }, "tri_bodies[0].bending_compliance");
  expect_error([](SceneDesc& s) { s.tri_bodies[0].pinned = {1, 9}; }, "tri_bodies[0].pinned[1]");
  expect_error([](SceneDesc& s) { s.tri_bodies[0].initial_vertices = {{0, 0, 0}}; }, "tri_bodies[0].initial_vertices");
  expect_error([](SceneDesc& s) { s.tri_bodies[0].mesh.triangles.clear(); }, "tri_bodies[0].mesh has no triangles");
  expect_error([](SceneDesc& s) { s.tri_bodies[0].mesh.vertices[4][1] = kNaN; }, "tri_bodies[0].mesh.vertices[4]");
  expect_error([](SceneDesc& s) { s.tri_bodies[1].mesh.triangles[3] = {0, 1, 9}; },
               "tri_bodies[1].mesh.triangles[3] refers to vertex 9");
  // Degenerate: a repeated vertex, three collinear vertices.
  expect_error([](SceneDesc& s) { s.tri_bodies[0].mesh.triangles[2] = {4, 4, 5}; },
               "tri_bodies[0].mesh.triangles[2] has zero area");
  expect_error([](SceneDesc& s) { s.tri_bodies[0].mesh.triangles[2] = {0, 1, 2}; },
               "tri_bodies[0].mesh.triangles[2] has zero area");
  expect_error([](SceneDesc& s) { s.line_bodies[0].bending_compliance = kNaN; }, "line_bodies[0].bending_compliance");
  // Valid in double, but far from the origin a 10 um triangle has no area
  // in float32 positions: the compiler names the body and triangle.
  expect_error(
      [](SceneDesc& s) {
        s.tri_bodies[1].mesh.vertices = {point(1e4, 0, 0), point(1e4 + 1e-5, 0, 0), point(1e4, 1e-5, 0)};
        s.tri_bodies[1].mesh.triangles = {{0, 1, 2}};
        s.tri_bodies[1].bending_compliance = -1.0;
      },
      "tri_bodies[1].mesh: triangle 0 has no positive area in single precision");
}

TEST(ThinScene, NonManifoldEdgeGetsNoBendingAndIsAccepted) {
  // Three triangles on one edge (a T-junction, e.g. a septum meeting a
  // wall): distance and area constraints, no dihedral constraint there.
  SceneDesc scene;
  TriBodyDesc fin;
  fin.mesh.vertices = {point(0, 0, 0), point(0, 0, 0.01), point(-0.01, 0, 0.005), point(0.01, 0, 0.005),
                       point(0, 0.01, 0.005)};
  fin.mesh.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  fin.bending_compliance = 0.0;
  scene.tri_bodies.push_back(fin);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  EXPECT_EQ(sim->info().distance_constraints, 7u);
  EXPECT_EQ(sim->info().other_constraints, 3u) << "three area constraints, no dihedral one";
}

}  // namespace
}  // namespace sinew
