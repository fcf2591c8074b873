// contact_kernels.cpp — CPU reference kernels of attachments and of contacts
// with analytic colliders (planes, spheres, capsules, boxes, cylinders,
// implicit CSG shapes, tools).
//
// Macklin, Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant
// Constrained Dynamics", MIG 2016: the xPBD update, with the contact's
// multiplier clamped to lambda >= 0 (an inequality constraint C >= 0).
// Macklin, Müller, Chentanez, Kim, "Unified Particle Physics for Real-Time
// Applications", SIGGRAPH 2014, eq. 24-25: Coulomb friction at position
// level — the tangential displacement relative to the collider over the
// substep is cancelled inside the static cone (mu_s times the normal
// correction) and reduced by mu_k times it outside. Here the friction is
// kept as an accumulated multiplier lambda_t clamped to the cone, so that
// several iterations converge to that rule (see contact_params.h).
//
// One work item per particle, every collider in turn: a particle's contacts
// are solved by one item, so no writes race and nothing depends on threads.
#include "cpu/contact_kernels.h"

#include <algorithm>
#include <cmath>

#include "xpbd_params.h"

#if SINEW_HAS_OPENVDB
#include "cpu/level_set_sampling.h"
#endif

namespace sinew::kernels {
namespace {

float4 xyz(float4 v) { return {v.x, v.y, v.z, 0.0f}; }
float length3(float4 v) { return std::sqrt(dot3(v, v)); }
// a + t (b - a): exactly a when a == b (a still collider or target), exactly b at t = 1.
float4 lerp3(float4 a, float4 b, float t) { return t >= 1.0f ? xyz(b) : xyz(a + t * (b - a)); }

}  // namespace

Pose collider_pose(const ColliderEntry& e, float t) {
  const float4 p0{e.start_px, e.start_py, e.start_pz, 0.0f}, p1{e.end_px, e.end_py, e.end_pz, 0.0f};
  const float4 q0{e.start_qx, e.start_qy, e.start_qz, e.start_qw};
  float4 q1{e.end_qx, e.end_qy, e.end_qz, e.end_qw};
  if (t >= 1.0f) return {p1, q1};
  if (t <= 0.0f) return {p0, q0};
  if (q0.x * q1.x + q0.y * q1.y + q0.z * q1.z + q0.w * q1.w < 0.0f) q1 = -1.0f * q1;  // shorter arc
  const float4 q = (1.0f - t) * q0 + t * q1;
  const float norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  return {lerp3(p0, p1, t), (1.0f / norm) * q};
}

namespace {

// The distance of one of the analytic shapes (SINEW_SHAPE_PLANE..CYLINDER).
SignedDistance shape_distance(const ColliderEntry& e, float4 local) {
  switch (e.shape) {
    case SINEW_SHAPE_SPHERE: {
      const float r = length3(local);
      if (r > 0.0f) return {r - e.radius, (1.0f / r) * xyz(local)};
      return {-e.radius, {0.0f, 1.0f, 0.0f, 0.0f}};
    }
    case SINEW_SHAPE_CAPSULE: {
      const float s = std::clamp(local.y, -e.half_height, e.half_height);
      const float4 v{local.x, local.y - s, local.z, 0.0f};
      const float r = length3(v);
      if (r > 0.0f) return {r - e.radius, (1.0f / r) * v};
      return {-e.radius, {1.0f, 0.0f, 0.0f, 0.0f}};
    }
    case SINEW_SHAPE_BOX: {
      const float p[3] = {local.x, local.y, local.z};
      const float half[3] = {e.half_x, e.half_y, e.half_z};
      float q[3], out[3], outside = 0.0f;
      int nearest = 0;
      for (int a = 0; a < 3; ++a) {
        q[a] = std::abs(p[a]) - half[a];
        out[a] = std::max(q[a], 0.0f) * (p[a] < 0.0f ? -1.0f : 1.0f);
        outside += out[a] * out[a];
        if (q[a] > q[nearest]) nearest = a;
      }
      if (outside > 0.0f) {  // outside: the distance to the box, along the offset from it
        const float d = std::sqrt(outside);
        return {d, {out[0] / d, out[1] / d, out[2] / d, 0.0f}};
      }
      float n[3] = {0.0f, 0.0f, 0.0f};  // inside: out through the nearest face
      n[nearest] = p[nearest] < 0.0f ? -1.0f : 1.0f;
      return {q[nearest], {n[0], n[1], n[2], 0.0f}};
    }
    case SINEW_SHAPE_CYLINDER: {
      // Radial and axial excess: outside the side (dr > 0), the caps
      // (dy > 0), both (the rim: the distance to the circle), or inside
      // (the nearer of side and cap).
      const float r = std::sqrt(local.x * local.x + local.z * local.z);
      const float dr = r - e.radius, dy = std::abs(local.y) - e.half_height;
      const float sy = local.y < 0.0f ? -1.0f : 1.0f;
      const float ux = r > 0.0f ? local.x / r : 1.0f, uz = r > 0.0f ? local.z / r : 0.0f;
      if (dr > 0.0f && dy > 0.0f) {
        const float d = std::sqrt(dr * dr + dy * dy);
        return {d, {dr * ux / d, dy * sy / d, dr * uz / d, 0.0f}};
      }
      if (dr > dy) return {dr, {ux, 0.0f, uz, 0.0f}};
      return {dy, {0.0f, sy, 0.0f, 0.0f}};
    }
    case SINEW_SHAPE_PLANE:
    default: return {local.y, {0.0f, 1.0f, 0.0f, 0.0f}};
  }
}

// A torus about the y axis: the distance to its core circle (radius R in
// y = 0) less the tube's radius. On the core circle (no direction) the
// normal is +y; on the axis the radial direction is +x.
SignedDistance torus_distance(float major, float minor, float4 local) {
  const float r = std::sqrt(local.x * local.x + local.z * local.z);
  const float ux = r > 0.0f ? local.x / r : 1.0f, uz = r > 0.0f ? local.z / r : 0.0f;
  const float qr = r - major;
  const float len = std::sqrt(qr * qr + local.y * local.y);
  if (!(len > 0.0f)) return {-minor, {0.0f, 1.0f, 0.0f, 0.0f}};
  return {len - minor, {qr * ux / len, local.y / len, qr * uz / len, 0.0f}};
}

// One primitive node at a point in the collider's frame: moved into the
// node's frame, measured, the normal rotated back, less the rounding.
SignedDistance primitive_distance(const ImplicitEntry& n, float4 local) {
  const float4 q{n.qx, n.qy, n.qz, n.qw};
  const float4 own = rotate_inverse(q, local - float4{n.px, n.py, n.pz, 0.0f});
  SignedDistance sd;
  if (n.op == SINEW_IMPLICIT_TORUS) {
    sd = torus_distance(n.radius, n.minor_radius, own);
  } else {
    ColliderEntry shape{};
    shape.shape = n.op;  // SINEW_IMPLICIT_HALF_SPACE..CYLINDER are SINEW_SHAPE_PLANE..CYLINDER
    shape.radius = n.radius;
    shape.half_height = n.half_height;
    shape.half_x = n.half_x;
    shape.half_y = n.half_y;
    shape.half_z = n.half_z;
    sd = shape_distance(shape, own);
  }
  return {sd.distance - n.rounding, rotate(q, sd.normal)};
}

}  // namespace

SignedDistance implicit_distance(const ImplicitEntry* nodes, std::uint32_t count, float4 local) {
  SignedDistance stack[SINEW_IMPLICIT_STACK];
  int top = 0;  // values on the stack
  for (std::uint32_t k = 0; k < count; ++k) {
    const ImplicitEntry& n = nodes[k];
    if (n.op < SINEW_IMPLICIT_UNITE) {
      stack[top++] = primitive_distance(n, local);
      continue;
    }
    const SignedDistance b = stack[--top], a = stack[top - 1];
    SignedDistance r = a;
    if (n.op == SINEW_IMPLICIT_UNITE) {
      if (b.distance < a.distance) r = b;
    } else if (n.op == SINEW_IMPLICIT_INTERSECT) {
      if (b.distance > a.distance) r = b;
    } else if (-b.distance > a.distance) {  // subtract: outside b
      r = {-b.distance, -1.0f * b.normal};
    }
    stack[top - 1] = r;
  }
  return stack[0];
}

SignedDistance collider_distance(const ColliderEntry& e, float4 local, const ImplicitEntry* nodes,
                                 std::uint32_t* grids) {
  if (e.shape == SINEW_SHAPE_IMPLICIT) return implicit_distance(nodes + e.implicit_first, e.implicit_count, local);
#if SINEW_HAS_OPENVDB
  if (e.shape == SINEW_SHAPE_LEVEL_SET) {
    // Its trilinear value; its gradient, normalised (zero beyond the bands).
    const float4 s = sample_level_set_grid(grids, e.implicit_first, e.half_x, e.half_y, local);
    const float4 g{s.y, s.z, s.w, 0.0f};
    const float length = length3(g);
    return {s.x, length > 0.0f ? (1.0f / length) * g : float4{0.0f, 0.0f, 0.0f, 0.0f}};
  }
#else
  (void)grids;
#endif
  return shape_distance(e, local);
}

void xpbd_solve_attachment(const void* params, std::byte* const* bindings, std::uint32_t begin,
                           std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* idx = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* data = reinterpret_cast<const float2*>(bindings[2]);  // (target index, alpha)
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  const auto* targets = reinterpret_cast<const TargetEntry*>(bindings[5]);
  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const float4 xi = x[idx[i]];
    const TargetEntry& target = targets[static_cast<std::uint32_t>(data[i].x)];
    const float4 goal = lerp3(float4{target.start_x, target.start_y, target.start_z, 0.0f},
                              float4{target.end_x, target.end_y, target.end_z, 0.0f}, p.substep_end);
    const float4 d = xyz(xi - goal);
    const float c = length3(d);  // zero rest length
    const float alpha_t = data[i].y * p.inv_h2;
    const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
    if (p.measure_only) {
      residual[i] = std::abs(c + alpha_t * lambda_i);  // [m]: no rest value to normalise by
      continue;
    }
    // On the target the gradient (x - target) / |x - target| is undefined
    // and C = 0: nothing to do. Immovable particles are never written.
    if (!(c > 0.0f) || !(xi.w > 0.0f)) {
      lambda[i] = lambda_i;
      continue;
    }
    const float dlambda = (-c - alpha_t * lambda_i) / (xi.w + alpha_t);
    x[idx[i]] = add_scaled3(xi, xi.w * dlambda / c, d);
    lambda[i] = lambda_i + dlambda;
  }
}

