// FEM tet materials (TetMaterial: neo_hookean, stvk, corotational), against
// physics: the exact uniaxial-stretch relations of stable Neo-Hookean, the
// small-strain E and nu of every model, a bar hanging under its own weight,
// inverted tets recovering, a body at rest staying at rest; and
// finite-difference checks of every constraint gradient.
//
// Notation: F deformation gradient, J = det F, mu and lambda the Lame
// parameters of E and nu, lambda' = lambda + mu, gamma = 1 + mu / lambda'.
//
// Stable Neo-Hookean in uniaxial stretch (the energy of Macklin & Müller
// 2021, Psi = mu/2 (|F|^2 - 3) + lambda'/2 (J - gamma)^2), F = diag(s, t, t):
//   P = dPsi/dF = mu F + lambda' (J - gamma) cof F,  cof F = diag(t^2, s t, s t).
//   Traction-free sides, P22 = mu t + lambda' (J - gamma) s t = 0, give
//     lambda' (J - gamma) = -mu / s,                                   (1)
//   so J = s t^2 = gamma - mu / (lambda' s), i.e.
//     t^2 = (1 + (mu / lambda') (1 - 1 / s)) / s,                      (2)
//   and the nominal (first Piola-Kirchhoff) axial stress is, with (1),
//     P11 = mu s + lambda' (J - gamma) t^2 = mu (s - t^2 / s) = mu (s - J / s^2).   (3)
//   The axial force is P11 A0 (A0 the rest cross-section) in every section.
//   Check at small strain s = 1 + e: t = 1 - nu e and P11 = E e to first
//   order, with nu = (1 - mu/lambda') / 2 = lambda / (2 (lambda + mu)) and
//   E = mu (3 - mu/lambda') = mu (3 lambda + 2 mu) / (lambda + mu).
//
// The static tests reach equilibrium by dynamic relaxation with kinetic
// damping (relax() below): xPBD frames, restarted at rest from the current
// positions whenever the kinetic energy has passed a peak.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "cpu/fem_kernels.h"
#include "fem_params.h"
#include "test_support.h"
#include "xpbd_params.h"

namespace sinew {
namespace {

using kernels::double4;
using kernels::float4;
using kernels::fem::mat3;
using M3 = mat3<double>;

// ------------------------------------------------------------------ helpers

class Fem : public test::BackendTest {};

// A simulation of `scene` on the test's backend, or a failure (every
// backend has the FEM kernels: kernels/gpu/NAME.gpu, compiled to OpenCL C
// and SPIR-V, twin kernels/cpu/fem_kernels.cpp, tests/fem_agreement_test.cpp
// compares them).
#define FEM_SIMULATION(sim, scene)                                \
  auto sim##_made = test::create_or_skip(scene, GetParam());      \
  ASSERT_TRUE(sim##_made.ok()) << sim##_made.error().message();   \
  Simulation& sim = *sim##_made

std::vector<float> positions(const Simulation& sim) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  return x;
}

const char* model_name(TetMaterial m) {
  switch (m) {
    case TetMaterial::neo_hookean: return "neo_hookean";
    case TetMaterial::stvk: return "stvk";
    case TetMaterial::corotational: return "corotational";
    case TetMaterial::none: break;
  }
  return "none";
}

constexpr TetMaterial kModels[] = {TetMaterial::neo_hookean, TetMaterial::stvk, TetMaterial::corotational};

struct Lame {
  double mu, lambda;
};
Lame lame(double young, double nu) {
  return {young / (2.0 * (1.0 + nu)), young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))};
}

M3 mul(const M3& a, const M3& b) {
  M3 c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c.m[i][j] += a.m[i][k] * b.m[k][j];
  return c;
}
M3 transpose(const M3& a) {
  M3 t{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t.m[i][j] = a.m[j][i];
  return t;
}
double det3(const M3& a) {
  const auto& m = a.m;
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}
// Inverse by cofactors (written out here, independent of the library).
M3 inverse(const M3& a) {
  const auto& m = a.m;
  const double d = det3(a);
  M3 r{};
  r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / d;
  r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / d;
  r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / d;
  r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / d;
  r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / d;
  r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / d;
  r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / d;
  r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / d;
  r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / d;
  return r;
}
// cof F = det(F) F^-T (F invertible).
M3 cof(const M3& f) {
  const M3 it = transpose(inverse(f));
  M3 c{};
  const double d = det3(f);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.m[i][j] = d * it.m[i][j];
  return c;
}

// Edge matrix [x1 - x0, x2 - x0, x3 - x0] (columns) of four points.
template <class P>
M3 edge_matrix(const P& p0, const P& p1, const P& p2, const P& p3) {
  const P* q[3] = {&p1, &p2, &p3};
  M3 d{};
  for (int k = 0; k < 3; ++k)
    for (int r = 0; r < 3; ++r) d.m[r][k] = double((*q[k])[r]) - double(p0[r]);
  return d;
}

// F of tet t of `mesh` at float positions xyzw, in double.
M3 deformation_of(const TetMesh& mesh, const std::array<std::uint32_t, 4>& t, const std::vector<float>& x,
                  std::uint32_t first = 0) {
  const M3 dm = edge_matrix(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]], mesh.vertices[t[3]]);
  auto at = [&](int k) {
    const std::size_t i = 4 * std::size_t{first + t[k]};
    return std::array<double, 3>{x[i], x[i + 1], x[i + 2]};
  };
  return mul(edge_matrix(at(0), at(1), at(2), at(3)), inverse(dm));
}

