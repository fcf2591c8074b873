// fem_kernels.cpp — CPU reference kernels of the FEM tet materials.
//
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016; Macklin, Müller, "A Constraint-based
// Formulation of Stable Neo-Hookean Materials", MIG 2021. The models'
// constraints are in kernels/math/fem_math.h, the data layout in
// kernels/shared/fem_params.h.
//
// Each work item solves one tet's two constraints C = (C_D, C_H) together,
// as one 2x2 xPBD system (the coupled solve Macklin & Müller 2021 recommend):
//   (J W J^T + alpha~) dlambda = -(C + alpha~ lambda),  dx = W J^T dlambda,
// J = the two gradients (rows), W = the inverse masses. Why coupled and not
// one after the other: in stable Neo-Hookean the two gradients are parallel
// at rest (|F| and det F both grow along F = I) and the rest state is a
// balance of two large multipliers (lambda_D = -sqrt(3) / alpha~_D against
// lambda_H = (gamma - 1) / alpha~_H). The coupled solve finds that balance
// in one step, so a body at rest does not move; one after the other, each
// substep starts with C_D pulling the tet in and C_H only partly pushing it
// back, and a body at rest shrinks: measured on a 10 x 2 x 2-cell bar (E =
// 100 kPa, 1 cm cells, 300 frames of 0.5 ms, 10 iterations) its width fell
// by 3% (sequential) against 0 (coupled), and by 14% at 1 ms. For the zero-
// rest-value constraints of stvk and corotational both ways agree at rest;
// one kernel shape serves all three.
//
// What the formulation costs (tests/fem_test.cpp, README "FEM materials"):
// xPBD linearises each constraint (Gauss-Newton), which drops lambda times
// the constraint's curvature. For neo_hookean's prestressed pair that term
// is the whole shear stiffness at rest, so shear is effectively integrated
// explicitly: with the shear-wave Courant number k = h sqrt(mu / rho) / cell,
// rounding at rest grows without bound above k ~ 0.75, and converged statics
// are biased: the lateral contraction of a 40% stretch is off by 0.07% at
// k = 0.05, 0.35% at 0.1, 1.3% at 0.2. The norms |E| and |F - R| of stvk and
// corotational curve sharply near zero too, more mildly in effect: their
// Poisson ratio at 1% strain is off by ~0.9% at k = 0.2, ~7% at k = 0.6.
//
// The 2x2 system is solved in a basis that keeps it well conditioned in
// float: with a = grad C_D, b = grad C_H, beta = <a, b>_W / <a, a>_W and
// b' = b - beta a (W-orthogonal to a), the unknowns mu = (dlambda_D +
// beta dlambda_H, dlambda_H) satisfy
//   [<a,a> + ad,   -beta ad              ] mu = -( r_D            )
//   [-beta ad,     <b',b'> + beta^2 ad + ah]      ( r_H - beta r_D )
// (ad, ah = alpha~_D, alpha~_H; r = C + alpha~ lambda), whose determinant
// <a,a><b',b'> + <a,a>(beta^2 ad + ah) + ad <b',b'> + ad ah is a sum of
// non-negative terms: no cancellation even when the gradients are parallel
// and the material is stiff, where the usual form A_DD A_HH - A_DH^2 loses
// every digit in float. Then dx = W (a mu_1 + b' mu_2). The system is scaled
// by 1 / (its diagonal sum) before the products, against float overflow.
//
// All in float, like the GPU kernels; particles with w == 0 are never
// written (a colour's tets may share one); the measuring pass writes
// sqrt(r_D^2 + r_H^2) and changes nothing. No allocation.
#include "cpu/fem_kernels.h"

#include "fem_params.h"
#include "xpbd_params.h"

