// thin_kernels.cpp — CPU reference kernels of thin bodies and threads.
//
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016, eq. 18: for one constraint C with
// compliance alpha, alpha~ = alpha / h^2 and
//   dlambda = (-C - alpha~ lambda) / (sum_i w_i |grad_i C|^2 + alpha~),
//   dx_i    = w_i grad_i C dlambda.
// The constraints (area, dihedral angle, Kelager line bending) and their
// gradients are in kernels/math/thin_math.h, the data layouts in
// kernels/shared/thin_params.h. Each work item solves one constraint; a
// dispatch covers one colour, whose constraints share no movable particle.
// All in float, like the GPU kernels; particles with w == 0 are never
// written (a colour's constraints may share one); a constraint with no
// direction (a collapsed triangle, a straight hinge edge of zero length, a
// thread vertex exactly at its centroid) or with nothing movable and no
// compliance keeps its lambda and moves nothing; the measuring pass writes
// the residual (normalised as thin_params.h says) and changes nothing.
#include "cpu/thin_kernels.h"

#include "thin_params.h"
#include "xpbd_params.h"

namespace sinew::kernels {
namespace {

// The xPBD step of one constraint over N particles with gradients g; with
// nothing to do (see below) it stores lambda unchanged and moves nothing.
template <int N>
void apply(float4* x, const std::uint32_t* ids, const float4* xs, const float4* g, float c, float alpha_t,
           float lambda_i, float* lambda_out) {
  float w = 0.0f;
  for (int k = 0; k < N; ++k) w += xs[k].w * dot3(g[k], g[k]);
  const float total = w + alpha_t;
  // total == 0: all immovable and rigid; not finite: a gradient overflowed
  // (a near-degenerate element in float): no usable direction.
  if (!(total > 0.0f) || !std::isfinite(total)) {
    *lambda_out = lambda_i;
    return;
  }
  const float dlambda = (-c - alpha_t * lambda_i) / total;
  for (int k = 0; k < N; ++k)
    if (xs[k].w > 0.0f) x[ids[k]] = add_scaled3(xs[k], xs[k].w * dlambda, g[k]);
  *lambda_out = lambda_i + dlambda;
}

}  // namespace

void xpbd_solve_area(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* idx = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* data = reinterpret_cast<const float*>(bindings[2]);
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const std::uint32_t* ids = idx + std::size_t{i} * 3;
    const float* d = data + std::size_t{i} * SINEW_AREA_DATA_STRIDE;
    const float4 xs[3] = {x[ids[0]], x[ids[1]], x[ids[2]]};
    const float alpha_t = d[1] * p.inv_h2;
    const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
    const float c = thin::triangle_area(xs[0], xs[1], xs[2]) - d[0];  // rounds as the rest area did
    if (p.measure_only) {
      residual[i] = std::abs(c + alpha_t * lambda_i) / d[0];
      continue;
    }
    float4 g[3];
    if (!thin::triangle_area_gradients(xs[0], xs[1], xs[2], g)) {
      lambda[i] = lambda_i;
      continue;
    }
    apply<3>(x, ids, xs, g, c, alpha_t, lambda_i, &lambda[i]);
  }
}

void xpbd_solve_dihedral(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* idx = reinterpret_cast<const uint4*>(bindings[1]);
  const auto* data = reinterpret_cast<const float*>(bindings[2]);
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const uint4 h = idx[i];
    const std::uint32_t ids[4] = {h.x, h.y, h.z, h.w};
    const float* d = data + std::size_t{i} * SINEW_DIHEDRAL_DATA_STRIDE;
    const float4 xs[4] = {x[h.x], x[h.y], x[h.z], x[h.w]};
    const float alpha_t = d[1] * p.inv_h2;
    const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
    // Wrapped, so that a hinge at rest near +-pi has no jump; 0 exactly at rest.
    const float c = thin::wrap_angle(thin::dihedral_angle(xs[0], xs[1], xs[2], xs[3]) - d[0]);
    if (p.measure_only) {
      residual[i] = std::abs(c + alpha_t * lambda_i);  // radians
      continue;
    }
    float4 g[4];
    if (!thin::dihedral_angle_gradients(xs[0], xs[1], xs[2], xs[3], g)) {
      lambda[i] = lambda_i;
      continue;
    }
    apply<4>(x, ids, xs, g, c, alpha_t, lambda_i, &lambda[i]);
  }
}

void xpbd_solve_line_bending(const void* params, std::byte* const* bindings, std::uint32_t begin,
                             std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* idx = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* data = reinterpret_cast<const float*>(bindings[2]);
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const std::uint32_t* ids = idx + std::size_t{i} * 3;
    const float* d = data + std::size_t{i} * SINEW_LINE_BENDING_DATA_STRIDE;
    const float4 xs[3] = {x[ids[0]], x[ids[1]], x[ids[2]]};
    const float alpha_t = d[1] * p.inv_h2;
    const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
    const float c = thin::line_bending_offset(xs[0], xs[1], xs[2]) - d[0];
    if (p.measure_only) {
      residual[i] = std::abs(c + alpha_t * lambda_i) / d[2];  // per segment rest length
      continue;
    }
    float4 g[3];
    if (!thin::line_bending_gradients(xs[0], xs[1], xs[2], g)) {
      lambda[i] = lambda_i;
      continue;
    }
    apply<3>(x, ids, xs, g, c, alpha_t, lambda_i, &lambda[i]);
  }
}

}  // namespace sinew::kernels