// First Piola-Kirchhoff stress P = dPsi/dF of each model's energy as
// scene.h documents it, written out independently of the kernels (only the
// corotational rotation comes from the library; RotationPart checks it).
M3 piola(TetMaterial model, const M3& f, const Lame& l) {
  M3 p{};
  const double j = det3(f);
  if (model == TetMaterial::neo_hookean) {
    // Psi = mu/2 |F|^2 + lambda'/2 (J - gamma)^2
    const double lp = l.lambda + l.mu, gamma = 1.0 + l.mu / lp;
    const M3 c = cof(f);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) p.m[a][b] = l.mu * f.m[a][b] + lp * (j - gamma) * c.m[a][b];
  } else if (model == TetMaterial::stvk) {
    // Psi = mu |E|^2 + lambda/2 (J - 1)^2, E = (F^T F - I)/2: P = 2 mu F E + lambda (J - 1) cof F
    M3 e = mul(transpose(f), f);
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) e.m[a][b] *= 0.5;
      e.m[a][a] -= 0.5;
    }
    const M3 fe = mul(f, e), c = cof(f);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) p.m[a][b] = 2.0 * l.mu * fe.m[a][b] + l.lambda * (j - 1.0) * c.m[a][b];
  } else {
    // Psi = mu |F - R|^2 + lambda/2 (tr(R^T F) - 3)^2: P = 2 mu (F - R) + lambda (tr(R^T F) - 3) R
    const M3 r = kernels::fem::rotation_part(f);
    double tr = 0.0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) tr += r.m[a][b] * f.m[a][b];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) p.m[a][b] = 2.0 * l.mu * (f.m[a][b] - r.m[a][b]) + l.lambda * (tr - 3.0) * r.m[a][b];
  }
  return p;
}

// Sum over the vertices in `set` of the gradient of the body's elastic
// energy (the sum over tets of V Psi(F)), in double from float positions.
// At a static equilibrium without gravity this is minus the force the
// pins of `set` exert on the body.
std::array<double, 3> energy_gradient_sum(TetMaterial model, const Lame& l, const TetMesh& mesh,
                                          const std::vector<float>& x, const std::vector<bool>& set) {
  std::array<double, 3> sum{0, 0, 0};
  for (const auto& t : mesh.tets) {
    if (!(set[t[0]] || set[t[1]] || set[t[2]] || set[t[3]])) continue;
    const M3 dm = edge_matrix(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]], mesh.vertices[t[3]]);
    const M3 dm_inv = inverse(dm);
    const double volume = det3(dm) / 6.0;
    // dE/dx_k = V (P Dm^-T) column k-1 for k = 1..3; dE/dx_0 = -their sum.
    const M3 h = mul(piola(model, deformation_of(mesh, t, x), l), transpose(dm_inv));
    for (int k = 0; k < 4; ++k) {
      if (!set[t[k]]) continue;
      for (int a = 0; a < 3; ++a) sum[a] += volume * (k == 0 ? -(h.m[a][0] + h.m[a][1] + h.m[a][2]) : h.m[a][k - 1]);
    }
  }
  return sum;
}

// Dynamic relaxation with kinetic damping (Cundall): steps the simulation
// and, once the kinetic energy has fallen to half its peak (a peak of the
// dominant mode has passed), restarts the scene at rest from the current
// positions. Done when such a peak stays under `ke_tol` [J] (set above the
// float noise of velocities derived from float positions, ~ m (ulp(x)/h)^2,
// and below the energy of any motion that matters), or after `max_frames`.
// `frames` counts the frames run.
std::vector<float> relax(Simulation& first_sim, SceneDesc scene, const std::string& backend, int max_frames,
                         double ke_tol, int& frames) {
  Simulation* sim = &first_sim;
  Result<Simulation> restarted = Error(ErrorCode::internal, "");
  frames = 0;
  double peak = 0.0;
  while (frames < max_frames) {
    if (Status s = sim->step(); !s) {
      ADD_FAILURE() << s.error().message();
      break;
    }
    ++frames;
    const double ke = sim->last_frame().kinetic_energy;
    peak = std::max(peak, ke);
    if (ke > 0.5 * peak) continue;
    if (peak < ke_tol) break;
    const std::vector<float> x = positions(*sim);
    TetBodyDesc& body = scene.tet_bodies[0];
    body.initial_vertices.resize(body.mesh.vertices.size());
    for (std::size_t v = 0; v < body.initial_vertices.size(); ++v)
      body.initial_vertices[v] = {x[4 * v], x[4 * v + 1], x[4 * v + 2]};
    restarted = test::create_or_skip(scene, backend);
    if (!restarted.ok()) {
      ADD_FAILURE() << restarted.error().message();
      break;
    }
    sim = &*restarted;
    peak = 0.0;
  }
  return positions(*sim);
}

// ------------------------------------------------------- uniaxial stretch

// The static tests run at small Courant numbers h sqrt(mu / rho) / cell
// (0.05 to 0.2), where the converged xPBD statics are accurate: larger
// steps bias them (neo_hookean most, README "FEM materials"), and much
// smaller ones stall on float positions (a force f on a particle of mass m
// moves it by f h^2 / m per frame, below a float ulp for small h).

