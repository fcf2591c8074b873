// body_attachment_kernels.cpp — CPU reference kernel of the attachments
// between two bodies (BodyAttachmentDesc): a distance constraint
// |p_a - p_b| - rest length between a barycentric point of each body, with
// a breaking force.
// Macklin, Mueller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016 (the multiplier update and lambda / h^2 as
// the constraint force); the barycentric points as in iMSTK's
// PbdBaryPointToPointConstraint. Layout in kernels/shared/contact_params.h.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "contact_params.h"
#include "cpu/cpu_kernels.h"
#include "math/vec4.h"
#include "xpbd_params.h"

namespace sinew::kernels {
namespace {

float4 xyz(float4 v) { return {v.x, v.y, v.z, 0.0f}; }
float length3(float4 v) { return std::sqrt(dot3(v, v)); }

}  // namespace

void xpbd_solve_body_attachment(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* idx = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  auto* data = reinterpret_cast<float4*>(bindings[2]);  // wa, wb, (alpha, break force, broken, rest length)
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const std::uint32_t* q = &idx[8 * std::size_t{i}];
    const float4 wa = data[3 * std::size_t{i}], wb = data[3 * std::size_t{i} + 1];
    float4& extra = data[3 * std::size_t{i} + 2];
    if (extra.z != 0.0f) {  // broken: it holds nothing any more
      if (p.measure_only) residual[i] = 0.0f;
      else lambda[i] = 0.0f;
      continue;
    }
    const float4 a0 = x[q[0]], a1 = x[q[1]], a2 = x[q[2]], a3 = x[q[3]];
    const float4 b0 = x[q[4]], b1 = x[q[5]], b2 = x[q[6]], b3 = x[q[7]];
    const float4 pa = add_scaled3(add_scaled3(add_scaled3(wa.x * a0, wa.y, a1), wa.z, a2), wa.w, a3);
    const float4 pb = add_scaled3(add_scaled3(add_scaled3(wb.x * b0, wb.y, b1), wb.z, b2), wb.w, b3);
    const float4 d = xyz(pa - pb);
    const float len = length3(d);
    const float c = len - extra.w;  // extra.w: the rest length
    const float alpha_t = extra.x * p.inv_h2;
    const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
    if (p.measure_only) {
      residual[i] = std::abs(c + alpha_t * lambda_i);  // [m]: not normalised (the rest length may be 0)
      continue;
    }
    const float weight_a = wa.x * wa.x * a0.w + wa.y * wa.y * a1.w + wa.z * wa.z * a2.w + wa.w * wa.w * a3.w;
    const float weight_b = wb.x * wb.x * b0.w + wb.y * wb.y * b1.w + wb.z * wb.z * b2.w + wb.w * wb.w * b3.w;
    const float weight = weight_a + weight_b;
    // On each other the gradient is undefined (and C = 0 at rest length
    // 0); with every particle immovable nothing can move.
    if (!(len > 0.0f) || !(weight > 0.0f)) {
      lambda[i] = lambda_i;
      continue;
    }
    const float dlambda = (-c - alpha_t * lambda_i) / (weight + alpha_t);
    const float s = dlambda / len;  // along d: the unit normal's step
    // A zero weight (an unused slot, which repeats the side's first
    // particle) writes nothing, so no particle is written twice.
    if (a0.w > 0.0f && wa.x != 0.0f) x[q[0]] = add_scaled3(a0, a0.w * wa.x * s, d);
    if (a1.w > 0.0f && wa.y != 0.0f) x[q[1]] = add_scaled3(a1, a1.w * wa.y * s, d);
    if (a2.w > 0.0f && wa.z != 0.0f) x[q[2]] = add_scaled3(a2, a2.w * wa.z * s, d);
    if (a3.w > 0.0f && wa.w != 0.0f) x[q[3]] = add_scaled3(a3, a3.w * wa.w * s, d);
    if (b0.w > 0.0f && wb.x != 0.0f) x[q[4]] = add_scaled3(b0, -(b0.w * wb.x * s), d);
    if (b1.w > 0.0f && wb.y != 0.0f) x[q[5]] = add_scaled3(b1, -(b1.w * wb.y * s), d);
    if (b2.w > 0.0f && wb.z != 0.0f) x[q[6]] = add_scaled3(b2, -(b2.w * wb.z * s), d);
    if (b3.w > 0.0f && wb.w != 0.0f) x[q[7]] = add_scaled3(b3, -(b3.w * wb.w * s), d);
    const float lambda_new = lambda_i + dlambda;
    lambda[i] = lambda_new;
    // The constraint force |lambda| / h^2 [N] past the breaking force: the
    // attachment lets go, for good (the flag stays on the device).
    if (extra.y > 0.0f && std::abs(lambda_new) * p.inv_h2 > extra.y) extra.z = 1.0f;
  }
}

}  // namespace sinew::kernels
