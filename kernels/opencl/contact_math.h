/* contact_math.h — helpers of the OpenCL contact kernels
 * (xpbd_solve_attachment.cl, xpbd_solve_contacts.cl), twins of the ones in
 * kernels/cpu/contact_kernels.h and .cpp: quaternion rotation, collider
 * poses interpolated across a frame and the signed distance of each shape.
 * Same operation order as the CPU code, no fused multiply-add (cl_math.h
 * turns FP_CONTRACT off), so results round like the CPU reference.
 * Macklin, Müller, Chentanez, "XPBD", MIG 2016; Macklin, Müller, Chentanez,
 * Kim, "Unified Particle Physics for Real-Time Applications", SIGGRAPH 2014
 * (friction, used by xpbd_solve_contacts.cl).
 *
 * Every .cl file is pasted into one program, so the helpers live here, once,
 * behind the include guard, with the prefix contact_. Quaternions are float4
 * (x, y, z, w), w the scalar part, as in the CPU Pose. The collider and
 * target layouts are the shared ones of kernels/shared/contact_params.h. */
#ifndef SINEW_CONTACT_MATH_CL_H
#define SINEW_CONTACT_MATH_CL_H

#include "cl_math.h"
#include "contact_params.h"

typedef struct ContactPose {
  float3 p;
  float4 q;
} ContactPose;

typedef struct ContactDistance {
  float distance;
  float3 normal;
} ContactDistance;

inline float contact_length3(float3 v) { return sqrt(dot3(v, v)); }

/* std::max and std::clamp of the CPU code, NaN and signed zeros alike. */
inline float contact_max(float a, float b) { return a < b ? b : a; }
inline float contact_clamp(float v, float lo, float hi) { return v < lo ? lo : (hi < v ? hi : v); }

/* a + t (b - a): exactly a when a == b, exactly b at t >= 1. */
inline float3 contact_lerp3(float3 a, float3 b, float t) { return t >= 1.0f ? b : a + t * (b - a); }

/* v rotated by the unit quaternion q: v + 2 w (u x v) + 2 u x (u x v), u = q.xyz. */
inline float3 contact_rotate(float4 q, float3 v) {
  const float3 t = 2.0f * cross3(q.xyz, v);
  return v + q.w * t + cross3(q.xyz, t);
}

/* v rotated by the inverse of the unit quaternion q. */
inline float3 contact_rotate_inverse(float4 q, float3 v) {
  return contact_rotate((float4)(-q.x, -q.y, -q.z, q.w), v);
}

/* The collider's pose at fraction t of the frame: position lerped, rotation
 * nlerped on the shorter arc (CPU: collider_pose). */
inline ContactPose contact_collider_pose(global const ColliderEntry* e, float t) {
  const float3 p0 = (float3)(e->start_px, e->start_py, e->start_pz);
  const float3 p1 = (float3)(e->end_px, e->end_py, e->end_pz);
  const float4 q0 = (float4)(e->start_qx, e->start_qy, e->start_qz, e->start_qw);
  float4 q1 = (float4)(e->end_qx, e->end_qy, e->end_qz, e->end_qw);
  ContactPose pose;
  if (t >= 1.0f) {
    pose.p = p1;
    pose.q = q1;
    return pose;
  }
  if (t <= 0.0f) {
    pose.p = p0;
    pose.q = q0;
    return pose;
  }
  if (q0.x * q1.x + q0.y * q1.y + q0.z * q1.z + q0.w * q1.w < 0.0f) q1 = -1.0f * q1;  // shorter arc
  const float4 q = (1.0f - t) * q0 + t * q1;
  const float norm = sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  pose.p = contact_lerp3(p0, p1, t);
  pose.q = (1.0f / norm) * q;
  return pose;
}

/* Signed distance of a point in the collider's frame (negative inside) and
 * the outward unit normal there, in that frame (CPU: collider_distance). */
inline ContactDistance contact_collider_distance(global const ColliderEntry* e, float3 point) {
  ContactDistance sd;
  switch (e->shape) {
    case SINEW_SHAPE_SPHERE: {
      const float r = contact_length3(point);
      if (r > 0.0f) {
        sd.distance = r - e->radius;
        sd.normal = (1.0f / r) * point;
      } else {
        sd.distance = -e->radius;
        sd.normal = (float3)(0.0f, 1.0f, 0.0f);
      }
      return sd;
    }
    case SINEW_SHAPE_CAPSULE: {
      const float s = contact_clamp(point.y, -e->half_height, e->half_height);
      const float3 v = (float3)(point.x, point.y - s, point.z);
      const float r = contact_length3(v);
      if (r > 0.0f) {
        sd.distance = r - e->radius;
        sd.normal = (1.0f / r) * v;
      } else {
        sd.distance = -e->radius;
        sd.normal = (float3)(1.0f, 0.0f, 0.0f);
      }
      return sd;
    }
    case SINEW_SHAPE_BOX: {
      const float p[3] = {point.x, point.y, point.z};
      const float half_extent[3] = {e->half_x, e->half_y, e->half_z};
      float q[3], out[3], outside = 0.0f;
      int nearest = 0;
      for (int a = 0; a < 3; ++a) {
        q[a] = fabs(p[a]) - half_extent[a];
        out[a] = contact_max(q[a], 0.0f) * (p[a] < 0.0f ? -1.0f : 1.0f);
        outside += out[a] * out[a];
        if (q[a] > q[nearest]) nearest = a;
      }
      if (outside > 0.0f) {  // outside: the distance to the box, along the offset from it
        const float d = sqrt(outside);
        sd.distance = d;
        sd.normal = (float3)(out[0] / d, out[1] / d, out[2] / d);
        return sd;
      }
      float n[3] = {0.0f, 0.0f, 0.0f};  // inside: out through the nearest face
      n[nearest] = p[nearest] < 0.0f ? -1.0f : 1.0f;
      sd.distance = q[nearest];
      sd.normal = (float3)(n[0], n[1], n[2]);
      return sd;
    }
    case SINEW_SHAPE_PLANE:
    default:
      sd.distance = point.y;
      sd.normal = (float3)(0.0f, 1.0f, 0.0f);
      return sd;
  }
}

#endif /* SINEW_CONTACT_MATH_CL_H */