namespace sinew::kernels {
namespace {

using fem::mat3;
using fem::TetConstraints;

enum class Model { neo_hookean, stvk, corotational };

template <Model kModel>
void solve_tets(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  constexpr std::uint32_t stride =
      kModel == Model::corotational ? SINEW_FEM_COROTATIONAL_LAMBDA_STRIDE : SINEW_FEM_LAMBDA_STRIDE;
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* idx = reinterpret_cast<const uint4*>(bindings[1]);
  const auto* data = reinterpret_cast<const float*>(bindings[2]);
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const uint4 t = idx[i];
    const float* d = data + std::size_t{i} * SINEW_FEM_DATA_STRIDE;
    mat3<float> dm_inv;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) dm_inv.m[r][c] = d[SINEW_FEM_DM_INV + 3 * r + c];
    const float4 xs[4] = {x[t.x], x[t.y], x[t.z], x[t.w]};
    const mat3<float> f = fem::deformation_gradient(xs[0], xs[1], xs[2], xs[3], dm_inv);
    float* l = lambda + std::size_t{i} * stride;
    TetConstraints<float> c;
    if constexpr (kModel == Model::neo_hookean) {
      c = fem::neo_hookean_constraints(f, d[SINEW_FEM_H0]);
    } else if constexpr (kModel == Model::stvk) {
      c = fem::stvk_constraints(f, d[SINEW_FEM_H0]);
    } else {
      // The rotation: the exact one on the first solve (no quaternion kept
      // yet: all zero), then a few iterations from the last one. Kept by
      // every solving pass, never by the measuring one.
      float* kept = l + SINEW_FEM_ROTATION;
      fem::quat<float> q{kept[0], kept[1], kept[2], kept[3]};
      if (q.w == 0.0f && q.x == 0.0f && q.y == 0.0f && q.z == 0.0f) q = fem::rotation_quaternion(f);
      q = fem::refine_rotation(f, q, fem::kRotationIterations);
      if (!p.measure_only) kept[0] = q.w, kept[1] = q.x, kept[2] = q.y, kept[3] = q.z;
      c = fem::corotational_constraints(f, fem::quaternion_matrix(q), d[SINEW_FEM_H0]);
    }

    const float ad = d[SINEW_FEM_ALPHA_D] * p.inv_h2, ah = d[SINEW_FEM_ALPHA_H] * p.inv_h2;
    const float ld = p.reset_lambda ? 0.0f : l[0], lh = p.reset_lambda ? 0.0f : l[1];
    const float rd = c.c_d + ad * ld, rh = c.c_h + ah * lh;
    if (p.measure_only) {
      residual[i] = std::sqrt(rd * rd + rh * rh);
      continue;
    }

    float4 a[4], b[4];
    fem::position_gradients(c.dc_d, dm_inv, a);
    fem::position_gradients(c.dc_h, dm_inv, b);
    float aa = 0.0f, ab = 0.0f;
    for (int k = 0; k < 4; ++k) {
      aa += xs[k].w * dot3(a[k], a[k]);
      ab += xs[k].w * dot3(a[k], b[k]);
    }
    const float beta = aa > 0.0f ? ab / aa : 0.0f;
    float bb = 0.0f;  // <b', b'>_W
    for (int k = 0; k < 4; ++k) {
      b[k] = b[k] - beta * a[k];
      bb += xs[k].w * dot3(b[k], b[k]);
    }
    // Scaled by 1 / (sum of the diagonal terms), so that no product below
    // overflows float for tiny, light tets (<a,a> ~ w / cell^2 reaches 1e18).
    const float total = aa + bb + ad + ah;
    // total == 0 (or det == 0 below): nothing can move and nothing is
    // compliant (all four particles immovable with rigid constraints, or a
    // tet collapsed to a point): no direction to push along.
    if (!(total > 0.0f) || !std::isfinite(total)) {
      l[0] = ld;
      l[1] = lh;
      continue;
    }
    const float scale = 1.0f / total;
    const float saa = scale * aa, sbb = scale * bb, sad = scale * ad, sah = scale * ah;
    const float m11 = saa + sad, m12 = -beta * sad, m22 = sbb + beta * beta * sad + sah;
    const float det = saa * sbb + saa * (beta * beta * sad + sah) + sad * sbb + sad * sah;
    if (!(det > 0.0f)) {
      l[0] = ld;
      l[1] = lh;
      continue;
    }
    const float rhs1 = -scale * rd, rhs2 = -scale * (rh - beta * rd);
    const float mu1 = (m22 * rhs1 - m12 * rhs2) / det;
    const float mu2 = (m11 * rhs2 - m12 * rhs1) / det;
    const std::uint32_t ids[4] = {t.x, t.y, t.z, t.w};
    for (int k = 0; k < 4; ++k) {
      if (xs[k].w > 0.0f) {
        const float4 dx = mu1 * a[k] + mu2 * b[k];
        x[ids[k]] = add_scaled3(xs[k], xs[k].w, dx);
      }
    }
    l[0] = ld + (mu1 - beta * mu2);
    l[1] = lh + mu2;
  }
}

}  // namespace

void xpbd_solve_neo_hookean(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  solve_tets<Model::neo_hookean>(params, bindings, begin, end);
}

void xpbd_solve_stvk(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  solve_tets<Model::stvk>(params, bindings, begin, end);
}

void xpbd_solve_corotational(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  solve_tets<Model::corotational>(params, bindings, begin, end);
}

}  // namespace sinew::kernels