void xpbd_solve_point_attachment(const void* params, std::byte* const* bindings, std::uint32_t begin,
                                 std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* idx = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* data = reinterpret_cast<const float4*>(bindings[2]);  // (w0, w1, w2, alpha), (target, 0, 0, 0)
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  const auto* targets = reinterpret_cast<const TargetEntry*>(bindings[5]);
  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const std::uint32_t* q = &idx[3 * std::size_t{i}];
    const float4 x0 = x[q[0]], x1 = x[q[1]], x2 = x[q[2]];
    const float4 w = data[2 * std::size_t{i}];
    const TargetEntry& target = targets[static_cast<std::uint32_t>(data[2 * std::size_t{i} + 1].x)];
    const float4 goal = lerp3(float4{target.start_x, target.start_y, target.start_z, 0.0f},
                              float4{target.end_x, target.end_y, target.end_z, 0.0f}, p.substep_end);
    const float4 point = add_scaled3(add_scaled3(w.x * x0, w.y, x1), w.z, x2);
    const float4 d = xyz(point - goal);
    const float c = length3(d);  // zero rest length
    const float alpha_t = w.w * p.inv_h2;
    const float lambda_i = p.reset_lambda ? 0.0f : lambda[i];
    if (p.measure_only) {
      residual[i] = std::abs(c + alpha_t * lambda_i);  // [m]
      continue;
    }
    const float weight = w.x * w.x * x0.w + w.y * w.y * x1.w + w.z * w.z * x2.w;
    // On the target the gradient is undefined and C = 0; with every
    // particle immovable nothing can move.
    if (!(c > 0.0f) || !(weight > 0.0f)) {
      lambda[i] = lambda_i;
      continue;
    }
    const float dlambda = (-c - alpha_t * lambda_i) / (weight + alpha_t);
    const float s = dlambda / c;  // along d: the unit normal's step
    if (x0.w > 0.0f) x[q[0]] = add_scaled3(x0, x0.w * w.x * s, d);
    if (x1.w > 0.0f) x[q[1]] = add_scaled3(x1, x1.w * w.y * s, d);
    if (x2.w > 0.0f) x[q[2]] = add_scaled3(x2, x2.w * w.z * s, d);
    lambda[i] = lambda_i + dlambda;
  }
}

