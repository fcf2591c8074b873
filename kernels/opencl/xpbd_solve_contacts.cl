// xpbd_solve_contacts.cl — OpenCL twin of
// kernels/cpu/contact_kernels.cpp:xpbd_solve_contacts: contacts of particles
// with analytic colliders (plane, sphere, capsule, box) and tools (capsules).
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016: the normal multiplier clamped to
// lambda_n >= 0. Macklin, Müller, Chentanez, Kim, "Unified Particle Physics
// for Real-Time Applications", SIGGRAPH 2014, eq. 24-25: Coulomb friction at
// position level, kept as an accumulated multiplier lambda_t clamped to the
// static / kinetic cone (see kernels/shared/contact_params.h).
//
// One work item per movable particle (all in one colour), every collider in
// turn. The impulses a particle gives the tools go to that particle's own
// slots (particle * tools + tool), written by this item only: no atomics, no
// race; the host reduces them in particle order (simulation_contacts.cpp).
#include "contact_math.h"
#include "xpbd_params.h"

kernel void xpbd_solve_contacts(global float4* x, global const uint* idx, global const float* margin,
                                global float* lambda, global float* residual, global const float4* prev,
                                global const float4* collider_data, global float4* impulses, SolveParams p) {
  const uint gid = get_global_id(0);
  if (gid >= p.count) return;
  const uint i = p.first + gid;
  // The collider buffer: a ColliderHeader, then ColliderEntry[colliders + tools].
  global const ColliderHeader* header = (global const ColliderHeader*)collider_data;
  global const ColliderEntry* entries =
      (global const ColliderEntry*)((global const uchar*)collider_data + sizeof(ColliderHeader));
  const uint colliders = header->colliders, tools = header->tools;
  const float substep_fraction = header->substep_fraction;

  const uint count = colliders + tools;
  const float t1 = p.substep_end;                             // the substep's end, as a frame fraction
  const float t0 = contact_max(t1 - substep_fraction, 0.0f);  // and its start
  // The frame's first sweep restarts the impulse sums; the measuring pass never writes them.
  const bool restart_impulses = p.reset_lambda && !p.measure_only && t1 <= 1.5f * substep_fraction;
  const bool last_substep = t1 >= 1.0f;  // exactly 1 in the last substep
  const bool restart_last = p.reset_lambda && !p.measure_only && last_substep;
  const float inv_h = 1.0f / p.h;

  const uint particle = idx[i];
  const float4 x_start = x[particle];
  float3 xi = x_start.xyz;
  const float w = x_start.w;
  global float* lam = lambda + (size_t)i * count * SINEW_CONTACT_LAMBDA_PER_COLLIDER;
  global float4* slots = impulses + (size_t)particle * tools * SINEW_CONTACT_IMPULSE_FLOAT4S;
  for (uint t = 0; t < tools; ++t) {
    global float4* slot = slots + t * SINEW_CONTACT_IMPULSE_FLOAT4S;
    if (restart_impulses) slot[0] = slot[1] = (float4)(0.0f);
    if (restart_last) slot[2] = slot[3] = slot[4] = (float4)(0.0f);
  }
  float worst = 0.0f;

  for (uint k = 0; k < count; ++k) {
    global const ColliderEntry* e = entries + k;
    global float* lk = lam + k * SINEW_CONTACT_LAMBDA_PER_COLLIDER;
    const float lambda_n = p.reset_lambda ? 0.0f : lk[0];
    float3 lambda_t = p.reset_lambda ? (float3)(0.0f) : (float3)(lk[1], lk[2], lk[3]);

    const ContactPose pose = contact_collider_pose(e, t1);
    const ContactDistance sd = contact_collider_distance(e, contact_rotate_inverse(pose.q, xi - pose.p));
    const float c = sd.distance - margin[i];
    const float3 n = contact_rotate(pose.q, sd.normal);
    const float alpha_t = e->compliance * p.inv_h2;

    if (p.measure_only) {
      worst = contact_max(worst, lambda_n > 0.0f ? fabs(c + alpha_t * lambda_n) : contact_max(-c, 0.0f));
      continue;
    }
    float lambda_n_new = 0.0f;
    float3 lambda_t_new = (float3)(0.0f);
    float dlambda_n = 0.0f;
    float3 dlambda_t = (float3)(0.0f);
    if ((lambda_n > 0.0f || c < 0.0f) && w > 0.0f) {  // touching, or touched earlier in this substep
      // Normal: xPBD with lambda_n >= 0 (the collider only pushes).
      lambda_n_new = contact_max(lambda_n + (-c - alpha_t * lambda_n) / (w + alpha_t), 0.0f);
      dlambda_n = lambda_n_new - lambda_n;
      xi = xi + (w * dlambda_n) * n;

      // Friction: the tangential displacement over the substep relative to
      // the collider's point now under the particle, cancelled inside the
      // static cone, else reduced to the kinetic one.
      lambda_t = lambda_t - dot3(lambda_t, n) * n;  // keep it in the current tangent plane
      if (lambda_n_new > 0.0f) {
        const ContactPose start = contact_collider_pose(e, t0);
        const float3 on_collider = contact_rotate_inverse(pose.q, xi - pose.p);
        const float3 was = start.p + contact_rotate(start.q, on_collider);  // that point at the substep's start
        float3 relative = was - prev[particle].xyz;                         // (x - prev) - (x - was)
        relative = relative - dot3(relative, n) * n;
        lambda_t_new = lambda_t - (1.0f / w) * relative;
        const float len = contact_length3(lambda_t_new);
        if (len > e->static_friction * lambda_n_new)
          lambda_t_new = len > 0.0f ? (e->dynamic_friction * lambda_n_new / len) * lambda_t_new : (float3)(0.0f);
      }
      dlambda_t = lambda_t_new - lambda_t;
      xi = xi + w * dlambda_t;
    }
    lk[0] = lambda_n_new;
    lk[1] = lambda_t_new.x;
    lk[2] = lambda_t_new.y;
    lk[3] = lambda_t_new.z;

    if (k >= colliders) {  // a tool: it receives the opposite of the impulse
      global float4* slot = slots + (k - colliders) * SINEW_CONTACT_IMPULSE_FLOAT4S;
      const float3 lever = xi - pose.p;
      const float3 j = (-inv_h) * (dlambda_n * n + dlambda_t);
      const float3 moment = cross3(lever, j);
      slot[0] = (float4)(slot[0].xyz + j, 0.0f);
      slot[1] = (float4)(slot[1].xyz + moment, 0.0f);
      if (last_substep) {
        slot[2] = (float4)(slot[2].xyz + j, 0.0f);
        slot[3] = (float4)(slot[3].xyz + moment, 0.0f);
        slot[4] = lambda_n_new > 0.0f ? (float4)(lever, 1.0f / w) : (float4)(0.0f);
      }
    }
  }
  if (p.measure_only) {
    residual[i] = worst;
    return;
  }
  if (w > 0.0f) x[particle] = (float4)(xi, w);
}