// A bar of 20 x 2 x 2 cells of 1 cm (aspect 10:1) along x, its rest shape
// unstretched, started stretched by s along x with the expected lateral
// stretch t0 away from its ends, both end faces pinned (they cannot
// contract; ten cells away from them the state is uniaxial), no gravity.
constexpr int kBarCells = 20, kBarWidth = 2;
constexpr double kCell = 0.01;

SceneDesc uniaxial_scene(TetMaterial model, double young, double nu, double s, double t0, double h) {
  TetBodyDesc bar;
  // Centred on the origin: float positions resolve finer there.
  const double length = kBarCells * kCell, width = kBarWidth * kCell;
  auto mesh = make_tet_grid({.nx = kBarCells, .ny = kBarWidth, .nz = kBarWidth,
                             .origin = {-length / 2, -width / 2, -width / 2}, .cell_size = {kCell, kCell, kCell}});
  EXPECT_TRUE(mesh.ok());
  bar.mesh = *mesh;
  bar.density = 1000.0;
  EXPECT_TRUE(bar.set_material(model, young, nu).ok());
  for (std::uint32_t v = 0; v < bar.mesh.vertices.size(); ++v) {
    const Vec3d p = bar.mesh.vertices[v];
    const bool end = std::abs(p[0]) > length / 2 - 1e-9;
    const double t = end ? 1.0 : t0;
    bar.initial_vertices.push_back({s * p[0], t * p[1], t * p[2]});
    if (end) bar.pinned.push_back(v);
  }
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver = {.time_step = h, .substeps = 1, .iterations = 5};
  scene.tet_bodies.push_back(std::move(bar));
  return scene;
}

struct BarResult {
  double s_mid = 0, t_mid = 0;  // stretch and lateral stretch of the middle section
  double force = 0;             // axial force through the bar [N]
  int frames = 0;
};

// Relaxes the bar and measures the middle section (stretch between the
// cross-sections two cells either side of the middle; lateral stretch of
// the middle cross-section, across y and z) and the axial reaction at the
// x = L end, from the energy gradient in double.
BarResult relax_bar(Simulation& sim, const SceneDesc& scene, const std::string& backend, TetMaterial model,
                    const Lame& l, double ke_tol) {
  BarResult r;
  const std::vector<float> x = relax(sim, scene, backend, 3000, ke_tol, r.frames);
  const TetMesh& mesh = scene.tet_bodies[0].mesh;
  const int nx = kBarCells + 1, ny = kBarWidth + 1;
  auto vertex = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
  auto mean_x = [&](int i) {
    double m = 0;
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < ny; ++k) m += x[4 * vertex(i, j, k)];
    return m / (ny * ny);
  };
  const int mid = kBarCells / 2, half = 2;
  r.s_mid = (mean_x(mid + half) - mean_x(mid - half)) / (2 * half * kCell);
  double width = 0;
  for (int k = 0; k < ny; ++k) width += x[4 * vertex(mid, ny - 1, k) + 1] - x[4 * vertex(mid, 0, k) + 1];
  for (int j = 0; j < ny; ++j) width += x[4 * vertex(mid, j, ny - 1) + 2] - x[4 * vertex(mid, j, 0) + 2];
  r.t_mid = width / (2.0 * ny * kBarWidth * kCell);
  std::vector<bool> end(mesh.vertices.size());
  for (std::size_t v = 0; v < end.size(); ++v) end[v] = mesh.vertices[v][0] > kBarCells * kCell / 2 - 1e-9;
  r.force = energy_gradient_sum(model, l, mesh, x, end)[0];
  return r;
}

TEST_P(Fem, NeoHookeanUniaxialStretchMatchesTheClosedForm) {
  const double young = 1e4, nu = 0.3, s = 1.4;
  const Lame l = lame(young, nu);
  const double lp = l.lambda + l.mu;
  auto t_exact = [&](double stretch) {  // (2)
    return std::sqrt((1.0 + (l.mu / lp) * (1.0 - 1.0 / stretch)) / stretch);
  };
  // Courant number 0.05: the contraction error is 0.35% at 0.1, 1.3% at 0.2.
  const SceneDesc scene = uniaxial_scene(TetMaterial::neo_hookean, young, nu, s, t_exact(s), 2.5e-4);
  FEM_SIMULATION(sim, scene);
  const BarResult r = relax_bar(sim, scene, GetParam(), TetMaterial::neo_hookean, l, 2e-9);
  const double t = t_exact(r.s_mid);
  const double force = l.mu * (r.s_mid - t * t / r.s_mid) * std::pow(kBarWidth * kCell, 2);  // (3) times A0
  std::printf("[ neo_hookean s = %.1f ] %d frames: s_mid %.6f, t_mid %.6f (exact %.6f, contraction error %.3f%%), "
              "force %.6g N (exact %.6g N, error %.3f%%)\n",
              s, r.frames, r.s_mid, r.t_mid, t, 100 * (r.t_mid - t) / (1 - t), r.force, force,
              100 * (r.force - force) / force);
  EXPECT_NEAR(r.t_mid, t, 0.01 * (1.0 - t)) << "lateral contraction 1 - t within 1%";
  EXPECT_NEAR(r.force, force, 0.01 * force) << "reaction force within 1% of P11 A0";
}