// The radius [m] of a ball about a scene collider's centre that holds the
// whole shape (sphere, capsule, box, cylinder), or -1 for shapes without one
// (plane, implicit, level set). A particle outside it by more than its
// margin cannot touch the collider.
float bounding_radius(const ColliderEntry& e) {
  switch (e.shape) {
    case SINEW_SHAPE_SPHERE: return e.radius;
    case SINEW_SHAPE_CAPSULE: return e.radius + e.half_height;
    case SINEW_SHAPE_BOX: return std::sqrt(e.half_x * e.half_x + e.half_y * e.half_y + e.half_z * e.half_z);
    case SINEW_SHAPE_CYLINDER: return std::sqrt(e.radius * e.radius + e.half_height * e.half_height);
    default: return -1.0f;
  }
}

void xpbd_solve_contacts(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* idx = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  const auto* margin = reinterpret_cast<const float*>(bindings[2]);
  auto* lambda = reinterpret_cast<float*>(bindings[3]);
  auto* residual = reinterpret_cast<float*>(bindings[4]);
  const auto* prev = reinterpret_cast<const float4*>(bindings[5]);
  const auto& header = *reinterpret_cast<const ColliderHeader*>(bindings[6]);
  const auto* colliders = reinterpret_cast<const ColliderEntry*>(bindings[6] + sizeof(ColliderHeader));
  const auto* nodes = reinterpret_cast<const ImplicitEntry*>(colliders + header.colliders + header.tools);
  auto* impulses = reinterpret_cast<float4*>(bindings[7]);
  auto* grids = reinterpret_cast<std::uint32_t*>(bindings[8]);

  const std::uint32_t count = header.colliders + header.tools;
  const float t1 = p.substep_end;                                  // the substep's end, as a frame fraction
  const float t0 = std::max(t1 - header.substep_fraction, 0.0f);   // and its start
  // The frame's first sweep (first iteration of the first substep) restarts
  // the impulse sums; the measuring pass never writes them.
  const bool restart_impulses = p.reset_lambda && !p.measure_only && t1 <= 1.5f * header.substep_fraction;
  const bool last_substep = t1 >= 1.0f;  // exactly 1 in the last substep
  const bool restart_last = p.reset_lambda && !p.measure_only && last_substep;
  const float inv_h = 1.0f / p.h;

  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const std::uint32_t particle = idx[i];
    float4 xi = x[particle];
    const float w = xi.w;
    float* lam = lambda + std::size_t{i} * count * SINEW_CONTACT_LAMBDA_PER_COLLIDER;
    float4* slots = impulses + std::size_t{particle} * header.tools * SINEW_CONTACT_IMPULSE_FLOAT4S;
    for (std::uint32_t t = 0; t < header.tools; ++t) {
      float4* slot = slots + t * SINEW_CONTACT_IMPULSE_FLOAT4S;
      if (restart_impulses) slot[0] = slot[1] = float4{0, 0, 0, 0};
      if (restart_last) slot[2] = slot[3] = slot[4] = float4{0, 0, 0, 0};
    }
    float worst = 0.0f;

    for (std::uint32_t k = 0; k < count; ++k) {
      const ColliderEntry& e = colliders[k];
      float* lk = lam + k * SINEW_CONTACT_LAMBDA_PER_COLLIDER;
      const float lambda_n = p.reset_lambda ? 0.0f : lk[0];
      float4 lambda_t = p.reset_lambda ? float4{0, 0, 0, 0} : float4{lk[1], lk[2], lk[3], 0.0f};

      const Pose pose = collider_pose(e, t1);
      // Far from a scene collider it has not touched in this substep, the
      // particle's result is known without its signed distance: no contact,
      // multipliers 0, no residual. Every particle of the scene meets every
      // collider in every sweep, and an organ's particles are nearly all far
      // from a probe, so this skips most of the distances. The ball is
      // widened by 1% + 1 um so that the distance computed in float would be
      // positive with room to spare; tools are not skipped (their impulse
      // sums add even zero corrections).
      const float reach = bounding_radius(e);
      if (k < header.colliders && reach >= 0.0f && lambda_n == 0.0f) {
        const float4 d = xyz(xi - pose.p);
        const float far = 1.01f * (reach + std::max(margin[i], 0.0f)) + 1e-6f;
        if (dot3(d, d) > far * far) {
          if (!p.measure_only) lk[0] = lk[1] = lk[2] = lk[3] = 0.0f;
          continue;
        }
      }
      const SignedDistance sd = collider_distance(e, rotate_inverse(pose.q, xi - pose.p), nodes, grids);
      const float c = sd.distance - margin[i];
      const float4 n = rotate(pose.q, sd.normal);
      const float alpha_t = e.compliance * p.inv_h2;

      if (p.measure_only) {
        worst = std::max(worst, lambda_n > 0.0f ? std::abs(c + alpha_t * lambda_n) : std::max(-c, 0.0f));
        continue;
      }
      float lambda_n_new = 0.0f;
      float4 lambda_t_new{0.0f, 0.0f, 0.0f, 0.0f};
      float dlambda_n = 0.0f;
      float4 dlambda_t{0.0f, 0.0f, 0.0f, 0.0f};
      if ((lambda_n > 0.0f || c < 0.0f) && w > 0.0f) {  // touching, or touched earlier in this substep
        // Normal: xPBD with lambda_n >= 0 (the collider only pushes).
        lambda_n_new = std::max(lambda_n + (-c - alpha_t * lambda_n) / (w + alpha_t), 0.0f);
        dlambda_n = lambda_n_new - lambda_n;
        xi = add_scaled3(xi, w * dlambda_n, n);

        // Friction: the displacement over the substep relative to the point
        // of the collider now under the particle, tangential part, cancelled
        // inside the static cone, else reduced to the kinetic one.
        lambda_t = lambda_t - dot3(lambda_t, n) * n;  // keep it in the current tangent plane
        if (lambda_n_new > 0.0f) {
          const Pose start = collider_pose(e, t0);
          const float4 on_collider = rotate_inverse(pose.q, xi - pose.p);
          const float4 was = start.p + rotate(start.q, on_collider);  // that point at the substep's start
          float4 relative = xyz(was - prev[particle]);                // (x - prev) - (x - was)
          relative = relative - dot3(relative, n) * n;
          lambda_t_new = lambda_t - (1.0f / w) * relative;
          const float len = length3(lambda_t_new);
          if (len > e.static_friction * lambda_n_new)
            lambda_t_new = len > 0.0f ? (e.dynamic_friction * lambda_n_new / len) * lambda_t_new : float4{0, 0, 0, 0};
        }
        dlambda_t = xyz(lambda_t_new - lambda_t);
        xi = add_scaled3(xi, w, dlambda_t);
      }
      lk[0] = lambda_n_new;
      lk[1] = lambda_t_new.x;
      lk[2] = lambda_t_new.y;
      lk[3] = lambda_t_new.z;

      if (k >= header.colliders) {  // a tool: it receives the opposite of the impulse
        float4* slot = slots + (k - header.colliders) * SINEW_CONTACT_IMPULSE_FLOAT4S;
        const float4 lever = xyz(xi - pose.p);
        const float4 j = (-inv_h) * (dlambda_n * n + dlambda_t);
        const float4 moment = cross3(lever, j);
        slot[0] = xyz(slot[0] + j);
        slot[1] = xyz(slot[1] + moment);
        if (last_substep) {
          slot[2] = xyz(slot[2] + j);
          slot[3] = xyz(slot[3] + moment);
          slot[4] = lambda_n_new > 0.0f ? float4{lever.x, lever.y, lever.z, 1.0f / w} : float4{0, 0, 0, 0};
        }
      }
    }
    if (p.measure_only) {
      residual[i] = worst;
      continue;
    }
    if (w > 0.0f) x[particle] = xi;
  }
}

}  // namespace sinew::kernels
