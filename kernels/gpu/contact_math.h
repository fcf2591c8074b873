/* contact_math.h — helpers of the contact kernels (xpbd_solve_attachment.gpu,
 * xpbd_solve_contacts.gpu), twins of the ones in kernels/cpu/contact_kernels.h
 * and .cpp: quaternion rotation, collider poses interpolated across a frame
 * and the signed distance of each shape. Same operation order as the CPU
 * code; every arithmetic result is PRECISE, so nothing is fused into a
 * multiply-add, here in the helpers too.
 * Macklin, Müller, Chentanez, "XPBD", MIG 2016; Macklin, Müller, Chentanez,
 * Kim, "Unified Particle Physics for Real-Time Applications", SIGGRAPH 2014
 * (friction, used by xpbd_solve_contacts.gpu).
 *
 * Quaternions are float4 (x, y, z, w), w the scalar part, as in the CPU
 * Pose. The collider and target layouts are the shared ones of
 * kernels/shared/contact_params.h; the kernels bind those buffers as
 * vectors and rebuild the entries here (contact_collider), since neither
 * language can view one buffer as a header followed by an array of structs
 * the way the other does. */
#ifndef SINEW_CONTACT_MATH_H
#define SINEW_CONTACT_MATH_H

#include "vec_math.h"
#include "contact_params.h"

/* The collider buffer as uint4: the ColliderHeader (colliders, tools,
 * substep_fraction's bits, pad), then CONTACT_COLLIDER_UINT4S per
 * ColliderEntry (112 bytes, scalar members only, in the order of
 * contact_params.h). */
#define CONTACT_COLLIDER_UINT4S 7u

/* A ColliderEntry with its poses as vectors. */
SINEW_STRUCT_BEGIN(ContactCollider)
  uint shape;
  float radius;
  float half_height;
  float compliance;
  float half_x;
  float half_y;
  float half_z;
  float static_friction;
  float dynamic_friction;
  uint implicit_first;
  uint implicit_count;
  float3 start_p;
  float4 start_q;  /* (x, y, z, w) */
  float3 end_p;
  float4 end_q;
SINEW_STRUCT_END(ContactCollider)

SINEW_STRUCT_BEGIN(ContactPose)
  float3 p;
  float4 q;
SINEW_STRUCT_END(ContactPose)

SINEW_STRUCT_BEGIN(ContactDistance)
  float distance;
  float3 normal;
SINEW_STRUCT_END(ContactDistance)

float4 contact_bits_float4(uint4 u) {
  return make_float4(bits_float(u.x), bits_float(u.y), bits_float(u.z), bits_float(u.w));
}

/* The entry from its CONTACT_COLLIDER_UINT4S words. */
ContactCollider contact_collider(const uint4 f[7]) {
  ContactCollider e;
  e.shape = f[0].x;
  e.radius = bits_float(f[0].y);
  e.half_height = bits_float(f[0].z);
  e.compliance = bits_float(f[0].w);
  const float4 f1 = contact_bits_float4(f[1]);
  e.half_x = f1.x;
  e.half_y = f1.y;
  e.half_z = f1.z;
  e.static_friction = f1.w;
  e.dynamic_friction = bits_float(f[2].x);
  e.implicit_first = f[2].y;
  e.implicit_count = f[2].z;
  e.start_p = contact_bits_float4(f[3]).xyz;
  e.start_q = contact_bits_float4(f[4]).yzwx;  // stored (w, x, y, z)
  e.end_p = contact_bits_float4(f[5]).xyz;
  e.end_q = contact_bits_float4(f[6]).yzwx;
  return e;
}

PRECISE float contact_length3(float3 v) {
  PRECISE float d = dot3(v, v);
  return sqrt(d);
}

/* std::max and std::clamp of the CPU code, NaN and signed zeros alike. */
float contact_max(float a, float b) { return a < b ? b : a; }
float contact_clamp(float v, float lo, float hi) { return v < lo ? lo : (hi < v ? hi : v); }

/* a + t (b - a): exactly a when a == b, exactly b at t >= 1. */
PRECISE float3 contact_lerp3(float3 a, float3 b, float t) {
  if (t >= 1.0f) return b;
  PRECISE float3 r = a + t * (b - a);
  return r;
}

/* v rotated by the unit quaternion q: v + 2 w (u x v) + 2 u x (u x v), u = q.xyz. */
PRECISE float3 contact_rotate(float4 q, float3 v) {
  PRECISE float3 t = 2.0f * cross3(q.xyz, v);
  PRECISE float3 r = v + q.w * t + cross3(q.xyz, t);
  return r;
}

