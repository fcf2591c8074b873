// compile_fem.cpp — the FEM constraints of tet bodies: two per tet (C_D, C_H)
// solved together by one kernel per material (kernels/cpu/fem_kernels.cpp),
// with the per-tet data of kernels/shared/fem_params.h.
//
// Lamé parameters from Young's modulus E and Poisson's ratio nu:
//   mu = E / (2 (1 + nu)),  lambda = E nu / ((1 + nu) (1 - 2 nu)).
// Compliances (include/sinew/scene.h), V the tet's rest volume:
//   neo_hookean (Macklin, Müller, MIG 2021): alpha_D = 1 / (mu V),
//     alpha_H = 1 / (lambda' V) with lambda' = lambda + mu, gamma = 1 + mu / lambda';
//     the energy mu/2 |F|^2 + lambda'/2 (det F - gamma)^2 is, to second order in
//     the strain eps, mu eps:eps + lambda/2 (tr eps)^2: linear elasticity with E, nu;
//   stvk: alpha_D = 1 / (2 mu V), alpha_H = 1 / (lambda V), C_H = det F - 1;
//   corotational: alpha_D = 1 / (2 mu V), alpha_H = 1 / (lambda V), C_H = tr(R^T F) - 3.
// stvk and corotational need lambda > 0 (nu > 0): with lambda <= 0 their
// hydrostatic compliance would be infinite or negative (and stvk would have
// nothing left to push inverted tets back out). neo_hookean's lambda' =
// E / (2 (1 + nu) (1 - 2 nu)) is positive for every nu in (-1, 0.5).
//
// Dm and its inverse are computed in double from the float rest positions
// (the positions the kernels see), then rounded once.
#include <cmath>
#include <cstdio>
#include <string>

#include "compiler/scene_compiler.h"
#include "fem_params.h"

