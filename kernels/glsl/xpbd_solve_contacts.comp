// xpbd_solve_contacts.comp — GLSL twin of
// kernels/cpu/contact_kernels.cpp:xpbd_solve_contacts (and the OpenCL one):
// contacts of particles with analytic colliders (plane, sphere, capsule,
// box) and tools (capsules).
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016: the normal multiplier clamped to
// lambda_n >= 0. Macklin, Müller, Chentanez, Kim, "Unified Particle Physics
// for Real-Time Applications", SIGGRAPH 2014, eq. 24-25: Coulomb friction at
// position level, kept as an accumulated multiplier lambda_t clamped to the
// static / kinetic cone (see kernels/shared/contact_params.h).
//
// One invocation per movable particle (all in one colour), every collider in
// turn. The impulses a particle gives the tools go to that particle's own
// slots (particle * tools + tool), written by this invocation only: no
// atomics, no race; the host reduces them in particle order
// (simulation_contacts.cpp).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "contact_math.h"
#include "xpbd_params.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { SolveParams p; };
layout(std430, binding = 0) buffer Position { vec4 x[]; };
layout(std430, binding = 1) readonly buffer Indices { uint idx[]; };
layout(std430, binding = 2) readonly buffer Margin { float margin[]; };
layout(std430, binding = 3) buffer Lambda { float lambda[]; };
layout(std430, binding = 4) writeonly buffer Residual { float residual[]; };
layout(std430, binding = 5) readonly buffer Previous { vec4 prev[]; };
// The 16-byte ColliderHeader, then 112-byte ColliderEntry (std430: scalar
// members only, so offsets and the array stride match the C++ layout).
layout(std430, binding = 6) readonly buffer Colliders {
  ColliderHeader header;
  ColliderEntry colliders[];
};
layout(std430, binding = 7) buffer Impulses { vec4 impulses[]; };

