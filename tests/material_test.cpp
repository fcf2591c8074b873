// material_test — the linear-elastic oracle against closed forms, and
// set_elastic's edge network against the oracle on the same mesh: a bar in
// tension, a block in shear, a beam in bending (docs/materials.md).
//
// Loads are body loads (gravity, scaled per case so that strains are
// ~1e-3: linear, and thousands of float ulps); supports are pinned faces.
// "Stiffness ratio" = oracle displacement / network displacement of the
// loaded face (1: as stiff as linear elasticity, < 1: softer).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "material_cases.h"
#include "sinew/simulation.h"

namespace sinew {
namespace {

using test::MaterialCase;
using test::MaterialProblem;
using test::StaticLoads;
using test::measured;

constexpr double kE = test::kMaterialE;
constexpr double kCell = test::kMaterialCell;

TetBodyDesc body_on(const TetMesh& mesh, double nu) {
  TetBodyDesc body;
  body.mesh = mesh;
  EXPECT_TRUE(body.set_elastic(kE, nu).ok());
  return body;
}

// The oracle: a bar on rollers under uniform end traction has uniform
// stress, which constant-strain tets represent exactly: stretch F L / (E A),
// lateral contraction nu F / (E A) per unit width.
TEST(LinearElasticOracle, BarUnderEndTractionIsExact) {
  const int nx = 6, ny = 2, nz = 3;
  const double length = nx * kCell, width = ny * kCell, depth = nz * kCell, force = 3.0;
  const double nu = 0.3;
  const TetMesh mesh = test::graded_box(nx, ny, nz, kCell, 1.0, 0.0);
  StaticLoads loads;
  loads.density = 0.0;
  loads.point_forces.assign(mesh.vertices.size(), Vec3d{0, 0, 0});
  // Consistent loads of a uniform traction on the x = L face: each tet
  // face there gives a third of its force to each of its corners.
  const double traction = force / (width * depth);
  for (const auto& tet : mesh.tets)
    for (int skip = 0; skip < 4; ++skip) {
      std::uint32_t f[3];
      int n = 0;
      for (int i = 0; i < 4; ++i)
        if (i != skip) f[n++] = tet[std::size_t(i)];
      bool on_end = true;
      for (std::uint32_t v : f) on_end = on_end && std::abs(mesh.vertices[v][0] - length) < 1e-9;
      if (!on_end) continue;
      const Vec3d& a = mesh.vertices[f[0]];
      const Vec3d& b = mesh.vertices[f[1]];
      const Vec3d& c = mesh.vertices[f[2]];
      const double area = 0.5 * std::abs((b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]));
      for (std::uint32_t v : f) loads.point_forces[v][0] += traction * area / 3.0;
    }
  // Rollers on x = 0 (u_x = 0), one corner held in y and z, one in z.
  for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v)
    if (mesh.vertices[v][0] < 1e-9) loads.fixed_components.push_back({v, 0});
  loads.fixed_components.push_back({0, 1});
  loads.fixed_components.push_back({0, 2});
  loads.fixed_components.push_back({std::uint32_t((nx + 1) * ny), 2});  // (0, width, 0)
  std::string error;
  const auto u = test::solve_linear_elastic(mesh, kE, nu, loads, &error);
  ASSERT_FALSE(u.empty()) << error;
  const double strain = force / (kE * width * depth);
  EXPECT_NEAR(test::mean_displacement(mesh, u, 0, 0, length), strain * length, 1e-9 * strain * length);
  // Lateral: y = width face moves by -nu strain width relative to y = 0.
  const double lateral = test::mean_displacement(mesh, u, 1, 1, width) - test::mean_displacement(mesh, u, 1, 1, 0.0);
  EXPECT_NEAR(lateral, -nu * strain * width, 1e-6 * nu * strain * width);
  const double through = test::mean_displacement(mesh, u, 2, 2, depth) - test::mean_displacement(mesh, u, 2, 2, 0.0);
  EXPECT_NEAR(through, -nu * strain * depth, 1e-6 * nu * strain * depth);
}

