// mesh_contact_kernels.cpp — CPU reference kernels of the contacts between
// deformable meshes (vertex-triangle and edge-edge); layout and formulation
// in kernels/shared/mesh_contact_params.h.
//
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016 (the inequality's multiplier clamped to
// lambda_n >= 0); Macklin, Müller, Chentanez, Kim, "Unified Particle Physics
// for Real-Time Applications", SIGGRAPH 2014, eq. 24-25 (Coulomb friction at
// position level, kept as an accumulated multiplier as in
// contact_kernels.cpp) and section 4.2 (Jacobi iteration with averaging).
//
// Two schedules of the same solve (MeshCollisionDesc::schedule):
//  - xpbd_solve_mesh_contacts: one work item per contact of one colour (the
//    host coloured the frame's contacts so that no two of a colour share a
//    movable particle): Gauss-Seidel, each contact sees the corrections of
//    the colours before it;
//  - xpbd_mesh_contacts_jacobi + xpbd_mesh_contacts_gather: every contact
//    from the same positions, then each touched particle moves by the mean
//    of its contacts' corrections. Two dispatches per sweep however many
//    colours the contacts would need.
// Neither depends on the thread count: every item writes only its own slots.
#include <algorithm>
#include <cmath>

#include "cpu/cpu_kernels.h"
#include "math/vec4.h"
#include "mesh_contact_params.h"

namespace sinew::kernels {
namespace {

struct Step {
  float4 z[4];    // the particles' new positions
  float4 lambda;  // (lambda_n, lambda_t xyz)
};

// One contact solved once from positions xk (w = inverse mass) and the
// substep's start positions prev, in the GPU kernels' operation order
// (kernels/gpu/mesh_contact_math.h).
Step solve_contact(const float4 (&xk)[4], const float4 (&prev)[4], const float (&c)[4], float4 n, float offset,
                   float4 lambda_i, const MeshContactParams& p) {
  Step out{{xk[0], xk[1], xk[2], xk[3]}, {}};
  const float alpha_t = p.compliance * p.inv_h2;
  const float lambda_n = lambda_i.x;
  const float4 lambda_t{lambda_i.y, lambda_i.z, lambda_i.w, 0.0f};
  const float weight = xk[0].w * (c[0] * c[0]) + xk[1].w * (c[1] * c[1]) + xk[2].w * (c[2] * c[2]) +
                       xk[3].w * (c[3] * c[3]);
  float4 gap_vector = c[0] * xk[0];
  gap_vector = gap_vector + c[1] * xk[1];
  gap_vector = gap_vector + c[2] * xk[2];
  gap_vector = gap_vector + c[3] * xk[3];
  const float constraint = dot3(n, gap_vector) + offset - p.thickness;
  float lambda_n_new = 0.0f;
  float4 lambda_t_new{0.0f, 0.0f, 0.0f, 0.0f};
  // Touching, or pushed earlier in this substep; nothing movable: nothing to do.
  if ((lambda_n > 0.0f || constraint < 0.0f) && weight > 0.0f) {
    const float step_n = lambda_n + (-constraint - alpha_t * lambda_n) / (weight + alpha_t);
    lambda_n_new = step_n > 0.0f ? step_n : 0.0f;
    const float dn = lambda_n_new - lambda_n;
    float4 y[4];
    for (int k = 0; k < 4; ++k) y[k] = add_scaled3(xk[k], xk[k].w * c[k] * dn, n);
    // Friction: the closest points' relative motion over the substep,
    // cancelled inside the static cone, reduced to the kinetic one outside.
    if (lambda_n_new > 0.0f) {
      float4 moved = c[0] * (y[0] - prev[0]);
      moved = moved + c[1] * (y[1] - prev[1]);
      moved = moved + c[2] * (y[2] - prev[2]);
      moved = moved + c[3] * (y[3] - prev[3]);
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
    for (int k = 0; k < 4; ++k) out.z[k] = add_scaled3(y[k], xk[k].w * c[k], dt);
  }
  out.lambda = float4{lambda_n_new, lambda_t_new.x, lambda_t_new.y, lambda_t_new.z};
  return out;
}

// Contact i's particles, their positions and the solve, as both schedules
// read them; in a substep's first sweep the last substep's lambda is added
// to the frame's sum at `sum` (or the sum zeroed in the frame's first).
Step solve_item(std::uint32_t i, const MeshContactParams& p, std::byte* const* bindings, float4* sum,
                const float* motion, const std::uint32_t*& v, float4 (&xk)[4]) {
  const auto* x = reinterpret_cast<const float4*>(bindings[0]);
  const auto* prev = reinterpret_cast<const float4*>(bindings[1]);
  const auto* particles = reinterpret_cast<const std::uint32_t*>(bindings[3]);  // 4 per contact
  const auto* coefficients = reinterpret_cast<const float4*>(bindings[4]);
  const auto* normals = reinterpret_cast<const float4*>(bindings[5]);
  const auto* lambda = reinterpret_cast<const float4*>(bindings[6]);
  v = particles + std::size_t{i} * 4;
  float4 before[4];
  for (int k = 0; k < 4; ++k) xk[k] = x[v[k]], before[k] = prev[v[k]];
  const float c[4] = {coefficients[i].x, coefficients[i].y, coefficients[i].z, coefficients[i].w};
  const float4 n{normals[i].x, normals[i].y, normals[i].z, 0.0f};
  const float4 lambda_old = lambda[i];
  if (p.reset_lambda == 2u) sum[i] = float4{0.0f, 0.0f, 0.0f, 0.0f};
  if (p.reset_lambda == 1u) sum[i] = sum[i] + lambda_old;
  const float4 lambda_i = p.reset_lambda != 0u ? float4{0.0f, 0.0f, 0.0f, 0.0f} : lambda_old;
  return solve_contact(xk, before, c, n, normals[i].w + motion[i] * (1.0f - p.substep_end), lambda_i, p);
}

}  // namespace

void xpbd_solve_mesh_contacts(const void* params, std::byte* const* bindings, std::uint32_t begin,
                              std::uint32_t end) {
  const auto& p = *static_cast<const MeshContactParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* table = reinterpret_cast<const std::uint32_t*>(bindings[2]);
  auto* lambda = reinterpret_cast<float4*>(bindings[6]);
  auto* sum = reinterpret_cast<float4*>(bindings[7]);
  const auto* motion = reinterpret_cast<const float*>(bindings[8]);
  const auto* order = reinterpret_cast<const std::uint32_t*>(bindings[9]);
  const std::uint32_t count = table[p.color];
  const std::uint32_t first = table[p.colors + p.color];
  // Item k solves slot k; serially, item 0 solves every slot in order.
  const std::uint32_t from = p.serial != 0u ? 0u : begin;
  const std::uint32_t to = p.serial != 0u ? (begin == 0u && end > 0u ? count : 0u) : std::min(end, count);
  for (std::uint32_t item = from; item < to; ++item) {
    const std::uint32_t i = p.ordered != 0u ? order[first + item] : first + item;
    const std::uint32_t* v = nullptr;
    float4 xk[4];
    const Step s = solve_item(i, p, bindings, sum, motion, v, xk);
    // Immovable particles are never written (contacts of a colour may share one).
    for (int k = 0; k < 4; ++k)
      if (xk[k].w > 0.0f) x[v[k]] = float4{s.z[k].x, s.z[k].y, s.z[k].z, xk[k].w};
    lambda[i] = s.lambda;
  }
}

void xpbd_mesh_contacts_jacobi(const void* params, std::byte* const* bindings, std::uint32_t begin,
                               std::uint32_t end) {
  const auto& p = *static_cast<const MeshContactParams*>(params);
  const auto* table = reinterpret_cast<const std::uint32_t*>(bindings[2]);
  auto* lambda = reinterpret_cast<float4*>(bindings[6]);
  auto* delta = reinterpret_cast<float4*>(bindings[7]);  // 4 per contact
  auto* sum = reinterpret_cast<float4*>(bindings[8]);
  const auto* motion = reinterpret_cast<const float*>(bindings[9]);
  for (std::uint32_t i = begin; i < std::min(end, table[0]); ++i) {
    const std::uint32_t* v = nullptr;
    float4 xk[4];
    const Step s = solve_item(i, p, bindings, sum, motion, v, xk);
    for (int k = 0; k < 4; ++k)
      delta[4 * std::size_t{i} + k] = float4{s.z[k].x - xk[k].x, s.z[k].y - xk[k].y, s.z[k].z - xk[k].z, 0.0f};
    lambda[i] = s.lambda;
  }
}

void xpbd_mesh_contacts_gather(const void* /*params*/, std::byte* const* bindings, std::uint32_t begin,
                               std::uint32_t end) {
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* table = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* touched = reinterpret_cast<const std::uint32_t*>(bindings[2]);
  const auto* offsets = reinterpret_cast<const std::uint32_t*>(bindings[3]);
  const auto* slots = reinterpret_cast<const std::uint32_t*>(bindings[4]);
  const auto* delta = reinterpret_cast<const float4*>(bindings[5]);
  for (std::uint32_t j = begin; j < std::min(end, table[1]); ++j) {
    float4 sum{0.0f, 0.0f, 0.0f, 0.0f};
    for (std::uint32_t k = offsets[j]; k < offsets[j + 1]; ++k) sum = sum + delta[slots[k]];
    const float share = 1.0f / static_cast<float>(offsets[j + 1] - offsets[j]);
    x[touched[j]] = add_scaled3(x[touched[j]], share, sum);
  }
}

}  // namespace sinew::kernels
