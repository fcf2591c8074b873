/* dd_math.h — double-float arithmetic for the GPU kernels, the twin of
 * kernels/cpu/dd_math.h (same float operations in the same order, every
 * result PRECISE, so the two agree bitwise). A value is float2(hi, lo),
 * the unevaluated sum hi + lo (~48 significant bits); Dekker 1971, Knuth
 * TAOCP 2 4.2.2, Hida, Li, Bailey 2007. */
#ifndef SINEW_GPU_DD_MATH_H
#define SINEW_GPU_DD_MATH_H

float2 dd_two_sum(float a, float b) {
  PRECISE float s = a + b;
  PRECISE float bb = s - a;
  PRECISE float e = (a - (s - bb)) + (b - bb);
  return make_float2(s, e);
}

float2 dd_quick_two_sum(float a, float b) {
  PRECISE float s = a + b;
  PRECISE float e = b - (s - a);
  return make_float2(s, e);
}

float2 dd_split(float a) {
  PRECISE float c = 4097.0f * a;
  PRECISE float hi = c - (c - a);
  PRECISE float lo = a - hi;
  return make_float2(hi, lo);
}

float2 dd_two_prod(float a, float b) {
  PRECISE float p = a * b;
  const float2 as = dd_split(a);
  const float2 bs = dd_split(b);
  PRECISE float e = ((as.x * bs.x - p) + as.x * bs.y + as.y * bs.x) + as.y * bs.y;
  return make_float2(p, e);
}

float2 dd_add(float2 a, float2 b) {
  float2 s = dd_two_sum(a.x, b.x);
  const float2 t = dd_two_sum(a.y, b.y);
  PRECISE float e1 = s.y + t.x;
  s = dd_quick_two_sum(s.x, e1);
  PRECISE float e2 = s.y + t.y;
  return dd_quick_two_sum(s.x, e2);
}

float2 dd_neg(float2 a) { return make_float2(-a.x, -a.y); }

float2 dd_sub(float2 a, float2 b) { return dd_add(a, dd_neg(b)); }

float2 dd_mul(float2 a, float2 b) {
  const float2 p = dd_two_prod(a.x, b.x);
  PRECISE float cross = a.x * b.y + a.y * b.x;
  PRECISE float e = p.y + cross;
  return dd_quick_two_sum(p.x, e);
}

float2 dd_div(float2 a, float2 b) {
  PRECISE float q1 = a.x / b.x;
  const float2 r = dd_add(a, dd_neg(dd_mul(make_float2(q1, 0.0f), b)));
  PRECISE float q2 = r.x / b.x;
  return dd_quick_two_sum(q1, q2);
}

#endif /* SINEW_GPU_DD_MATH_H */