/* v rotated by the inverse of the unit quaternion q. */
PRECISE float3 contact_rotate_inverse(float4 q, float3 v) {
  return contact_rotate(make_float4(-q.x, -q.y, -q.z, q.w), v);
}

/* The collider's pose at fraction t of the frame: position lerped, rotation
 * nlerped on the shorter arc (CPU: collider_pose). */
ContactPose contact_collider_pose(ContactCollider e, float t) {
  ContactPose pose;
  if (t >= 1.0f) {
    pose.p = e.end_p;
    pose.q = e.end_q;
    return pose;
  }
  if (t <= 0.0f) {
    pose.p = e.start_p;
    pose.q = e.start_q;
    return pose;
  }
  const float4 q0 = e.start_q;
  float4 q1 = e.end_q;
  PRECISE float arc = q0.x * q1.x + q0.y * q1.y + q0.z * q1.z + q0.w * q1.w;
  if (arc < 0.0f) {  // shorter arc
    PRECISE float4 flipped = -1.0f * q1;
    q1 = flipped;
  }
  PRECISE float4 q = (1.0f - t) * q0 + t * q1;
  PRECISE float norm = sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  PRECISE float4 unit = (1.0f / norm) * q;
  pose.p = contact_lerp3(e.start_p, e.end_p, t);
  pose.q = unit;
  return pose;
}

/* Signed distance of a point in the collider's frame (negative inside) and
 * the outward unit normal there, in that frame, for the analytic shapes
 * (plane to cylinder; CPU: shape_distance). Implicit shapes are evaluated
 * by the kernel, node by node (contact_implicit_node and below). */
ContactDistance contact_shape_distance(ContactCollider e, float3 point) {
  ContactDistance sd;
  switch (e.shape) {
    case SINEW_SHAPE_SPHERE: {
      PRECISE float r = contact_length3(point);
      if (r > 0.0f) {
        PRECISE float d = r - e.radius;
        PRECISE float3 nn = (1.0f / r) * point;
        sd.distance = d;
        sd.normal = nn;
      } else {
        sd.distance = -e.radius;
        sd.normal = make_float3(0.0f, 1.0f, 0.0f);
      }
      return sd;
    }
    case SINEW_SHAPE_CAPSULE: {
      const float s = contact_clamp(point.y, -e.half_height, e.half_height);
      PRECISE float3 v = make_float3(point.x, point.y - s, point.z);
      PRECISE float r = contact_length3(v);
      if (r > 0.0f) {
        PRECISE float d = r - e.radius;
        PRECISE float3 nn = (1.0f / r) * v;
        sd.distance = d;
        sd.normal = nn;
      } else {
        sd.distance = -e.radius;
        sd.normal = make_float3(1.0f, 0.0f, 0.0f);
      }
      return sd;
    }
    case SINEW_SHAPE_BOX: {
      const float p[3] = {point.x, point.y, point.z};
      const float half_extent[3] = {e.half_x, e.half_y, e.half_z};
      PRECISE float q[3];
      PRECISE float out_offset[3];
      PRECISE float outside = 0.0f;
      int nearest = 0;
      for (int a = 0; a < 3; ++a) {
        q[a] = fabs(p[a]) - half_extent[a];
        out_offset[a] = contact_max(q[a], 0.0f) * (p[a] < 0.0f ? -1.0f : 1.0f);
        outside = outside + out_offset[a] * out_offset[a];
        if (q[a] > q[nearest]) nearest = a;
      }
      if (outside > 0.0f) {  // outside: the distance to the box, along the offset from it
        PRECISE float d = sqrt(outside);
        PRECISE float3 nn = make_float3(out_offset[0] / d, out_offset[1] / d, out_offset[2] / d);
        sd.distance = d;
        sd.normal = nn;
        return sd;
      }
      float n[3] = {0.0f, 0.0f, 0.0f};  // inside: out through the nearest face
      n[nearest] = p[nearest] < 0.0f ? -1.0f : 1.0f;
      sd.distance = q[nearest];
      sd.normal = make_float3(n[0], n[1], n[2]);
      return sd;
    }
    case SINEW_SHAPE_CYLINDER: {
      PRECISE float r = sqrt(point.x * point.x + point.z * point.z);
      PRECISE float dr = r - e.radius;
      PRECISE float dy = fabs(point.y) - e.half_height;
      const float sy = point.y < 0.0f ? -1.0f : 1.0f;
      PRECISE float ux = r > 0.0f ? point.x / r : 1.0f;
      PRECISE float uz = r > 0.0f ? point.z / r : 0.0f;
      if (dr > 0.0f && dy > 0.0f) {
        PRECISE float d = sqrt(dr * dr + dy * dy);
        PRECISE float3 nn = make_float3(dr * ux / d, dy * sy / d, dr * uz / d);
        sd.distance = d;
        sd.normal = nn;
        return sd;
      }
      if (dr > dy) {
        sd.distance = dr;
        sd.normal = make_float3(ux, 0.0f, uz);
        return sd;
      }
      sd.distance = dy;
      sd.normal = make_float3(0.0f, sy, 0.0f);
      return sd;
    }
    case SINEW_SHAPE_PLANE:
    default:
      sd.distance = point.y;
      sd.normal = make_float3(0.0f, 1.0f, 0.0f);
      return sd;
  }
}