TEST_P(Fem, SmallStrainGivesYoungsModulusAndPoissonsRatio) {
  // 1% uniaxial stretch: E = (force / A0) / (s - 1), nu = (1 - t) / (s - 1),
  // both from the middle section. The models agree with linear elasticity
  // to first order in the strain; their second-order terms are below 1% here.
  const double young = 1e4, nu = 0.3, s = 1.01;
  const Lame l = lame(young, nu);
  for (TetMaterial model : kModels) {
    const SceneDesc scene = uniaxial_scene(model, young, nu, s, 1.0 - nu * (s - 1.0), 5e-4);  // Courant 0.1
    FEM_SIMULATION(sim, scene);
    const BarResult r = relax_bar(sim, scene, GetParam(), model, l, 2e-10);
    const double e = r.s_mid - 1.0;
    const double young_measured = r.force / std::pow(kBarWidth * kCell, 2) / e;
    const double nu_measured = (1.0 - r.t_mid) / e;
    std::printf("[ %s, 1%% strain ] %d frames: E %.5g Pa (error %.2f%%), nu %.4f (error %.2f%%)\n", model_name(model),
                r.frames, young_measured, 100 * (young_measured / young - 1), nu_measured,
                100 * (nu_measured / nu - 1));
    EXPECT_NEAR(young_measured, young, 0.03 * young) << model_name(model);
    EXPECT_NEAR(nu_measured, nu, 0.03 * nu) << model_name(model);
  }
}

// ------------------------------------------------------------ hanging bar

TEST_P(Fem, BarHangingUnderItsOwnWeightStretchesByRhoGL2Over2E) {
  // A bar of length L hanging from its pinned top face: the section at
  // height y above the tip carries the weight below it, nominal stress
  // rho g y, so with
  // nu = 0 (no lateral coupling; neo_hookean is the model that allows it)
  // the tip drops by the integral of rho g y / E: rho g L^2 / (2 E). Stable
  // Neo-Hookean at nu = 0 has P11 = 2 mu (s - 1) + O((s - 1)^3) in uniaxial
  // stress (from (2) and (3): t^2 = (2 - 1/s)/s), so at the 1% strain at the
  // top the closed form holds to ~1e-4. 3 x 20 x 3 cells of 5 mm (L = 10 cm).
  const double young = 1e4, rho = 1000.0, g = 1.0, cell = 0.005;
  const int n = 3, m = 20;
  const double length = m * cell, width = n * cell;
  TetBodyDesc bar;
  auto mesh = make_tet_grid({.nx = n, .ny = m, .nz = n, .origin = {-width / 2, -length / 2, -width / 2},
                             .cell_size = {cell, cell, cell}});
  ASSERT_TRUE(mesh.ok());
  bar.mesh = *mesh;
  bar.density = rho;
  SINEW_ASSERT_OK(bar.set_material(TetMaterial::neo_hookean, young, 0.0));
  for (std::uint32_t v = 0; v < bar.mesh.vertices.size(); ++v)
    if (bar.mesh.vertices[v][1] > length / 2 - 1e-9) bar.pinned.push_back(v);
  SceneDesc scene;
  scene.gravity = {0.0, -g, 0.0};
  scene.solver = {.time_step = 5e-4, .substeps = 1, .iterations = 5};  // Courant number 0.22
  scene.tet_bodies.push_back(bar);
  FEM_SIMULATION(sim, scene);
  int frames = 0;
  const std::vector<float> x = relax(sim, scene, GetParam(), 4000, 3e-11, frames);
  double tip = 0.0;
  int count = 0;
  for (std::uint32_t v = 0; v < bar.mesh.vertices.size(); ++v)
    if (bar.mesh.vertices[v][1] < -length / 2 + 1e-9) {
      tip += bar.mesh.vertices[v][1] - x[4 * v + 1];
      ++count;
    }
  tip /= count;
  const double expected = rho * g * length * length / (2.0 * young);
  std::printf("[ hanging bar ] %d frames: tip displacement %.6g m (rho g L^2 / 2E = %.6g m, error %.2f%%)\n", frames,
              tip, expected, 100 * (tip / expected - 1));
  EXPECT_NEAR(tip, expected, 0.05 * expected);
}

// ------------------------------------------------------ rest and inversion

TEST_P(Fem, BodyAtRestWithoutGravityStaysAtRest) {
  // Every model's forces vanish at the rest shape. For neo_hookean that is a
  // balance of two large multipliers (the deviatoric constraint |F| = sqrt(3)
  // at rest), which the coupled solve finds in one step; float rounding of
  // that balance is amplified like an explicit shear step, so the Courant
  // number h sqrt(mu / rho) / cell must be small (README): 0.1 here
  // (E = 10 kPa, 1 cm cells, 32 substeps of a 60 Hz frame). Measured with 8
  // substeps (0.39): 4e-5 of the size; with 4 (0.78): unstable.
  for (TetMaterial model : kModels) {
    TetBodyDesc box;
    box.mesh = test::box_mesh(4, 3, 5, 0.01);
    SINEW_ASSERT_OK(box.set_material(model, 1e4, 0.45));
    box.pinned = {0, 7};
    SceneDesc scene;
    scene.gravity = {0.0, 0.0, 0.0};
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 32, .iterations = 2};
    scene.tet_bodies.push_back(box);
    FEM_SIMULATION(sim, scene);
    const std::vector<float> start = positions(sim);
    double moved = 0.0;
    for (int f = 0; f < 100; ++f) {
      SINEW_ASSERT_OK(sim.step());
      const std::vector<float> x = positions(sim);
      for (std::size_t i = 0; i < x.size(); ++i)
        if (i % 4 != 3) moved = std::max(moved, std::abs(double(x[i]) - double(start[i])));
    }
    const double size = 0.05;
    std::printf("[ %s at rest ] largest displacement over 100 frames: %.3g m (%.3g of its size)\n", model_name(model),
                moved, moved / size);
    EXPECT_LT(moved, 1e-6 * size) << model_name(model);
  }
}

