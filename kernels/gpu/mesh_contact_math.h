/* mesh_contact_math.h — one contact between meshes solved once, shared by
 * xpbd_solve_mesh_contacts.gpu (Gauss-Seidel, writes the positions) and
 * xpbd_mesh_contacts_jacobi.gpu (Jacobi, writes the corrections); twin of
 * solve_contact in kernels/cpu/mesh_contact_kernels.cpp, same operation
 * order, every result PRECISE. Formulation: kernels/shared/mesh_contact_params.h
 * (Macklin et al., "XPBD", MIG 2016; "Unified Particle Physics", 2014). */
#ifndef SINEW_MESH_CONTACT_MATH_H
#define SINEW_MESH_CONTACT_MATH_H

#include "vec_math.h"
#include "mesh_contact_params.h"

/* The four particles' new positions and the contact's new multipliers. */
SINEW_STRUCT_BEGIN(MeshContactStep)
  float3 z0;
  float3 z1;
  float3 z2;
  float3 z3;
  float4 lambda;
SINEW_STRUCT_END(MeshContactStep)

MeshContactStep mesh_contact_solve(float4 x0, float4 x1, float4 x2, float4 x3, float3 prev0, float3 prev1,
                                   float3 prev2, float3 prev3, float4 c, float3 n, float offset,
                                   float4 lambda_i, MeshContactParams p) {
  MeshContactStep result;
  result.z0 = x0.xyz;
  result.z1 = x1.xyz;
  result.z2 = x2.xyz;
  result.z3 = x3.xyz;
  PRECISE float alpha_t = p.compliance * p.inv_h2;
  const float lambda_n = lambda_i.x;
  const float3 lambda_t = make_float3(lambda_i.y, lambda_i.z, lambda_i.w);
  PRECISE float weight = x0.w * (c.x * c.x) + x1.w * (c.y * c.y) + x2.w * (c.z * c.z) + x3.w * (c.w * c.w);
  PRECISE float3 gap_vector = c.x * x0.xyz;
  gap_vector = gap_vector + c.y * x1.xyz;
  gap_vector = gap_vector + c.z * x2.xyz;
  gap_vector = gap_vector + c.w * x3.xyz;
  PRECISE float constraint = dot3(n, gap_vector) + offset - p.thickness;
  float lambda_n_new = 0.0f;
  float3 lambda_t_new = make_float3(0.0f, 0.0f, 0.0f);
  if ((lambda_n > 0.0f || constraint < 0.0f) && weight > 0.0f) {
    PRECISE float step_n = lambda_n + (-constraint - alpha_t * lambda_n) / (weight + alpha_t);
    lambda_n_new = step_n > 0.0f ? step_n : 0.0f;
    PRECISE float dn = lambda_n_new - lambda_n;
    PRECISE float3 y0 = x0.xyz + (x0.w * c.x * dn) * n;
    PRECISE float3 y1 = x1.xyz + (x1.w * c.y * dn) * n;
    PRECISE float3 y2 = x2.xyz + (x2.w * c.z * dn) * n;
    PRECISE float3 y3 = x3.xyz + (x3.w * c.w * dn) * n;
    if (lambda_n_new > 0.0f) {
      PRECISE float3 moved = c.x * (y0 - prev0);
      moved = moved + c.y * (y1 - prev1);
      moved = moved + c.z * (y2 - prev2);
      moved = moved + c.w * (y3 - prev3);
      PRECISE float along = dot3(moved, n);
      PRECISE float3 moved_t = moved - along * n;
      PRECISE float inv_weight = 1.0f / weight;
      PRECISE float3 cancel = lambda_t - inv_weight * moved_t;
      lambda_t_new = cancel;
      PRECISE float len = sqrt(dot3(lambda_t_new, lambda_t_new));
      PRECISE float cone = p.static_friction * lambda_n_new;
      if (len > cone) {
        PRECISE float scale = len > 0.0f ? p.dynamic_friction * lambda_n_new / len : 0.0f;
        PRECISE float3 kinetic = scale * lambda_t_new;
        lambda_t_new = kinetic;
      }
    }
    PRECISE float3 dt = lambda_t_new - lambda_t;
    PRECISE float3 z0 = y0 + (x0.w * c.x) * dt;
    PRECISE float3 z1 = y1 + (x1.w * c.y) * dt;
    PRECISE float3 z2 = y2 + (x2.w * c.z) * dt;
    PRECISE float3 z3 = y3 + (x3.w * c.w) * dt;
    result.z0 = z0;
    result.z1 = z1;
    result.z2 = z2;
    result.z3 = z3;
  }
  result.lambda = make_float4(lambda_n_new, lambda_t_new.x, lambda_t_new.y, lambda_t_new.z);
  return result;
}

#endif /* SINEW_MESH_CONTACT_MATH_H */
