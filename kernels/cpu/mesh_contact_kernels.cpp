// mesh_contact_kernels.cpp — CPU reference kernel of the contacts between
// deformable meshes (vertex-triangle and edge-edge), layout and formulation
// in kernels/shared/mesh_contact_params.h.
//
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016 (the inequality's multiplier clamped to
// lambda_n >= 0); Macklin, Müller, Chentanez, Kim, "Unified Particle Physics
// for Real-Time Applications", SIGGRAPH 2014, eq. 24-25 (Coulomb friction at
// position level, kept as an accumulated multiplier as in contact_kernels.cpp).
//
// One work item per contact of one colour: the host coloured the frame's
// contacts so that no two of a colour share a movable particle, so every
// item writes its own particles and nothing depends on the thread count.
#include <algorithm>
#include <cmath>

#include "cpu/cpu_kernels.h"
#include "math/vec4.h"
#include "mesh_contact_params.h"

namespace sinew::kernels {

void xpbd_solve_mesh_contacts(const void* params, std::byte* const* bindings, std::uint32_t begin,
                              std::uint32_t end) {
  const auto& p = *static_cast<const MeshContactParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* prev = reinterpret_cast<const float4*>(bindings[1]);
  const auto* table = reinterpret_cast<const std::uint32_t*>(bindings[2]);
  const auto* particles = reinterpret_cast<const std::uint32_t*>(bindings[3]);  // 4 per contact
  const auto* coefficients = reinterpret_cast<const float4*>(bindings[4]);
  const auto* normals = reinterpret_cast<const float4*>(bindings[5]);
  auto* lambda = reinterpret_cast<float4*>(bindings[6]);
  const std::uint32_t count = table[p.color];
  const std::uint32_t first = table[p.colors + p.color];
  const float alpha_t = p.compliance * p.inv_h2;
  for (std::uint32_t item = begin; item < std::min(end, count); ++item) {
    const std::uint32_t i = first + item;
    const std::uint32_t* v = particles + std::size_t{i} * 4;
    const float c[4] = {coefficients[i].x, coefficients[i].y, coefficients[i].z, coefficients[i].w};
    const float4 n{normals[i].x, normals[i].y, normals[i].z, 0.0f};
    float4 xk[4];
    for (int k = 0; k < 4; ++k) xk[k] = x[v[k]];
    const float4 lambda_i = p.reset_lambda ? float4{0.0f, 0.0f, 0.0f, 0.0f} : lambda[i];
    float lambda_n = lambda_i.x;
    float4 lambda_t{lambda_i.y, lambda_i.z, lambda_i.w, 0.0f};

    // W = sum w_k c_k^2, in a fixed order (the GPU kernel's).
    const float weight = xk[0].w * (c[0] * c[0]) + xk[1].w * (c[1] * c[1]) + xk[2].w * (c[2] * c[2]) +
                         xk[3].w * (c[3] * c[3]);
    float4 gap_vector = c[0] * xk[0];
    gap_vector = gap_vector + c[1] * xk[1];
    gap_vector = gap_vector + c[2] * xk[2];
    gap_vector = gap_vector + c[3] * xk[3];
    const float constraint = dot3(n, gap_vector) - p.thickness;
    float lambda_n_new = 0.0f;
    float4 lambda_t_new{0.0f, 0.0f, 0.0f, 0.0f};
    // Touching, or pushed earlier in this substep; nothing movable: nothing to do.
    if ((lambda_n > 0.0f || constraint < 0.0f) && weight > 0.0f) {
      const float step_n = lambda_n + (-constraint - alpha_t * lambda_n) / (weight + alpha_t);
      lambda_n_new = step_n > 0.0f ? step_n : 0.0f;
      const float dn = lambda_n_new - lambda_n;
      for (int k = 0; k < 4; ++k) xk[k] = add_scaled3(xk[k], xk[k].w * c[k] * dn, n);

      // Friction: the closest points' relative motion over the substep,
      // cancelled inside the static cone, reduced to the kinetic one outside.
      if (lambda_n_new > 0.0f) {
        float4 moved = c[0] * (xk[0] - prev[v[0]]);
        moved = moved + c[1] * (xk[1] - prev[v[1]]);
        moved = moved + c[2] * (xk[2] - prev[v[2]]);
        moved = moved + c[3] * (xk[3] - prev[v[3]]);
        const float along = dot3(moved, n);
        const float4 moved_t{moved.x - along * n.x, moved.y - along * n.y, moved.z - along * n.z, 0.0f};
        const float inv_weight = 1.0f / weight;
        lambda_t_new = float4{lambda_t.x - inv_weight * moved_t.x, lambda_t.y - inv_weight * moved_t.y,
                              lambda_t.z - inv_weight * moved_t.z, 0.0f};
        const float len = std::sqrt(dot3(lambda_t_new, lambda_t_new));
        const float cone = p.static_friction * lambda_n_new;
        if (len > cone) {
          const float scale = len > 0.0f ? p.dynamic_friction * lambda_n_new / len : 0.0f;
          lambda_t_new = float4{scale * lambda_t_new.x, scale * lambda_t_new.y, scale * lambda_t_new.z, 0.0f};
        }
      }
      const float4 dt{lambda_t_new.x - lambda_t.x, lambda_t_new.y - lambda_t.y, lambda_t_new.z - lambda_t.z, 0.0f};
      for (int k = 0; k < 4; ++k) xk[k] = add_scaled3(xk[k], xk[k].w * c[k], dt);
      // Immovable particles are never written (contacts of a colour may share one).
      for (int k = 0; k < 4; ++k)
        if (xk[k].w > 0.0f) x[v[k]] = xk[k];
    }
    lambda[i] = float4{lambda_n_new, lambda_t_new.x, lambda_t_new.y, lambda_t_new.z};
  }
}

}  // namespace sinew::kernels