// The oracle: a clamped cantilever (L/h = 10, nu = 0) under its own weight
// against Euler-Bernoulli (q L^4 / (8 E I)) plus Timoshenko's shear term
// (q L^2 / (2 kappa G A), kappa = 5/6). Linear tets are too stiff in
// bending by O(h^2), so the check is on two meshes (3 and 6 cells through
// the thickness): the error must shrink at least 2.5x (3.1x measured: not
// yet quite the asymptotic 4x), and the Richardson extrapolation
// (4 r_6 - r_3) / 3 must be within 3% of the theory (measured 0.974: the
// fully pinned end also stops the section warping that Timoshenko's
// shear term assumes free, which stiffens it a little).
TEST(LinearElasticOracle, CantileverConvergesToBeamTheory) {
  const double h = 0.02, length = 10 * h, nu = 0.0, rho = 1000.0, g = 1.0;
  const double area = h * h, inertia = h * h * h * h / 12.0, q = rho * g * area;
  const double theory = q * std::pow(length, 4) / (8.0 * kE * inertia) +
                        q * length * length / (2.0 * 5.0 / 6.0 * kE / (2.0 * (1.0 + nu)) * area);
  double ratio[2];
  for (int k = 0; k < 2; ++k) {
    const int n = 3 * (k + 1);
    const TetMesh mesh = test::graded_box(10 * n, n, n, h / n, 1.0, 0.0);
    StaticLoads loads;
    loads.density = rho;
    loads.gravity = {0.0, -g, 0.0};
    for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v)
      if (mesh.vertices[v][0] < 1e-9) loads.pinned.push_back(v);
    std::string error;
    const auto u = test::solve_linear_elastic(mesh, kE, nu, loads, &error);
    ASSERT_FALSE(u.empty()) << error;
    ratio[k] = -test::mean_displacement(mesh, u, 1, 0, length) / theory;
    std::printf("[ oracle ] cantilever, %d cells through the thickness: tip / beam theory %.4f\n", n, ratio[k]);
  }
  EXPECT_LT(ratio[0], ratio[1]);  // stiff, less so when finer
  EXPECT_GT(ratio[1], 0.85);
  EXPECT_LT(1.0 - ratio[1], (1.0 - ratio[0]) / 2.5);
  EXPECT_NEAR((4.0 * ratio[1] - ratio[0]) / 3.0, 1.0, 0.03);
}

// The singular case is an error, not a silent answer.
TEST(LinearElasticOracle, TooFewSupportsIsAnError) {
  const TetMesh mesh = test::graded_box(2, 1, 1, kCell, 1.0, 0.0);
  StaticLoads loads;
  loads.gravity = {0, -9.81, 0};
  std::string error;
  EXPECT_TRUE(test::solve_linear_elastic(mesh, kE, 0.3, loads, &error).empty());
  EXPECT_FALSE(error.empty());
}

// The network linearised at rest against the oracle, for nu from 0.2 to
// 0.45, on the regular and on the graded, jittered mesh. The bounds are
// what the fit reaches (docs/materials.md): along the axes the mean
// stiffness is exact, so the regular bar is within 2%; the graded mesh's
// nodes relax non-uniformly and it is up to 28% softer in tension; bending
// on two cells through the thickness is up to 17% softer (1-2% on a mesh
// twice as fine, where the oracle's own locking is less); the wide block
// in shear is ~30% stiffer: with its normal strains held by the supports,
// the network's normal-shear coupling adds stiffness the mean compliance
// does not show. Compliances set by hand (c_d = 1/E) are 3.4x too soft in
// bending and 9x in shear on these meshes.
TEST(Material, SetElasticAgainstTheOracleOnTheSameMesh) {
  for (bool graded : {false, true})
    for (double nu : {0.2, 0.3, 0.45})
      for (MaterialCase c : {MaterialCase::stretch, MaterialCase::bend, MaterialCase::shear}) {
        const MaterialProblem p = test::material_problem(c, graded);
        std::string error;
        const auto oracle = test::solve_linear_elastic(p.mesh, kE, nu, p.loads, &error);
        ASSERT_FALSE(oracle.empty()) << error;
        const auto network = test::solve_network(p.mesh, test::body_springs(body_on(p.mesh, nu)), p.loads, &error);
        ASSERT_FALSE(network.empty()) << error;
        const double ratio = measured(p, oracle) / measured(p, network);
        std::printf("[ material ] %s nu %.2f %-7s: stiffness ratio %.3f\n", graded ? "graded " : "regular", nu,
                    test::case_name(c), ratio);
        const double low = c == MaterialCase::stretch ? (graded ? 0.68 : 0.98) : c == MaterialCase::bend ? 0.82 : 1.2;
        const double high = c == MaterialCase::stretch ? 1.02 : c == MaterialCase::bend ? 1.0 : 1.36;
        EXPECT_GE(ratio, low) << test::case_name(c) << " nu " << nu << (graded ? " graded" : " regular");
        EXPECT_LE(ratio, high) << test::case_name(c) << " nu " << nu << (graded ? " graded" : " regular");
      }
}

