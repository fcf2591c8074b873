// dd_math.h — double-float arithmetic for the CPU reference kernels: a value
// is the unevaluated sum hi + lo of two floats (~48 significant bits), built
// from error-free transformations that need only correctly rounded float
// operations, no fused multiply-add (Dekker, "A floating-point technique for
// extending the available precision", Numer. Math. 1971; Knuth, TAOCP 2,
// 4.2.2; Hida, Li, Bailey 2007). The GPU twin is kernels/gpu/dd_math.h; both
// perform the same float operations in the same order, so they agree bitwise.
#pragma once

namespace sinew::kernels {

struct dd {
  float hi, lo;
};

/// a + b exactly as s + e (Knuth's TwoSum).
inline dd two_sum(float a, float b) {
  const float s = a + b;
  const float bb = s - a;
  const float e = (a - (s - bb)) + (b - bb);
  return {s, e};
}

/// a + b exactly, for |a| >= |b| (Dekker's FastTwoSum).
inline dd quick_two_sum(float a, float b) {
  const float s = a + b;
  return {s, b - (s - a)};
}

/// a split into two 12-bit halves, a = hi + lo exactly (Veltkamp).
inline dd split(float a) {
  const float c = 4097.0f * a;  // 2^12 + 1
  const float hi = c - (c - a);
  return {hi, a - hi};
}

/// a * b exactly as p + e (Dekker's TwoProduct, without FMA).
inline dd two_prod(float a, float b) {
  const float p = a * b;
  const dd as = split(a), bs = split(b);
  const float e = ((as.hi * bs.hi - p) + as.hi * bs.lo + as.lo * bs.hi) + as.lo * bs.lo;
  return {p, e};
}

inline dd dd_add(dd a, dd b) {
  dd s = two_sum(a.hi, b.hi);
  const dd t = two_sum(a.lo, b.lo);
  s.lo += t.hi;
  s = quick_two_sum(s.hi, s.lo);
  s.lo += t.lo;
  return quick_two_sum(s.hi, s.lo);
}

inline dd dd_neg(dd a) { return {-a.hi, -a.lo}; }

inline dd dd_mul(dd a, dd b) {
  dd p = two_prod(a.hi, b.hi);
  p.lo += a.hi * b.lo + a.lo * b.hi;
  return quick_two_sum(p.hi, p.lo);
}

/// a / b to ~48 bits: q1 = a / b, then one correction with the remainder.
inline dd dd_div(dd a, dd b) {
  const float q1 = a.hi / b.hi;
  const dd r = dd_add(a, dd_neg(dd_mul(dd{q1, 0.0f}, b)));
  const float q2 = r.hi / b.hi;
  return quick_two_sum(q1, q2);
}

inline double dd_value(dd a) { return double(a.hi) + double(a.lo); }

}  // namespace sinew::kernels
