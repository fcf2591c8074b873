/* contact_math.h — helpers of the GLSL contact kernels
 * (xpbd_solve_attachment.comp, xpbd_solve_contacts.comp), twins of the ones
 * in kernels/cpu/contact_kernels.h and .cpp (and kernels/opencl/contact_math.h):
 * quaternion rotation, collider poses interpolated across a frame and the
 * signed distance of each shape. Same operation order as the CPU code; every
 * arithmetic result is `precise` (SPIR-V NoContraction) so nothing is fused
 * into a multiply-add, here in the helpers too.
 * Macklin, Müller, Chentanez, "XPBD", MIG 2016; Macklin, Müller, Chentanez,
 * Kim, "Unified Particle Physics for Real-Time Applications", SIGGRAPH 2014
 * (friction, used by xpbd_solve_contacts.comp).
 *
 * Quaternions are vec4 (x, y, z, w), w the scalar part, as in the CPU Pose. */
#ifndef SINEW_CONTACT_MATH_GLSL_H
#define SINEW_CONTACT_MATH_GLSL_H

#include "glsl_math.h"
#include "contact_params.h"

precise float contact_length3(vec3 v) {
  precise float d = dot3(v, v);
  return sqrt(d);
}

/* std::max and std::clamp of the CPU code, NaN and signed zeros alike. */
float contact_max(float a, float b) { return a < b ? b : a; }
float contact_clamp(float v, float lo, float hi) { return v < lo ? lo : (hi < v ? hi : v); }

/* a + t (b - a): exactly a when a == b, exactly b at t >= 1. */
precise vec3 contact_lerp3(vec3 a, vec3 b, float t) {
  if (t >= 1.0) return b;
  precise vec3 r = a + t * (b - a);
  return r;
}

/* v rotated by the unit quaternion q: v + 2 w (u x v) + 2 u x (u x v), u = q.xyz. */
precise vec3 contact_rotate(vec4 q, vec3 v) {
  precise vec3 t = 2.0 * cross3(q.xyz, v);
  precise vec3 r = (v + q.w * t) + cross3(q.xyz, t);
  return r;
}

/* v rotated by the inverse of the unit quaternion q. */
precise vec3 contact_rotate_inverse(vec4 q, vec3 v) { return contact_rotate(vec4(-q.x, -q.y, -q.z, q.w), v); }

/* The collider's pose at fraction t of the frame: position lerped, rotation
 * nlerped on the shorter arc (CPU: collider_pose). */
void contact_collider_pose(ColliderEntry e, float t, out vec3 position, out vec4 rotation) {
  const vec3 p0 = vec3(e.start_px, e.start_py, e.start_pz);
  const vec3 p1 = vec3(e.end_px, e.end_py, e.end_pz);
  const vec4 q0 = vec4(e.start_qx, e.start_qy, e.start_qz, e.start_qw);
  vec4 q1 = vec4(e.end_qx, e.end_qy, e.end_qz, e.end_qw);
  if (t >= 1.0) {
    position = p1;
    rotation = q1;
    return;
  }
  if (t <= 0.0) {
    position = p0;
    rotation = q0;
    return;
  }
  precise float arc = ((q0.x * q1.x + q0.y * q1.y) + q0.z * q1.z) + q0.w * q1.w;
  if (arc < 0.0) {  // shorter arc
    precise vec4 flipped = -1.0 * q1;
    q1 = flipped;
  }
  precise vec4 q = (1.0 - t) * q0 + t * q1;
  precise float norm = sqrt(((q.x * q.x + q.y * q.y) + q.z * q.z) + q.w * q.w);
  precise vec4 unit = (1.0 / norm) * q;
  position = contact_lerp3(p0, p1, t);
  rotation = unit;
}

/* Signed distance of a point in the collider's frame (negative inside) and
 * the outward unit normal there, in that frame (CPU: collider_distance). */
void contact_collider_distance(ColliderEntry e, vec3 local, out float distance, out vec3 normal) {
  switch (e.shape) {
    case SINEW_SHAPE_SPHERE: {
      precise float r = contact_length3(local);
      if (r > 0.0) {
        precise float d = r - e.radius;
        precise vec3 nn = (1.0 / r) * local;
        distance = d;
        normal = nn;
      } else {
        distance = -e.radius;
        normal = vec3(0.0, 1.0, 0.0);
      }
      return;
    }
    case SINEW_SHAPE_CAPSULE: {
      const float s = contact_clamp(local.y, -e.half_height, e.half_height);
      precise vec3 v = vec3(local.x, local.y - s, local.z);
      precise float r = contact_length3(v);
      if (r > 0.0) {
        precise float d = r - e.radius;
        precise vec3 nn = (1.0 / r) * v;
        distance = d;
        normal = nn;
      } else {
        distance = -e.radius;
        normal = vec3(1.0, 0.0, 0.0);
      }
      return;
    }
    case SINEW_SHAPE_BOX: {
      const float p[3] = float[3](local.x, local.y, local.z);
      const float half_extent[3] = float[3](e.half_x, e.half_y, e.half_z);
      precise float q[3];
      precise float out_offset[3];
      precise float outside = 0.0;
      int nearest = 0;
      for (int a = 0; a < 3; ++a) {
        q[a] = abs(p[a]) - half_extent[a];
        out_offset[a] = contact_max(q[a], 0.0) * (p[a] < 0.0 ? -1.0 : 1.0);
        outside = outside + out_offset[a] * out_offset[a];
        if (q[a] > q[nearest]) nearest = a;
      }
      if (outside > 0.0) {  // outside: the distance to the box, along the offset from it
        precise float d = sqrt(outside);
        precise vec3 nn = vec3(out_offset[0] / d, out_offset[1] / d, out_offset[2] / d);
        distance = d;
        normal = nn;
        return;
      }
      vec3 n = vec3(0.0);  // inside: out through the nearest face
      n[nearest] = p[nearest] < 0.0 ? -1.0 : 1.0;
      distance = q[nearest];
      normal = n;
      return;
    }
    case SINEW_SHAPE_PLANE:
    default:
      distance = local.y;
      normal = vec3(0.0, 1.0, 0.0);
      return;
  }
}

#endif /* SINEW_CONTACT_MATH_GLSL_H */