// effective_moduli: what set_elastic asked for, along the axes; and the
// hand-set network's modulus, about a quarter of 1 / c_d on a grid.
TEST(Material, EffectiveModuliReportWhatTheBodyGot) {
  for (double nu : {0.2, 0.3, 0.45}) {
    const auto m = effective_moduli(body_on(test::graded_box(8, 2, 2, kCell, 1.0, 0.0), nu));
    ASSERT_TRUE(m.ok()) << m.error().message();
    EXPECT_NEAR(m->young / kE, 1.0, 0.01) << nu;
    EXPECT_NEAR(m->poisson, nu, 0.01) << nu;
    EXPECT_NEAR(m->shear / (kE / (2.0 * (1.0 + nu))), 1.0, 0.01) << nu;
  }
  TetBodyDesc by_hand;
  by_hand.mesh = test::graded_box(8, 2, 2, kCell, 1.0, 0.0);
  by_hand.distance_compliance = 1.0 / kE;
  by_hand.volume_compliance = 3.0 * (1.0 - 2.0 * 0.3) / kE;
  const auto old = effective_moduli(by_hand);
  ASSERT_TRUE(old.ok());
  EXPECT_GT(old->young / kE, 0.2);
  EXPECT_LT(old->young / kE, 0.3);
  by_hand.distance_compliance = 0.0;
  EXPECT_FALSE(effective_moduli(by_hand).ok());
}

TEST(Material, PoissonRatioTheNetworkCannotReachIsAnError) {
  TetBodyDesc body;
  const Status s = body.set_elastic(kE, 0.1);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message().find("poisson_ratio"), std::string::npos);
  EXPECT_FALSE(body.calibrated_network);
  EXPECT_FALSE(body.set_elastic(kE, 0.5).ok());
  EXPECT_TRUE(body.set_elastic(kE, 0.2).ok());
}

// The xPBD body on the CPU backend, run to its statics, against the
// linearised network it compiles to: the compiler's alphas are the fit's.
TEST(Material, XpbdBodyConvergesToTheNetworksStatics) {
  for (MaterialCase c : {MaterialCase::stretch, MaterialCase::bend}) {
    const MaterialProblem p = test::material_problem(c, false);
    FrameStats last;
    std::string error;
    const auto u = test::xpbd_statics(p, body_on(p.mesh, 0.3), &last, &error);
    ASSERT_FALSE(u.empty()) << error;
    EXPECT_EQ(last.stop, SolveStop::converged) << test::case_name(c);
    const auto network = test::solve_network(p.mesh, test::body_springs(body_on(p.mesh, 0.3)), p.loads, &error);
    const auto oracle = test::solve_linear_elastic(p.mesh, kE, 0.3, p.loads, &error);
    const double xpbd = measured(p, u), lin = measured(p, network), fe = measured(p, oracle);
    std::printf("[ material ] xPBD %s: %.5e m, linearised network %.5e m, oracle %.5e m\n", test::case_name(c), xpbd, lin, fe);
    EXPECT_NEAR(xpbd / lin, 1.0, 0.03) << test::case_name(c);
  }
}

}  // namespace
}  // namespace sinew