// Smallest det F over the tets of body 0 at positions x.
double smallest_det(const SceneDesc& scene, const std::vector<float>& x) {
  double lowest = 1e300;
  for (const auto& t : scene.tet_bodies[0].mesh.tets)
    lowest = std::min(lowest, det3(deformation_of(scene.tet_bodies[0].mesh, t, x)));
  return lowest;
}

TEST_P(Fem, InvertedTetRecovers) {
  // One free tet with its apex pushed through the opposite face (det F =
  // -0.5): its hydrostatic constraint pushes it back out, and it comes back
  // to its rest shape up to a rotation (F^T F = I).
  const double c = 0.01;
  for (TetMaterial model : kModels) {
    TetBodyDesc tet;
    tet.mesh.vertices = {{0, 0, 0}, {c, 0, 0}, {0, c, 0}, {0, 0, c}};
    tet.mesh.tets = {{0, 1, 2, 3}};
    tet.initial_vertices = {{0, 0, 0}, {c, 0, 0}, {0, c, 0}, {0.2 * c, 0.3 * c, -0.5 * c}};
    SINEW_ASSERT_OK(tet.set_material(model, 1e4, 0.3));
    SceneDesc scene;
    scene.gravity = {0.0, 0.0, 0.0};
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 16, .iterations = 2};
    scene.tet_bodies.push_back(tet);
    FEM_SIMULATION(sim, scene);
    EXPECT_LT(smallest_det(scene, positions(sim)), -0.4);
    for (int f = 0; f < 60; ++f) SINEW_ASSERT_OK(sim.step());
    const std::vector<float> x = positions(sim);
    const M3 f = deformation_of(tet.mesh, tet.mesh.tets[0], x);
    const M3 ftf = mul(transpose(f), f);
    double off = 0.0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) off = std::max(off, std::abs(ftf.m[a][b] - (a == b ? 1.0 : 0.0)));
    std::printf("[ %s, inverted tet ] after 1 s: det F %.4f, max |F^T F - I| %.3g\n", model_name(model), det3(f), off);
    EXPECT_GT(det3(f), 0.9) << model_name(model);
    EXPECT_LT(off, 0.1) << model_name(model);
  }
}

TEST_P(Fem, SquashedFlatAndReflectedBodiesRecover) {
  // A free 3 x 3 x 3-cell block started squashed flat (every vertex at y = 0,
  // every tet of zero volume) or reflected through y = 0 (every tet
  // inverted, det F = -1) unfolds until every tet has det F > 0.
  for (TetMaterial model : kModels) {
    for (const bool reflected : {false, true}) {
      TetBodyDesc block;
      block.mesh = test::box_mesh(3, 3, 3, 0.01);
      SINEW_ASSERT_OK(block.set_material(model, 1e4, 0.3));
      for (const Vec3d& p : block.mesh.vertices) block.initial_vertices.push_back({p[0], reflected ? -p[1] : 0.0, p[2]});
      SceneDesc scene;
      scene.gravity = {0.0, 0.0, 0.0};
      scene.solver = {.time_step = 1.0 / 60.0, .substeps = 16, .iterations = 2};
      scene.tet_bodies.push_back(block);
      FEM_SIMULATION(sim, scene);
      for (int f = 0; f < 120; ++f) SINEW_ASSERT_OK(sim.step());
      const std::vector<float> x = positions(sim);
      const double lowest = smallest_det(scene, x);
      std::printf("[ %s, %s block ] after 2 s: smallest det F %.4f, volume change %.4f\n", model_name(model),
                  reflected ? "reflected" : "flat", lowest, sim.last_frame().volume_change);
      EXPECT_GT(lowest, 0.0) << model_name(model) << (reflected ? " reflected" : " flat");
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, Fem, ::testing::ValuesIn(test::backends()), test::backend_name);

// ------------------------------------------------ constraint functions

// The constraints of `model` at F, in double (the templates the kernels
// run in float), with h0 = 1.4 (gamma), 1 and 3.
kernels::fem::TetConstraints<double> constraints_of(TetMaterial model, const M3& f) {
  switch (model) {
    case TetMaterial::neo_hookean: return kernels::fem::neo_hookean_constraints(f, 1.4);
    case TetMaterial::stvk: return kernels::fem::stvk_constraints(f, 1.0);
    default: return kernels::fem::corotational_constraints(f, 3.0);
  }
}

double4 random_point(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng), 1.0};
}
double& component(double4& v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
std::array<double, 3> xyz(const double4& v) { return {v.x, v.y, v.z}; }

// Central differences of C_D and C_H with respect to every coordinate of
// every vertex against grad_{x_i} C = column i of (dC/dF) Dm^-T.
void check_gradients(TetMaterial model, const double4 rest[4], double4 x[4], const std::string& what) {
  const M3 dm_inv = inverse(edge_matrix(xyz(rest[0]), xyz(rest[1]), xyz(rest[2]), xyz(rest[3])));
  auto eval = [&](const double4* p) {
    return constraints_of(model, kernels::fem::deformation_gradient(p[0], p[1], p[2], p[3], dm_inv));
  };
  const auto c = eval(x);
  double4 gd[4], gh[4];
  kernels::fem::position_gradients(c.dc_d, dm_inv, gd);
  kernels::fem::position_gradients(c.dc_h, dm_inv, gh);
  double scale = 0.0, coords = 0.0;  // largest gradient entry; largest coordinate
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) {
      scale = std::max({scale, std::abs(component(gd[i], k)), std::abs(component(gh[i], k))});
      coords = std::max(coords, std::abs(component(x[i], k)));
    }
  // Central differences at steps d and d/4, Richardson-extrapolated
  // (truncation error ~ d^4 times the fifth derivative; cancellation
  // ~ eps |C| / d): well below 1e-6 of the gradient even near flat tets.
  const double step = 1e-5 * coords;
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) {
      const double keep = component(x[i], k);
      auto central = [&](double d) {
        component(x[i], k) = keep + d;
        const auto plus = eval(x);
        component(x[i], k) = keep - d;
        const auto minus = eval(x);
        component(x[i], k) = keep;
        return std::array<double, 2>{(plus.c_d - minus.c_d) / (2 * d), (plus.c_h - minus.c_h) / (2 * d)};
      };
      const auto coarse = central(step), fine = central(step / 4);
      const double fd_d = (16 * fine[0] - coarse[0]) / 15, fd_h = (16 * fine[1] - coarse[1]) / 15;
      EXPECT_NEAR(fd_d, component(gd[i], k), 1e-6 * scale) << model_name(model) << " C_D, " << what << ", x" << i << k;
      EXPECT_NEAR(fd_h, component(gh[i], k), 1e-6 * scale) << model_name(model) << " C_H, " << what << ", x" << i << k;
    }
}