/* The collider buffer holds an ImplicitEntry as CONTACT_IMPLICIT_UINT4S uint4. */
#define CONTACT_IMPLICIT_UINT4S 4u

SINEW_STRUCT_BEGIN(ContactImplicitNode)
  uint op;
  float radius;
  float half_height;
  float rounding;
  float half_x;
  float half_y;
  float half_z;
  float minor_radius;
  float3 p;
  float4 q;  /* (x, y, z, w) */
SINEW_STRUCT_END(ContactImplicitNode)

ContactImplicitNode contact_implicit_node(const uint4 f[4]) {
  ContactImplicitNode n;
  n.op = f[0].x;
  n.radius = bits_float(f[0].y);
  n.half_height = bits_float(f[0].z);
  n.rounding = bits_float(f[0].w);
  const float4 f1 = contact_bits_float4(f[1]);
  n.half_x = f1.x;
  n.half_y = f1.y;
  n.half_z = f1.z;
  n.minor_radius = f1.w;
  n.p = contact_bits_float4(f[2]).xyz;
  n.q = contact_bits_float4(f[3]).yzwx;  // stored (w, x, y, z)
  return n;
}

/* A torus about the y axis (CPU: torus_distance): the distance to its core
 * circle less the tube's radius; +y on the core circle, +x radially on the
 * axis. */
ContactDistance contact_torus_distance(float major, float minor, float3 point) {
  ContactDistance sd;
  PRECISE float r = sqrt(point.x * point.x + point.z * point.z);
  PRECISE float ux = r > 0.0f ? point.x / r : 1.0f;
  PRECISE float uz = r > 0.0f ? point.z / r : 0.0f;
  PRECISE float qr = r - major;
  PRECISE float len = sqrt(qr * qr + point.y * point.y);
  if (!(len > 0.0f)) {
    sd.distance = -minor;
    sd.normal = make_float3(0.0f, 1.0f, 0.0f);
    return sd;
  }
  PRECISE float d = len - minor;
  PRECISE float3 nn = make_float3(qr * ux / len, point.y / len, qr * uz / len);
  sd.distance = d;
  sd.normal = nn;
  return sd;
}

/* One primitive node at a point in the collider's frame (CPU:
 * primitive_distance): into the node's frame, measured, the normal rotated
 * back, less the rounding. */
ContactDistance contact_primitive_distance(ContactImplicitNode n, float3 point) {
  PRECISE float3 offset = point - n.p;
  const float3 own = contact_rotate_inverse(n.q, offset);
  ContactDistance sd;
  if (n.op == SINEW_IMPLICIT_TORUS) {
    sd = contact_torus_distance(n.radius, n.minor_radius, own);
  } else {
    ContactCollider shape;
    shape.shape = n.op;  /* SINEW_IMPLICIT_HALF_SPACE..CYLINDER are SINEW_SHAPE_PLANE..CYLINDER */
    shape.radius = n.radius;
    shape.half_height = n.half_height;
    shape.half_x = n.half_x;
    shape.half_y = n.half_y;
    shape.half_z = n.half_z;
    sd = contact_shape_distance(shape, own);
  }
  ContactDistance r;
  PRECISE float d = sd.distance - n.rounding;
  r.distance = d;
  r.normal = contact_rotate(n.q, sd.normal);
  return r;
}

/* An operation on a (below) and b (top of the stack): the value chosen and
 * its normal, a on ties (CPU: implicit_distance). */
ContactDistance contact_implicit_combine(uint op, ContactDistance a, ContactDistance b) {
  ContactDistance r = a;
  if (op == SINEW_IMPLICIT_UNITE) {
    if (b.distance < a.distance) r = b;
  } else if (op == SINEW_IMPLICIT_INTERSECT) {
    if (b.distance > a.distance) r = b;
  } else if (-b.distance > a.distance) {  /* subtract: outside b */
    r.distance = -b.distance;
    PRECISE float3 flipped = -1.0f * b.normal;
    r.normal = flipped;
  }
  return r;
}

#endif /* SINEW_CONTACT_MATH_H */
