// suture_kernels.cpp — CPU reference of the needles' and sutures' rows:
// the thread tied to the needle's tail, the tip pushing a surface, the
// tissue held on the needle (puncture) and on the thread; layout and
// formulation in kernels/shared/suture_params.h (after Moore et al., "The
// interactive medical simulation toolkit (iMSTK)", Frontiers in Virtual
// Reality 2023, section 2.5; Macklin, Müller, Chentanez, "XPBD", MIG 2016;
// Macklin et al., "Unified Particle Physics", SIGGRAPH 2014, eq. 24-25 for
// the thread's friction; Karnopp, J. Dyn. Sys. Meas. Control 107(1), 1985, as
// Okamura, Simone and O'Leary, IEEE TBME 51(10), 2004, fit it to needle
// insertion, for the shaft's friction). The GPU twin (kernels/gpu/xpbd_sutures.gpu) does
// the same float operations in the same order.
#include <cmath>

#include "cpu/cpu_kernels.h"
#include "math/vec4.h"
#include "suture_params.h"

namespace sinew::kernels {
namespace {

struct Bindings {
  float4* x;
  const float4* prev;
  const std::uint32_t* table;
  const float4* needles;
  const float4* curve;
  const std::uint32_t* slots;
  uint4* rows;
  float4* weights;
  float4* lambda;
};

// Point k of needle n at fraction t of the frame (the lerp of its start and end).
float4 curve_point(const Bindings& b, std::uint32_t n, std::uint32_t k, float t) {
  const std::uint32_t at = b.table[1 + 2 * n] + k;
  const float4 s = b.curve[2 * at], e = b.curve[2 * at + 1];
  if (t >= 1.0f) return float4{e.x, e.y, e.z, 0.0f};
  const float4 r = s + t * (e - s);
  return float4{r.x, r.y, r.z, 0.0f};
}

// v's direction, w = 0 (as the GPU's float3).
float4 unit(float4 v) {
  const float length = std::sqrt(dot3(v, v));
  if (!(length > 0.0f)) return float4{0.0f, 0.0f, 0.0f, 0.0f};
  const float4 r = (1.0f / length) * v;
  return float4{r.x, r.y, r.z, 0.0f};
}

// The closest point of the needle's polyline to p: its position, segment
// and parameter on it.
struct Closest {
  float4 q;
  std::uint32_t segment;
  float u;
};
Closest closest_on_needle(const Bindings& b, std::uint32_t n, float4 p, float t) {
  const std::uint32_t points = b.table[2 + 2 * n];
  Closest best{curve_point(b, n, 0, t), 0, 0.0f};
  float best_d2 = -1.0f;
  float4 a = best.q;
  for (std::uint32_t j = 0; j + 1 < points; ++j) {
    const float4 c = curve_point(b, n, j + 1, t);
    const float4 e = c - a;
    const float length2 = dot3(e, e);
    float u = length2 > 0.0f ? dot3(p - a, e) / length2 : 0.0f;
    u = u < 0.0f ? 0.0f : u > 1.0f ? 1.0f : u;
    const float4 q = a + u * e;
    const float4 d = p - q;
    const float d2 = dot3(d, d);
    if (best_d2 < 0.0f || d2 < best_d2) best = {q, j, u}, best_d2 = d2;
    a = c;
  }
  return best;
}

// The tissue point of a row: the sum of its weights times its particles.
float4 tissue_point(const float4* x, const std::uint32_t* v, float4 w) {
  const float4 p = w.x * x[v[0]] + w.y * x[v[1]];
  return p + w.z * x[v[2]];
}

// Moves particles v[0..count) by w_k c_k dl along dir (movable ones only).
void apply(const Bindings& b, const std::uint32_t* v, const float* c, std::uint32_t count, float4 dir, float dl) {
  for (std::uint32_t k = 0; k < count; ++k) {
    const float4 xk = b.x[v[k]];
    if (!(xk.w > 0.0f)) continue;
    const float m = xk.w * c[k] * dl;
    b.x[v[k]] = float4{xk.x + m * dir.x, xk.y + m * dir.y, xk.z + m * dir.z, xk.w};
  }
}

}  // namespace

// Every row, in order: what it joins (particles v, coefficients c along the
// direction dir, its constraint C), one xPBD step, and the thread rows'
// friction.
void xpbd_sutures(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  if (begin != 0 || end == 0) return;  // one item does every row
  const auto& p = *static_cast<const SutureParams*>(params);
  const Bindings b{reinterpret_cast<float4*>(bindings[0]),
                   reinterpret_cast<const float4*>(bindings[1]),
                   reinterpret_cast<const std::uint32_t*>(bindings[2]),
                   reinterpret_cast<const float4*>(bindings[3]),
                   reinterpret_cast<const float4*>(bindings[4]),
                   reinterpret_cast<const std::uint32_t*>(bindings[5]),
                   reinterpret_cast<uint4*>(bindings[6]),
                   reinterpret_cast<float4*>(bindings[7]),
                   reinterpret_cast<float4*>(bindings[8])};
  const float t = p.substep_end;
  const float4 zero{0.0f, 0.0f, 0.0f, 0.0f};
  for (std::uint32_t i = 0; i < b.table[0]; ++i) {
    uint4* r = b.rows + 2 * std::size_t{i};
    float4* l = b.lambda + 3 * std::size_t{i};
    if (p.reset_lambda == 2u) l[2] = zero;
    if (p.reset_lambda == 1u) l[2] = l[2] + l[1];
    // (l[0].z, the shaft's slide speed at the end of the last substep, carries over.)
    if (p.reset_lambda != 0u) l[0] = float4{0.0f, 0.0f, l[0].z, 0.0f}, l[1] = zero;
    if (r[0].x == SINEW_SUTURE_DEAD) continue;
    const std::uint32_t n = r[0].y, points = b.table[2 + 2 * n];
    const float4 needle = b.needles[3 * n];
    const float4 shaft = b.needles[3 * n + 1];  // (f_c, f_s, b, v_band)
    const float cut = b.needles[3 * n + 2].x;
    const float alpha = needle.x * p.inv_h2;
    const float4 w = b.weights[i];
    std::uint32_t v[5] = {r[0].z, r[0].w, r[1].x, 0, 0};
    float c[5] = {w.x, w.y, w.z, 0.0f, 0.0f};
    std::uint32_t count = 3;
    float4 dir = zero;
    float constraint = 0.0f;
    bool unilateral = false;
    std::uint32_t near_segment = 0;  // a puncture's closest point on the needle
    float near_u = 0.0f;
    const float4 p_now = tissue_point(b.x, v, w);
    if (r[0].x == SINEW_SUTURE_TIE) {
      const float4 d = b.x[v[0]] - curve_point(b, n, 0, t);
      constraint = std::sqrt(dot3(d, d));
      dir = unit(d);
      c[0] = 1.0f;
      count = 1;
    } else if (r[0].x == SINEW_SUTURE_TIP) {
      // Along the triangle's normal, turned the way the tip goes (into the
      // tissue): the surface, not the tip's axis, says which way it gives.
      const float4 tip = curve_point(b, n, points - 1, t);
      const float4 d_tip = unit(tip - curve_point(b, n, points - 2, t));
      dir = unit(cross3(b.x[v[1]] - b.x[v[0]], b.x[v[2]] - b.x[v[0]]));
      if (dot3(dir, d_tip) < 0.0f) dir = float4{-dir.x, -dir.y, -dir.z, 0.0f};
      constraint = dot3(dir, p_now - tip);
      unilateral = true;
    } else if (r[0].x == SINEW_SUTURE_BLUNT) {
      // Kept ahead of the blunt tip's rounded end along the tip's axis: the
      // end is a hemisphere of radius R, set back from the tip by
      // R - sqrt(R^2 - r^2) at r from the axis (a flat end's rim, a step
      // as deep as the dent, would shear the tets there).
      const float4 tip = curve_point(b, n, points - 1, t);
      dir = unit(tip - curve_point(b, n, points - 2, t));
      const float4 off = p_now - tip;
      const float ahead = dot3(dir, off);
      const float radius = b.needles[3 * n + 2].y;
      const float left = radius * radius - (dot3(off, off) - ahead * ahead);
      const float sag = radius - std::sqrt(left > 0.0f ? left : 0.0f);
      constraint = ahead + sag;
      unilateral = true;
    } else if (r[0].x == SINEW_SUTURE_PUNCTURE) {
      const Closest q = closest_on_needle(b, n, p_now, t);
      near_segment = q.segment;
      near_u = q.u;
      const float4 d_tail = unit(curve_point(b, n, 1, t) - curve_point(b, n, 0, t));
      if (q.segment == 0 && q.u == 0.0f && dot3(d_tail, p_now - q.q) < 0.0f) {
        // The needle has passed this point: onto its thread (its
        // multipliers start afresh), or free.
        r[0].x = r[1].z >= 2u ? SINEW_SUTURE_THREAD : SINEW_SUTURE_DEAD;
        r[1].w = 0u;
        b.weights[i].w = 0.0f;
        l[0] = zero;
        if (r[0].x == SINEW_SUTURE_DEAD) continue;
      } else {
        float4 d = p_now - q.q;
        if (q.segment + 2u == points && q.u == 1.0f) {
          // Beyond the tip: held on the tip's axis only, so that a needle
          // pulled back leaves the point behind (the host then ends it).
          const float4 d_tip = unit(q.q - curve_point(b, n, points - 2, t));
          const float ahead = dot3(d_tip, d);
          if (ahead > 0.0f) d = d - ahead * d_tip;
        }
        constraint = std::sqrt(dot3(d, d));
        dir = unit(d);
      }
    }
    float s = 0.0f;
    if (r[0].x == SINEW_SUTURE_THREAD) {
      // Follow the thread to the segment closest to p (its last vertex a knot).
      const std::uint32_t first = r[1].y, vertices = r[1].z;
      // (The friction's multiplier carries over to a neighbouring segment:
      // its tangent is nearly the same. Zeroing it let the thread slip at
      // every segment boundary: the cut closed 4 -> 3.57 mm instead of 3.25.)
      std::uint32_t segment = r[1].w;
      for (std::uint32_t move = 0;; ++move) {
        const float4 a = b.x[b.slots[first + segment]];
        const float4 e = b.x[b.slots[first + segment + 1]] - a;
        const float length2 = dot3(e, e);
        s = length2 > 0.0f ? dot3(p_now - a, e) / length2 : 0.0f;
        if (move == SINEW_SUTURE_MAX_MOVES) break;
        if (s < 0.0f && segment > 0u) --segment;
        else if (s > 1.0f && segment + 2u < vertices) ++segment;
        else break;
      }
      s = s < 0.0f ? 0.0f : s > 1.0f ? 1.0f : s;
      r[1].w = segment;
      b.weights[i].w = s;
      v[3] = b.slots[first + segment];
      v[4] = b.slots[first + segment + 1];
      c[3] = -(1.0f - s);
      c[4] = -s;
      count = 5;
      const float4 d = p_now - ((1.0f - s) * b.x[v[3]] + s * b.x[v[4]]);
      constraint = std::sqrt(dot3(d, d));
      dir = unit(d);
    }
    float weight = 0.0f;
    for (std::uint32_t k = 0; k < count; ++k) weight = weight + b.x[v[k]].w * (c[k] * c[k]);
    if (!(weight > 0.0f)) continue;
    float lambda_n = l[0].x, lambda_t = l[0].y, slip = l[0].z;
    // The impulse given this substep, summed step by step: the directions
    // turn between sweeps, so lambda times the last direction is not it.
    float4 given = l[1];
    // A contact apart and not pushed in this substep does nothing; a
    // puncture or tie exactly met has no direction and needs nothing.
    const bool acts = unilateral ? (lambda_n > 0.0f || constraint < 0.0f) : constraint > 0.0f;
    if (acts) {
      float dl = (-constraint - alpha * lambda_n) / (weight + alpha);
      if (unilateral) dl = (lambda_n + dl > 0.0f ? lambda_n + dl : 0.0f) - lambda_n;
      apply(b, v, c, count, dir, dl);
      given = given + dl * dir;
      lambda_n = lambda_n + dl;
    }
    float4 tangent = zero;
    if (r[0].x == SINEW_SUTURE_TIP && lambda_n > 0.0f) {
      // A pushing tip catches the tissue (holds the point on its axis)
      // while the sideways pull stays within tan(max_puncture_angle) of
      // its push; beyond, the point slides, held at that bound.
      const float4 tip = curve_point(b, n, points - 1, t);
      const float4 ahead = tissue_point(b.x, v, w) - tip;
      const float4 across = ahead - dot3(dir, ahead) * dir;
      const float offset = std::sqrt(dot3(across, across));
      if (offset > 0.0f) {
        tangent = unit(across);
        const float held = lambda_t + (-offset - alpha * lambda_t) / (weight + alpha);
        const float limit = needle.w * lambda_n;
        const float next = std::fabs(held) <= limit ? held : (held > 0.0f ? limit : -limit);
        apply(b, v, c, count, tangent, next - lambda_t);
        given = given + (next - lambda_t) * tangent;
        lambda_t = next;
      }
    }
    if (r[0].x == SINEW_SUTURE_PUNCTURE &&
        (shaft.x > 0.0f || shaft.y > 0.0f || shaft.z > 0.0f || cut > 0.0f)) {
      // The shaft's Karnopp friction: the tissue point's slide along the
      // needle relative to the needle's own point over the substep.
      const float4 a0 = curve_point(b, n, near_segment, t), a1 = curve_point(b, n, near_segment + 1, t);
      const float4 b0 = curve_point(b, n, near_segment, p.substep_begin);
      const float4 b1 = curve_point(b, n, near_segment + 1, p.substep_begin);
      tangent = unit(a1 - a0);
      const float one_minus_u = 1.0f - near_u;
      const float4 moved = (one_minus_u * a0 + near_u * a1) - (one_minus_u * b0 + near_u * b1);
      float4 slide = zero;
      for (std::uint32_t k = 0; k < count; ++k) slide = slide + c[k] * (b.x[v[k]] - b.prev[v[k]]);
      const float rel = dot3(tangent, slide - moved);
      const float held = lambda_t - rel / weight;  // the multiplier that stops the slide
      const float magnitude = std::fabs(held);
      // The cutting force resists the needle advancing (the tissue held
      // towards the tip: held > 0) on the row of the body the tip is in.
      const float cutting = r[1].w == 1u && held > 0.0f ? cut : 0.0f;
      const float h2 = p.h * p.h;
      float limit = 0.0f;
      if (slip <= shaft.w) {
        // Karnopp: sliding slower than the band at the last substep's end,
        // it sticks while the static level holds it, else breaks away at it.
        limit = (shaft.y * w.w + cutting) * h2;
      } else {
        // Slipping: Coulomb, plus a viscous force on the slide that remains
        // (implicit: b L h W of it, over 1 + b L h W, so that a large b
        // brakes the slide without reversing it).
        const float coulomb = (shaft.x * w.w + cutting) * h2;
        const float k = shaft.z * w.w * p.h * weight;
        limit = magnitude <= coulomb ? magnitude : (coulomb + k * magnitude) / (1.0f + k);
      }
      const float next = magnitude <= limit ? held : (held > 0.0f ? limit : -limit);
      slip = std::fabs(held - next) * weight / p.h;
      apply(b, v, c, count, tangent, next - lambda_t);
      given = given + (next - lambda_t) * tangent;
      lambda_t = next;
    }
    if (r[0].x == SINEW_SUTURE_THREAD) {
      // Friction: the tissue point's slide along the thread relative to the
      // thread's point, since the substep's start.
      tangent = unit(b.x[v[4]] - b.x[v[3]]);
      float4 slide = zero;
      for (std::uint32_t k = 0; k < count; ++k) slide = slide + c[k] * (b.x[v[k]] - b.prev[v[k]]);
      const float held = lambda_t - dot3(tangent, slide) / weight;
      const float limit = needle.y * std::fabs(lambda_n);
      const float kinetic = needle.z * std::fabs(lambda_n);
      const float next = std::fabs(held) <= limit ? held : held > 0.0f ? kinetic : -kinetic;
      apply(b, v, c, count, tangent, next - lambda_t);
      given = given + (next - lambda_t) * tangent;
      lambda_t = next;
    }
    l[0] = float4{lambda_n, lambda_t, slip, 0.0f};
    l[1] = float4{given.x, given.y, given.z, 0.0f};
  }
}

}  // namespace sinew::kernels