// A random rest tet of reasonable shape: order-1 size, det of its edge
// matrix > 0.2 of the product of its edge lengths.
void random_rest_tet(std::mt19937& rng, double4 rest[4]) {
  for (;;) {
    for (int i = 0; i < 4; ++i) rest[i] = random_point(rng, 1.0);
    const double4 e1 = rest[1] - rest[0], e2 = rest[2] - rest[0], e3 = rest[3] - rest[0];
    const double v = kernels::dot3(e1, kernels::cross3(e2, e3));
    if (v > 0.2 * std::sqrt(kernels::dot3(e1, e1) * kernels::dot3(e2, e2) * kernels::dot3(e3, e3))) return;
  }
}

TEST(FemConstraints, GradientsMatchFiniteDifferencesAtRandomConfigurations) {
  std::mt19937 rng(std::random_device{}());
  for (TetMaterial model : kModels)
    for (int trial = 0; trial < 100; ++trial) {
      double4 rest[4], x[4];
      random_rest_tet(rng, rest);
      // Random positions: large deformations, rotations, inversions.
      for (int i = 0; i < 4; ++i) x[i] = random_point(rng, 1.0);
      check_gradients(model, rest, x, "random");
      // Near the rest shape: strains of a few percent.
      for (int i = 0; i < 4; ++i) x[i] = rest[i] + 0.05 * random_point(rng, 1.0);
      check_gradients(model, rest, x, "near rest");
    }
}

TEST(FemConstraints, GradientsMatchFiniteDifferencesNearDegenerateConfigurations) {
  std::mt19937 rng(std::random_device{}());
  std::uniform_real_distribution<double> side(-1.0, 1.0);
  for (TetMaterial model : kModels)
    for (int trial = 0; trial < 100; ++trial) {
      double4 rest[4], x[4];
      random_rest_tet(rng, rest);
      for (int i = 0; i < 3; ++i) x[i] = rest[i] + 0.2 * random_point(rng, 1.0);
      // Nearly flat: x3 within 1e-3 of the plane of x0, x1, x2 (det F of
      // either sign, ~1e-3).
      const double4 n = kernels::cross3(x[1] - x[0], x[2] - x[0]);
      const double4 unit_n = (1.0 / std::sqrt(kernels::dot3(n, n))) * n;
      x[3] = 0.3 * x[0] + 0.3 * x[1] + 0.4 * x[2] + (1e-3 * side(rng)) * unit_n;
      check_gradients(model, rest, x, "nearly flat");
      // Inverted: x3 mirrored through that plane.
      x[3] = rest[3] + 0.2 * random_point(rng, 1.0);
      x[3] = x[3] - (2.0 * kernels::dot3(x[3] - x[0], unit_n)) * unit_n;
      check_gradients(model, rest, x, "inverted");
    }
}