namespace sinew {
namespace {

std::string str(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

Status add_fem_constraints(SceneBuilder& b, const TetBodyDesc& body, std::uint32_t first, const std::string& name) {
  const double young = body.youngs_modulus, nu = body.poisson_ratio;
  const double mu = young / (2.0 * (1.0 + nu));
  const double lame = young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  Kernel kernel = Kernel::count_;
  double stiff_d = 0.0, stiff_h = 0.0, h0 = 0.0;  // alpha = 1 / (stiff * V)
  switch (body.material) {
    case TetMaterial::neo_hookean: {
      const double lame_nh = lame + mu;  // = E / (2 (1 + nu) (1 - 2 nu)) > 0 for nu in (-1, 0.5)
      kernel = Kernel::xpbd_solve_neo_hookean;
      stiff_d = mu;
      stiff_h = lame_nh;
      h0 = 1.0 + mu / lame_nh;
      break;
    }
    case TetMaterial::stvk:
    case TetMaterial::corotational:
      if (!(lame > 0.0))
        return Error(ErrorCode::bad_parameter,
                     name + ".poisson_ratio must be > 0 for the " +
                     (body.material == TetMaterial::stvk ? "stvk" : "corotational") +
                     " material (got " + str(nu) +
                     "): its hydrostatic constraint has compliance 1 / (lambda V) with "
                     "lambda = E nu / ((1 + nu) (1 - 2 nu)); use neo_hookean for nu <= 0");
      kernel = body.material == TetMaterial::stvk ? Kernel::xpbd_solve_stvk : Kernel::xpbd_solve_corotational;
      stiff_d = 2.0 * mu;
      stiff_h = lame;
      h0 = body.material == TetMaterial::stvk ? 1.0 : 3.0;
      break;
    case TetMaterial::none: return {};
  }
  if (!(std::isfinite(stiff_d) && std::isfinite(stiff_h) && stiff_d > 0.0 && stiff_h > 0.0))
    return Error(ErrorCode::bad_parameter,
                 name + ": youngs_modulus " + str(young) + " and poisson_ratio " + str(nu) +
                 " give Lame parameters that are not finite and positive");

  // Corotational tets also keep their rotation between solves (fem_params.h).
  RawConstraints& fem = b.constraints(kernel, 4, SINEW_FEM_DATA_STRIDE,
                                      kernel == Kernel::xpbd_solve_corotational ? SINEW_FEM_COROTATIONAL_LAMBDA_STRIDE
                                                                                : SINEW_FEM_LAMBDA_STRIDE);
  const auto& tets = body.mesh.tets;
  fem.particles.reserve(fem.particles.size() + 4 * tets.size());
  fem.data.reserve(fem.data.size() + SINEW_FEM_DATA_STRIDE * tets.size());
  for (std::size_t t = 0; t < tets.size(); ++t) {
    const auto& q = tets[t];
    auto where = [&] { return name + ".mesh: tet " + std::to_string(t); };
    // Dm = [x1 - x0, x2 - x0, x3 - x0] (columns), from the float rest positions.
    double dm[3][3];
    const kernels::float4 p0 = b.positions[first + q[0]];
    for (int k = 0; k < 3; ++k) {
      const kernels::float4 pk = b.positions[first + q[k + 1]];
      dm[0][k] = double(pk.x) - double(p0.x);
      dm[1][k] = double(pk.y) - double(p0.y);
      dm[2][k] = double(pk.z) - double(p0.z);
    }
    const double det = dm[0][0] * (dm[1][1] * dm[2][2] - dm[1][2] * dm[2][1]) -
                       dm[0][1] * (dm[1][0] * dm[2][2] - dm[1][2] * dm[2][0]) +
                       dm[0][2] * (dm[1][0] * dm[2][1] - dm[1][1] * dm[2][0]);
    if (!(det > 0.0))
      return Error(ErrorCode::bad_parameter,
                   where() +
                       " has no positive volume in single precision (its edge matrix Dm is singular or inverted)");
    // Dm^-1 = adj(Dm) / det: row i of the inverse is (column j x column k) / det.
    double inv[3][3];
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      inv[i][0] = (dm[1][j] * dm[2][k] - dm[2][j] * dm[1][k]) / det;
      inv[i][1] = (dm[2][j] * dm[0][k] - dm[0][j] * dm[2][k]) / det;
      inv[i][2] = (dm[0][j] * dm[1][k] - dm[1][j] * dm[0][k]) / det;
    }
    // F = Ds Dm^-1 is computed in float: its error at rest is about
    // float epsilon times the condition number of Dm. Above 1e5 a tet at
    // rest would already be strained by ~1%.
    double norm_dm = 0.0, norm_inv = 0.0;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        norm_dm += dm[r][c] * dm[r][c];
        norm_inv += inv[r][c] * inv[r][c];
      }
    const double condition = std::sqrt(norm_dm * norm_inv);
    if (!(condition < 1e5))
      return Error(ErrorCode::bad_parameter,
                   where() + " is too flat for single precision FEM (condition number of its edge matrix " +
                   str(condition) + ", must be < 1e5)");
    const double volume = det / 6.0;
    const double alpha_d = 1.0 / (stiff_d * volume), alpha_h = 1.0 / (stiff_h * volume);
    if (Status s = check_device_compliance(name, ".youngs_modulus (its deviatoric alpha = 1 / (mu V))", alpha_d, b.step); !s)
      return s;
    if (Status s = check_device_compliance(name, ".youngs_modulus (its volume alpha = 1 / (lambda V))", alpha_h, b.step);
        !s)
      return s;
    float row[SINEW_FEM_DATA_STRIDE] = {};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) row[SINEW_FEM_DM_INV + 3 * r + c] = static_cast<float>(inv[r][c]);
    row[SINEW_FEM_REST_VOLUME] = static_cast<float>(volume);
    row[SINEW_FEM_ALPHA_D] = static_cast<float>(alpha_d);
    row[SINEW_FEM_ALPHA_H] = static_cast<float>(alpha_h);
    row[SINEW_FEM_H0] = static_cast<float>(h0);
    for (float v : row)
      if (!std::isfinite(v))
        return Error(ErrorCode::bad_parameter,
                     where() + ": its FEM data do not fit in single precision (rest volume " + str(volume) +
                     " m^3, compliances " + str(alpha_d) + " and " + str(alpha_h) + " 1/(Pa m^3))");
    if (!(row[SINEW_FEM_ALPHA_D] > 0.0f && row[SINEW_FEM_ALPHA_H] > 0.0f))
      return Error(ErrorCode::bad_parameter,
                   where() + ": its compliances " + str(alpha_d) + " and " + str(alpha_h) +
                   " 1/(Pa m^3) round to 0 in single precision (youngs_modulus too large for this tet size)");
    for (std::uint32_t k : q) fem.particles.push_back(first + k);
    fem.data.insert(fem.data.end(), row, row + SINEW_FEM_DATA_STRIDE);
  }
  return {};
}

}  // namespace sinew
