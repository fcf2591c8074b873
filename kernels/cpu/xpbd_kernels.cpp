// xpbd_kernels.cpp — CPU reference kernels of the xPBD solver.
//
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016, eq. 18: for one constraint C with
// compliance alpha, alpha~ = alpha / h^2 and
//   dlambda = (-C - alpha~ lambda) / (sum_i w_i |grad_i C|^2 + alpha~),
//   dx_i    = w_i grad_i C dlambda.
// With damping (SolveParams::damping = gamma != 0), eq. 26:
//   dlambda = (-C - alpha~ lambda - gamma grad C . (x - x_prev)) /
//             ((1 + gamma) sum_i w_i |grad_i C|^2 + alpha~).
// Each work item solves one constraint. All constraints of one dispatch have
// one colour, so no two share a movable particle: the writes never race and
// the result does not depend on how items are split across threads.
#include "cpu/xpbd_kernels.h"

#include "xpbd_params.h"

namespace sinew::kernels {

void xpbd_predict(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const PredictParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  auto* prev = reinterpret_cast<float4*>(bindings[1]);
  auto* v = reinterpret_cast<float4*>(bindings[2]);
  const float4 g{p.gravity_x, p.gravity_y, p.gravity_z, 0.0f};
  for (std::uint32_t i = begin; i < end; ++i) {
    prev[i] = x[i];
    if (x[i].w == 0.0f) continue;  // pinned or kinematic: inverse mass 0
    // Damping scales the velocity carried from the last substep, not
    // gravity's impulse: damping (v + h g) would balance a body at rest
    // against d g instead of g, and a 1-substep frame with k = 20 1/s
    // sagged 28% less than its material (d = exp(-k h) = 0.72).
    const float d = v[i].w;  // velocity damping factor (1: none, and then exact)
    const float4 damped{v[i].x * d, v[i].y * d, v[i].z * d, d};
    v[i] = add_scaled3(damped, p.h, g);
    x[i] = add_scaled3(x[i], p.h, v[i]);
  }
}

void xpbd_external_force(const void* params, std::byte* const* bindings, std::uint32_t begin,
                         std::uint32_t end) {
  const auto& p = *static_cast<const ExternalForceParams*>(params);
  const auto* x = reinterpret_cast<const float4*>(bindings[0]);
  const auto* f = reinterpret_cast<const float4*>(bindings[1]);
  auto* v = reinterpret_cast<float4*>(bindings[2]);
  for (std::uint32_t i = begin; i < end; ++i) {
    // w > 0 rather than != 0: a pinned or kinematic particle (w == 0) is
    // moved by the host alone, so a force on it does nothing.
    if (!(x[i].w > 0.0f)) continue;
    // The impulse h f / m = (h w) f, as the GPU twin rounds it; v.w (the
    // damping factor) is kept, and xpbd_predict damps this impulse with
    // the rest of the velocity.
    const float s = p.h * x[i].w;
    v[i] = add_scaled3(v[i], s, f[i]);
  }
}

void xpbd_update_velocity(const void* params, std::byte* const* bindings, std::uint32_t begin,
                          std::uint32_t end) {
  const auto& p = *static_cast<const UpdateVelocityParams*>(params);
  const auto* x = reinterpret_cast<const float4*>(bindings[0]);
  const auto* prev = reinterpret_cast<const float4*>(bindings[1]);
  auto* v = reinterpret_cast<float4*>(bindings[2]);
  for (std::uint32_t i = begin; i < end; ++i) {
    const float4 vp = v[i];  // the predicted velocity; w: the damping factor, kept
    if (x[i].w == 0.0f) {
      v[i] = float4{0.0f, 0.0f, 0.0f, vp.w};
      continue;
    }
    // Why not (x - prev) / h: x is a float near |x|, so that quotient
    // carries ~ulp(|x|) / h of rounding (1e-4 m/s at 0.1 m and 128 substeps
    // of a 60 Hz frame), and velocity changes smaller than that, such as a
    // substep's damping, vanish. Here only the constraints' correction
    // x - x_p goes through a float position; v_p, and with it inertia,
    // gravity and damping, is carried exactly. x_p is recomputed with
    // xpbd_predict's very operation (prev is x as predict found it).
    const float4 d = x[i] - add_scaled3(prev[i], p.h, vp);
    v[i] = float4{vp.x + d.x * p.inv_h, vp.y + d.y * p.inv_h, vp.z + d.z * p.inv_h, vp.w};
  }
}

void xpbd_solve_distance(const void* params, std::byte* const* bindings, std::uint32_t begin,
                         std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* idx = reinterpret_cast<const uint2*>(bindings[1]);
  const auto* rest_alpha = reinterpret_cast<const float2*>(bindings[2]);
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  const auto* prev = reinterpret_cast<const float4*>(bindings[5]);
  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const uint2 e = idx[i];
    const float4 xa = x[e.x];
    const float4 xb = x[e.y];
    const float len = edge_length(xa, xb);
    const float w = xa.w + xb.w;
    const float alpha_t = rest_alpha[i].y * p.inv_h2;
    const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
    // A zero-length edge has no direction to push along; a constraint
    // between two immovable particles (w == 0 and alpha == 0) has nothing to do.
    const float c = len - rest_alpha[i].x;
    if (p.measure_only) {
      residual[i] = std::abs(c + alpha_t * lambda_i) / rest_alpha[i].x;
      continue;
    }
    if (len <= 0.0f || w + alpha_t <= 0.0f) {
      lambda[i] = lambda_i;
      continue;
    }
    const float4 n = edge_length_gradient(xa, xb, len);  // grad_a C = n, grad_b C = -n
    float dlambda;
    if (p.damping == 0.0f) {
      dlambda = (-c - alpha_t * lambda_i) / (w + alpha_t);
    } else {  // eq. 26: the constraint's rate over the substep, damped
      const float rate = dot3(n, (xa - prev[e.x]) - (xb - prev[e.y]));
      dlambda = (-c - alpha_t * lambda_i - p.damping * rate) / ((1.0f + p.damping) * w + alpha_t);
    }
    // Immovable particles (w == 0) are never written: two constraints of one
    // colour may share one, and a write would race (even with equal bytes).
    if (xa.w > 0.0f) x[e.x] = add_scaled3(xa, xa.w * dlambda, n);
    if (xb.w > 0.0f) x[e.y] = add_scaled3(xb, -xb.w * dlambda, n);
    lambda[i] = lambda_i + dlambda;
  }
}