TEST(FemConstraints, RestValues) {
  // At F = I: C_D = sqrt(3), C_H = 1 - gamma for neo_hookean; both 0 for the
  // others, and for them a rotation is at rest too.
  const M3 id{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  const auto nh = kernels::fem::neo_hookean_constraints(id, 1.4);
  EXPECT_DOUBLE_EQ(nh.c_d, std::sqrt(3.0));
  EXPECT_NEAR(nh.c_h, -0.4, 1e-15);
  EXPECT_EQ(kernels::fem::stvk_constraints(id, 1.0).c_d, 0.0);
  EXPECT_EQ(kernels::fem::stvk_constraints(id, 1.0).c_h, 0.0);
  const double a = 0.7;
  const M3 rot{{{std::cos(a), -std::sin(a), 0}, {std::sin(a), std::cos(a), 0}, {0, 0, 1}}};
  for (const M3& f : {id, rot}) {
    EXPECT_NEAR(kernels::fem::stvk_constraints(f, 1.0).c_d, 0.0, 1e-15);
    EXPECT_NEAR(kernels::fem::corotational_constraints(f, 3.0).c_d, 0.0, 1e-14);
    EXPECT_NEAR(kernels::fem::corotational_constraints(f, 3.0).c_h, 0.0, 1e-14);
  }
}

TEST(FemConstraints, RotationPartIsTheClosestRotation) {
  // R = rotation_part(F): orthonormal, det R = +1, R^T F symmetric, and
  // tr(R^T F) >= tr(Q^T F) for random rotations Q, for general, inverted
  // and nearly flat F. The float instance agrees with the double one where
  // R is well conditioned.
  std::mt19937 rng(std::random_device{}());
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto random_rotation = [&] {
    double q[4] = {gauss(rng), gauss(rng), gauss(rng), gauss(rng)};
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    return M3{{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
               {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
               {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
  };
  auto trace_of = [](const M3& r, const M3& f) {
    double t = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) t += r.m[a][b] * f.m[a][b];
    return t;
  };
  int float_checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    M3 f{};
    for (auto& row : f.m)
      for (double& v : row) v = gauss(rng);
    if (trial % 3 == 1) {  // nearly flat: one singular direction squashed to ~1e-4
      const M3 q = random_rotation();
      const M3 d{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1e-4 * gauss(rng)}}};
      f = mul(f, mul(q, mul(d, transpose(q))));
    }
    const M3 r = kernels::fem::rotation_part(f);
    const M3 rtr = mul(transpose(r), r), s = mul(transpose(r), f);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        EXPECT_NEAR(rtr.m[a][b], a == b ? 1.0 : 0.0, 1e-12);
        EXPECT_NEAR(s.m[a][b], s.m[b][a], 1e-10 * kernels::fem::frobenius_norm(f));
      }
    EXPECT_NEAR(det3(r), 1.0, 1e-12);
    const double best = trace_of(r, f);
    for (int k = 0; k < 50; ++k) EXPECT_GE(best, trace_of(random_rotation(), f) - 1e-12);
    // Float: R is well conditioned when det F > 0 is not small (the largest
    // eigenvalue of Horn's matrix, s1 + s2 + s3, is then well separated).
    if (det3(f) > 0.05 * std::pow(kernels::fem::frobenius_norm(f), 3)) {
      mat3<float> ff;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) ff.m[a][b] = static_cast<float>(f.m[a][b]);
      const mat3<float> rf = kernels::fem::rotation_part(ff);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) EXPECT_NEAR(rf.m[a][b], r.m[a][b], 1e-5);
      ++float_checked;
    }
  }
  EXPECT_GT(float_checked, 10);
}

// ------------------------------------------------------------- kernels

// One tet in kernel buffers, its data as compile_fem.cpp lays it out
// (kernels/shared/fem_params.h): the corner tet of edge c, density 1000.
struct OneTet {
  float4 x[4];
  kernels::uint4 idx{0, 1, 2, 3};
  float data[SINEW_FEM_DATA_STRIDE] = {};
  float lambda[SINEW_FEM_COROTATIONAL_LAMBDA_STRIDE] = {};  // neo_hookean and stvk use the first two
  float residual = 0;
  OneTet(TetMaterial model, double c, double young, double nu) {
    const Lame l = lame(young, nu);
    const double v = c * c * c / 6;
    data[0] = data[4] = data[8] = static_cast<float>(1 / c);
    data[SINEW_FEM_REST_VOLUME] = static_cast<float>(v);
    const bool nh = model == TetMaterial::neo_hookean;
    const double lh = nh ? l.lambda + l.mu : l.lambda;
    data[SINEW_FEM_ALPHA_D] = static_cast<float>(1 / ((nh ? 1 : 2) * l.mu * v));
    data[SINEW_FEM_ALPHA_H] = static_cast<float>(1 / (lh * v));
    data[SINEW_FEM_H0] = static_cast<float>(nh ? 1 + l.mu / lh : (model == TetMaterial::stvk ? 1 : 3));
    const float w = static_cast<float>(4 / (1000 * v)), fc = static_cast<float>(c);
    x[0] = {0, 0, 0, w};
    x[1] = {fc, 0, 0, w};
    x[2] = {0, fc, 0, w};
    x[3] = {0, 0, fc, w};
  }
  void solve(TetMaterial model, const kernels::SolveParams& p) {
    std::byte* b[5] = {reinterpret_cast<std::byte*>(x), reinterpret_cast<std::byte*>(&idx),
                       reinterpret_cast<std::byte*>(data), reinterpret_cast<std::byte*>(lambda),
                       reinterpret_cast<std::byte*>(&residual)};
    switch (model) {
      case TetMaterial::neo_hookean: kernels::xpbd_solve_neo_hookean(&p, b, 0, 1); break;
      case TetMaterial::stvk: kernels::xpbd_solve_stvk(&p, b, 0, 1); break;
      default: kernels::xpbd_solve_corotational(&p, b, 0, 1); break;
    }
  }
};