void main() {
  const uint gid = gl_GlobalInvocationID.x;
  if (gid >= p.count) return;
  const uint i = p.first + gid;

  const uint n_colliders = header.colliders;
  const uint n_tools = header.tools;
  const uint count = n_colliders + n_tools;
  const float t1 = p.substep_end;  // the substep's end, as a frame fraction
  precise float t1_minus = t1 - header.substep_fraction;
  const float t0 = contact_max(t1_minus, 0.0);  // and its start
  // The frame's first sweep restarts the impulse sums; the measuring pass never writes them.
  precise float first_end = 1.5 * header.substep_fraction;
  const bool restart_impulses = p.reset_lambda != 0u && p.measure_only == 0u && t1 <= first_end;
  const bool last_substep = t1 >= 1.0;  // exactly 1 in the last substep
  const bool restart_last = p.reset_lambda != 0u && p.measure_only == 0u && last_substep;
  precise float inv_h = 1.0 / p.h;

  const uint particle = idx[i];
  const vec4 x_start = x[particle];
  vec3 xi = x_start.xyz;
  const float w = x_start.w;
  const uint lam = i * count * SINEW_CONTACT_LAMBDA_PER_COLLIDER;
  const uint slots = particle * n_tools * SINEW_CONTACT_IMPULSE_FLOAT4S;
  for (uint t = 0u; t < n_tools; ++t) {
    const uint slot = slots + t * SINEW_CONTACT_IMPULSE_FLOAT4S;
    if (restart_impulses) impulses[slot] = impulses[slot + 1u] = vec4(0.0);
    if (restart_last) impulses[slot + 2u] = impulses[slot + 3u] = impulses[slot + 4u] = vec4(0.0);
  }
  float worst = 0.0;

  for (uint k = 0u; k < count; ++k) {
    const ColliderEntry e = colliders[k];
    const uint lk = lam + k * SINEW_CONTACT_LAMBDA_PER_COLLIDER;
    const float lambda_n = p.reset_lambda != 0u ? 0.0 : lambda[lk];
    vec3 lambda_t = p.reset_lambda != 0u ? vec3(0.0) : vec3(lambda[lk + 1u], lambda[lk + 2u], lambda[lk + 3u]);

    vec3 pose_p;
    vec4 pose_q;
    contact_collider_pose(e, t1, pose_p, pose_q);
    precise vec3 offset = xi - pose_p;
    float sd_distance;
    vec3 sd_normal;
    contact_collider_distance(e, contact_rotate_inverse(pose_q, offset), sd_distance, sd_normal);
    precise float c = sd_distance - margin[i];
    precise vec3 n = contact_rotate(pose_q, sd_normal);
    precise float alpha_t = e.compliance * p.inv_h2;

    if (p.measure_only != 0u) {
      precise float gap = abs(c + alpha_t * lambda_n);
      worst = contact_max(worst, lambda_n > 0.0 ? gap : contact_max(-c, 0.0));
      continue;
    }
    float lambda_n_new = 0.0;
    vec3 lambda_t_new = vec3(0.0);
    float dlambda_n = 0.0;
    vec3 dlambda_t = vec3(0.0);
    if ((lambda_n > 0.0 || c < 0.0) && w > 0.0) {  // touching, or touched earlier in this substep
      // Normal: xPBD with lambda_n >= 0 (the collider only pushes).
      precise float step_n = lambda_n + (-c - alpha_t * lambda_n) / (w + alpha_t);
      lambda_n_new = contact_max(step_n, 0.0);
      precise float dn = lambda_n_new - lambda_n;
      dlambda_n = dn;
      precise vec3 pushed = xi + (w * dlambda_n) * n;
      xi = pushed;

      // Friction: the tangential displacement over the substep relative to
      // the collider's point now under the particle, cancelled inside the
      // static cone, else reduced to the kinetic one.
      precise vec3 tangent = lambda_t - dot3(lambda_t, n) * n;  // keep it in the current tangent plane
      lambda_t = tangent;
      if (lambda_n_new > 0.0) {
        vec3 start_p;
        vec4 start_q;
        contact_collider_pose(e, t0, start_p, start_q);
        precise vec3 moved = xi - pose_p;
        precise vec3 on_collider = contact_rotate_inverse(pose_q, moved);
        precise vec3 was = start_p + contact_rotate(start_q, on_collider);  // that point at the substep's start
        precise vec3 relative = was - prev[particle].xyz;                   // (x - prev) - (x - was)
        precise vec3 relative_t = relative - dot3(relative, n) * n;
        precise vec3 cancel = lambda_t - (1.0 / w) * relative_t;
        lambda_t_new = cancel;
        precise float len = contact_length3(lambda_t_new);
        precise float cone = e.static_friction * lambda_n_new;
        if (len > cone) {
          if (len > 0.0) {
            precise vec3 kinetic = (e.dynamic_friction * lambda_n_new / len) * lambda_t_new;
            lambda_t_new = kinetic;
          } else {
            lambda_t_new = vec3(0.0);
          }
        }
      }
      precise vec3 dt = lambda_t_new - lambda_t;
      dlambda_t = dt;
      precise vec3 dragged = xi + w * dlambda_t;
      xi = dragged;
    }
    lambda[lk] = lambda_n_new;
    lambda[lk + 1u] = lambda_t_new.x;
    lambda[lk + 2u] = lambda_t_new.y;
    lambda[lk + 3u] = lambda_t_new.z;

    if (k >= n_colliders) {  // a tool: it receives the opposite of the impulse
      const uint slot = slots + (k - n_colliders) * SINEW_CONTACT_IMPULSE_FLOAT4S;
      precise vec3 lever = xi - pose_p;
      precise vec3 j = (-inv_h) * (dlambda_n * n + dlambda_t);
      precise vec3 moment = cross3(lever, j);
      precise vec3 sum_j = impulses[slot].xyz + j;
      precise vec3 sum_moment = impulses[slot + 1u].xyz + moment;
      impulses[slot] = vec4(sum_j, 0.0);
      impulses[slot + 1u] = vec4(sum_moment, 0.0);
      if (last_substep) {
        precise vec3 last_j = impulses[slot + 2u].xyz + j;
        precise vec3 last_moment = impulses[slot + 3u].xyz + moment;
        impulses[slot + 2u] = vec4(last_j, 0.0);
        impulses[slot + 3u] = vec4(last_moment, 0.0);
        precise float mass = 1.0 / w;
        impulses[slot + 4u] = lambda_n_new > 0.0 ? vec4(lever, mass) : vec4(0.0);
      }
    }
  }
  if (p.measure_only != 0u) {
    residual[i] = worst;
    return;
  }
  if (w > 0.0) x[particle] = vec4(xi, w);
}