void xpbd_solve_volume(const void* params, std::byte* const* bindings, std::uint32_t begin,
                       std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* idx = reinterpret_cast<const uint4*>(bindings[1]);
  const auto* rest_alpha = reinterpret_cast<const float2*>(bindings[2]);
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  const auto* prev = reinterpret_cast<const float4*>(bindings[5]);
  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const uint4 t = idx[i];
    const float4 x0 = x[t.x], x1 = x[t.y], x2 = x[t.z], x3 = x[t.w];
    float4 g[4];
    tet_volume_gradients(x0, x1, x2, x3, g);
    const float w = x0.w * dot3(g[0], g[0]) + x1.w * dot3(g[1], g[1]) + x2.w * dot3(g[2], g[2]) + x3.w * dot3(g[3], g[3]);
    const float alpha_t = rest_alpha[i].y * p.inv_h2;
    const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
    const float c = tet_volume(x0, x1, x2, x3) - rest_alpha[i].x;  // rounds as the rest volume did
    if (p.measure_only) {
      residual[i] = std::abs(c + alpha_t * lambda_i) / rest_alpha[i].x;
      continue;
    }
    if (w + alpha_t <= 0.0f) {  // fully collapsed or immovable: no direction
      lambda[i] = lambda_i;
      continue;
    }
    float dlambda;
    if (p.damping == 0.0f) {
      dlambda = (-c - alpha_t * lambda_i) / (w + alpha_t);
    } else {  // eq. 26: the volume's rate over the substep, damped
      const float rate = dot3(g[0], x0 - prev[t.x]) + dot3(g[1], x1 - prev[t.y]) + dot3(g[2], x2 - prev[t.z]) +
                         dot3(g[3], x3 - prev[t.w]);
      dlambda = (-c - alpha_t * lambda_i - p.damping * rate) / ((1.0f + p.damping) * w + alpha_t);
    }
    if (x0.w > 0.0f) x[t.x] = add_scaled3(x0, x0.w * dlambda, g[0]);
    if (x1.w > 0.0f) x[t.y] = add_scaled3(x1, x1.w * dlambda, g[1]);
    if (x2.w > 0.0f) x[t.z] = add_scaled3(x2, x2.w * dlambda, g[2]);
    if (x3.w > 0.0f) x[t.w] = add_scaled3(x3, x3.w * dlambda, g[3]);
    lambda[i] = lambda_i + dlambda;
  }
}

}  // namespace sinew::kernels