TEST(FemKernels, MeasuringPassWritesTheResidualAndChangesNothingElse) {
  std::mt19937 rng(std::random_device{}());
  std::uniform_real_distribution<float> u(-0.3f, 0.3f);
  for (TetMaterial model : kModels) {
    OneTet t(model, 0.01, 1e4, 0.3);
    for (float4& p : t.x) p = {p.x + 0.01f * u(rng), p.y + 0.01f * u(rng), p.z + 0.01f * u(rng), p.w};
    t.lambda[0] = 1e-7f * u(rng);
    t.lambda[1] = 1e-7f * u(rng);
    const OneTet before = t;
    kernels::SolveParams p{};
    p.count = 1;
    p.inv_h2 = 1e4f;
    p.measure_only = 1;
    t.solve(model, p);
    EXPECT_EQ(0, std::memcmp(before.x, t.x, sizeof t.x)) << model_name(model);
    EXPECT_EQ(0, std::memcmp(before.lambda, t.lambda, sizeof t.lambda)) << model_name(model);
    // sqrt((C_D + alpha~_D lambda_D)^2 + (C_H + alpha~_H lambda_H)^2), in double.
    const M3 dm_inv{{{100, 0, 0}, {0, 100, 0}, {0, 0, 100}}};
    auto at = [&](int k) { return double4{t.x[k].x, t.x[k].y, t.x[k].z, 0}; };
    const M3 f = kernels::fem::deformation_gradient(at(0), at(1), at(2), at(3), dm_inv);
    const double h0 = t.data[SINEW_FEM_H0];
    const auto c = model == TetMaterial::neo_hookean ? kernels::fem::neo_hookean_constraints(f, h0)
                   : model == TetMaterial::stvk      ? kernels::fem::stvk_constraints(f, h0)
                                                     : kernels::fem::corotational_constraints(f, h0);
    const double rd = c.c_d + double(t.data[SINEW_FEM_ALPHA_D]) * 1e4 * t.lambda[0];
    const double rh = c.c_h + double(t.data[SINEW_FEM_ALPHA_H]) * 1e4 * t.lambda[1];
    EXPECT_NEAR(t.residual, std::hypot(rd, rh), 1e-5 * (1 + std::hypot(rd, rh))) << model_name(model);
  }
}

TEST(FemKernels, PinnedTetConvergesToTheEnergyMinimumWithoutMovingPins) {
  // Vertices 0..2 pinned (w = 0), vertex 1 pulled out by 30%, vertex 3 free:
  // substeps of h = 1 ms (omega h ~ 1.6 for the free vertex, so implicit
  // Euler damps it) of 20 iterations each settle it where the model's
  // energy gradient at vertex 3 vanishes; pinned particles are never written.
  for (TetMaterial model : kModels) {
    OneTet t(model, 0.01, 1e4, 0.3);
    t.x[0].w = t.x[1].w = t.x[2].w = 0.0f;
    t.x[1].x = 0.013f;
    float4 pinned[3];
    std::memcpy(pinned, t.x, sizeof pinned);
    kernels::SolveParams p{};
    p.count = 1;
    p.inv_h2 = 1e6f;
    for (int substep = 0; substep < 200; ++substep)
      for (int it = 0; it < 20; ++it) {
        p.reset_lambda = it == 0;
        t.solve(model, p);
      }
    EXPECT_EQ(0, std::memcmp(pinned, t.x, sizeof pinned)) << model_name(model);
    TetMesh mesh;
    mesh.vertices = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0, 0, 0.01}};
    mesh.tets = {{0, 1, 2, 3}};
    std::vector<float> x(16);
    std::memcpy(x.data(), t.x, sizeof t.x);
    const auto g = energy_gradient_sum(model, lame(1e4, 0.3), mesh, x, {false, false, false, true});
    // Force scale: E strain A = 1e4 Pa * 0.3 * 1e-4 m^2 = 0.3 N.
    EXPECT_LT(std::hypot(g[0], g[1], g[2]), 1e-5 * 0.3) << model_name(model);
    EXPECT_GT(t.x[3].z, 0.005f) << model_name(model);
  }
}

TEST(FemScene, ErrorsNameTheBodyTetAndParameter) {
  TetBodyDesc body;
  body.mesh = test::box_mesh(1, 1, 1, 0.01);
  SINEW_ASSERT_OK(body.set_material(TetMaterial::stvk, 1e4, 0.0));
  SceneDesc scene;
  scene.tet_bodies.push_back(body);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_FALSE(sim.ok());
  EXPECT_NE(sim.error().message().find("tet_bodies[0].poisson_ratio must be > 0"), std::string::npos)
      << sim.error().message();

  // A sliver: valid in double and of positive float volume, but its edge
  // matrix is too ill-conditioned for F = Ds Dm^-1 in float.
  TetBodyDesc sliver;
  sliver.mesh.vertices = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0.003, 0.003, 1e-8}};
  sliver.mesh.tets = {{0, 1, 2, 3}};
  SINEW_ASSERT_OK(sliver.set_material(TetMaterial::neo_hookean, 1e4, 0.3));
  scene.tet_bodies = {body, sliver};
  scene.tet_bodies[0].poisson_ratio = 0.3;
  sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_FALSE(sim.ok());
  EXPECT_NE(sim.error().message().find("tet_bodies[1].mesh: tet 0 is too flat"), std::string::npos)
      << sim.error().message();
}

}  // namespace
}  // namespace sinew
