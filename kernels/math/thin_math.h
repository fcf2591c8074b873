// thin_math.h — the constraint functions of thin bodies (triangle meshes)
// and threads, shared by the CPU reference kernels
// (kernels/cpu/thin_kernels.cpp) and the scene compiler, which computes rest
// values with the very same code, so a body at rest has C == 0 exactly.
// Templates: the kernels run them in float, the tests differentiate them in
// double. Keep every operation and its order (the library compiles with
// -ffp-contract=off).
//
// Data layouts and residuals: kernels/shared/thin_params.h; compliances:
// include/sinew/scene.h (TriBodyDesc, LineBodyDesc).
//  - area:     C = A - A0, A = |(x1 - x0) x (x2 - x0)| / 2;
//  - dihedral: C = theta - theta0 (wrapped into [-pi, pi]), theta the signed
//    angle between the two triangles' normals about their shared edge
//    (0 when flat). Müller, Heidelberger, Hennix, Ratcliff, "Position Based
//    Dynamics", VRIPHYS 2006 / JVCIR 2007, section 4.2 uses
//    acos(n1 . n2), whose derivative 1 / sqrt(1 - d^2) is singular at 0 (a
//    flat sheet, the common rest state) and pi, and which has no sign; here
//    theta = atan2(sin, cos) of the normals (see dihedral_angle), with the
//    closed-form gradients of Bridson, Marino, Fedkiw, "Simulation of
//    Clothing with Folds and Wrinkles", SCA 2003, section 4 (also Tamstorf,
//    Grinspun, "Discrete bending forces and their Jacobians", GM 2013),
//    which are smooth through 0 and pi;
//  - line bending: Kelager, Niebe, Erleben, "A Triangle Bending Constraint
//    Model for Position-Based Dynamics", VRIPHYS 2010:
//    C = |x_v - c| - h0, c = (x_b0 + x_v + x_b1) / 3.
#pragma once

#include <cmath>
#include <limits>

#include "math/vec4.h"

namespace sinew::kernels {
namespace thin {

template <class T>
inline constexpr T pi = T(3.14159265358979323846);

/// Triangle area A = |(x1 - x0) x (x2 - x0)| / 2 [m^2] (unsigned: a
/// membrane in 3D has no inside-out); the area constraint is C = A - A0.
template <class T>
inline T triangle_area(vec4<T> x0, vec4<T> x1, vec4<T> x2) {
  const vec4<T> n = cross3(x1 - x0, x2 - x0);
  return T(0.5) * std::sqrt(dot3(n, n));
}

/// [out] g[k] = grad_{x_k} A. With N = (x1 - x0) x (x2 - x0) and
/// n = N / |N|: g1 = (x2 - x0) x n / 2, g2 = n x (x1 - x0) / 2,
/// g0 = -(g1 + g2) (each is half the opposite edge turned in-plane,
/// pointing away from it). Returns false, with g zero, when N == 0 (a
/// triangle collapsed to a line: no direction).
template <class T>
inline bool triangle_area_gradients(vec4<T> x0, vec4<T> x1, vec4<T> x2, vec4<T> g[3]) {
  const vec4<T> e1 = x1 - x0, e2 = x2 - x0;
  const vec4<T> nn = cross3(e1, e2);
  const T len = std::sqrt(dot3(nn, nn));
  if (!(len > T(0))) {
    g[0] = g[1] = g[2] = vec4<T>{T(0), T(0), T(0), T(0)};
    return false;
  }
  const vec4<T> n = (T(1) / len) * nn;
  g[1] = T(0.5) * cross3(e2, n);
  g[2] = T(0.5) * cross3(n, e1);
  g[0] = vec4<T>{T(0), T(0), T(0), T(0)} - (g[1] + g[2]);
  return true;
}

/// atan2(y, x) in [-pi, pi]: the angle of the point (x, y), our own, used
/// by dihedral_angle here and by its GPU twin (thin_atan2_portable in
/// kernels/gpu/thin_math.h, used by kernels/gpu/NAME.gpu, compiled to
/// OpenCL C and SPIR-V), which repeats it operation for operation.
/// Why not std::atan2: the rest angles the scene compiler stores are
/// computed on the host with this function, and a hinge at rest has
/// C == 0 exactly only if every backend computes the very same bits. The C
/// library's atan2f (glibc's, another libm's, a device builtin) differs
/// from one implementation to the next in the last bits or more, and the
/// devices have no C library; + - * / and sqrt are correctly rounded
/// (IEEE 754) on every backend we run, so a fixed sequence of them gives
/// the same result everywhere. The project compiles without contraction
/// (-ffp-contract=off, FP_CONTRACT OFF, GLSL `precise`): no fused
/// multiply-add changes a rounding.
///
/// Algorithm (each step exact or one rounding of + - * / sqrt):
///  1. NaN in, NaN out (x + y). Otherwise the angle a in [0, pi/2] of
///     (|x|, |y|), with the quadrant restored at the end: a -> pi - a when
///     x is negative (sign bit, so x = -0 counts), a -> -a when y is.
///  2. |x| == |y|: a = pi/4 rounded (both infinite included), or 0 when both
///     are zero. Otherwise a = atan(r), r = min/max in [0, 1) (0 when one is
///     zero or infinite), or pi/2 - atan(r) when |y| > |x|: r never
///     overflows, and zeros and infinities need no case of their own.
///  3. atan(r) = 2 atan(t), t = r / (1 + sqrt(1 + r^2)) <= tan(pi/8): the
///     half-angle identity tan(u/2) = sin u / (1 + cos u) with tan u = r,
///     cos u = 1 / sqrt(1 + r^2) (on argument reduction: J.-M. Muller,
///     "Elementary Functions: Algorithms and Implementation", Birkhauser,
///     chapter "Range reduction"). A
///     second halving (t <= tan(pi/16)) would shorten the series but
///     repeats the reduction's roundings: about 4.6 ulp in float instead
///     of 3.9, 3.3 eps in double instead of 2.2.
///  4. atan(t) = t - t^3/3 + t^5/5 - ... (Gregory's series,
///     Abramowitz & Stegun 4.4.42), in Horner form in z = t^2 as
///     t + t (z q), q = -1/3 + z (1/5 + z (-1/7 + ...)), each coefficient
///     (-1)^k / (2k + 1) rounded to T. The series alternates with
///     decreasing terms, so cutting it after n terms errs by less than
///     the first term left out, t^(2n+1) / (2n+1), relative t^(2n) / (2n+1)
///     <= 0.1716^n / (2n+1) (tan^2(pi/8) = 0.1716); half an ulp is at least
///     2^-(p+1) relative for p significand bits. float (p = 24): n = 9 gives
///     6.8e-9 < 2^-25 = 3.0e-8 (n = 8: 4.4e-8, too much); double (p = 53):
///     n = 20 gives 1.2e-17 < 2^-54 = 5.6e-17 (n = 19: 7.3e-17).
/// Accuracy, measured (tests/thin_test.cpp, ThinMath; 2e8 random pairs):
/// float within 3.9 ulp of the exact atan2 of its arguments, double within
/// 2.2 eps relative; the roundings of r and t dominate (glibc's atan2f:
/// about 1.5 ulp by the same measure). Plenty for an angle whose rest
/// value is computed by the same function.
/// C's conventions hold: atan2(+-0, +0) = +-0, atan2(+-0, -0) = +-pi,
/// atan2(+-y, +inf) = +-0, atan2(+-y, -inf) = +-pi, atan2(+-inf, x) =
/// +-pi/2, atan2(+-inf, +-inf) = +-pi/4 or +-3pi/4, exactly rounded; and
/// atan2(-y, x) = -atan2(y, x) bit for bit.
template <class T>
inline T atan2_portable(T y, T x) {
  static_assert(std::numeric_limits<T>::digits == 24 || std::numeric_limits<T>::digits == 53);
  constexpr int terms = std::numeric_limits<T>::digits == 24 ? 9 : 20;  // see 4. above
  if (std::isnan(x) || std::isnan(y)) return x + y;
  const T ax = std::fabs(x), ay = std::fabs(y);
  const auto atan01 = [](T r) {  // atan(r), r in [0, 1]
    const T t = r / (T(1) + std::sqrt(T(1) + r * r));
    const T z = t * t;
    T q = T(0);
    for (int k = terms - 1; k >= 1; --k) q = T(k % 2 ? -1 : 1) / T(2 * k + 1) + z * q;
    return T(2) * (t + t * (z * q));
  };
  T a;
  if (ax == ay) a = ax == T(0) ? T(0) : pi<T> / T(4);
  else if (ay < ax) a = atan01(ay / ax);
  else a = pi<T> / T(2) - atan01(ax / ay);
  if (std::signbit(x)) a = pi<T> - a;
  return std::signbit(y) ? -a : a;
}

/// The signed dihedral angle theta [rad] in (-pi, pi] of the hinge x0-x1
/// (the shared edge, e = x1 - x0) with wing vertices x2 and x3:
/// N1 = e x (x2 - x0) (the normal of triangle (x0, x1, x2)),
/// N2 = (x3 - x0) x e (of (x1, x0, x3): both triangles wound alike across
/// the edge), theta = atan2((n1 x n2) . e / |e|, n1 . n2) with n = N / |N|.
/// theta = 0 when the hinge is flat, +-pi when folded shut; moving the wing
/// x2 along +N1 (or x3 along +N2) decreases it.
/// atan2 keeps full precision near 0 and pi, where acos(n1 . n2) loses half
/// its digits; it is atan2_portable, so that every backend computes the same
/// bits as the scene compiler's rest angle. Returns 0 when the edge or a
/// wing is degenerate.
template <class T>
inline T dihedral_angle(vec4<T> x0, vec4<T> x1, vec4<T> x2, vec4<T> x3) {
  const vec4<T> e = x1 - x0;
  const vec4<T> n1 = cross3(e, x2 - x0), n2 = cross3(x3 - x0, e);
  const T l1 = std::sqrt(dot3(n1, n1)), l2 = std::sqrt(dot3(n2, n2)), le = std::sqrt(dot3(e, e));
  if (!(l1 > T(0)) || !(l2 > T(0)) || !(le > T(0))) return T(0);
  const vec4<T> u1 = (T(1) / l1) * n1, u2 = (T(1) / l2) * n2;
  const T s = dot3(cross3(u1, u2), e) / le;  // sin theta
  const T c = dot3(u1, u2);                  // cos theta
  return atan2_portable(s, c);
}

/// d wrapped into [-pi, pi] (d in (-2 pi, 2 pi], a difference of two
/// dihedral angles): the dihedral constraint is C = wrap(theta - theta0), so
/// that a hinge whose rest angle is near +-pi has no jump where theta
/// crosses from +pi to -pi.
template <class T>
inline T wrap_angle(T d) {
  if (d > pi<T>) return d - T(2) * pi<T>;
  if (d < -pi<T>) return d + T(2) * pi<T>;
  return d;
}

/// [out] g[k] = grad_{x_k} theta (Bridson et al. 2003, in the notation of
/// dihedral_angle): with |e| the edge length, a wing's gradient is normal to
/// its triangle and inversely proportional to its height h = |N| / |e|,
///   g2 = -|e| N1 / |N1|^2,  g3 = -|e| N2 / |N2|^2,
/// and the edge vertices take the balancing share by where the wings'
/// projections fall on the edge, s_k = (x_k - x0) . e / |e|^2:
///   g1 = -(s2 g2 + s3 g3),  g0 = -((1 - s2) g2 + (1 - s3) g3),
/// so that the gradients sum to zero (translation) and have no moment
/// (rotation). Smooth for every theta, including 0 and +-pi. Returns false,
/// with g zero, when the edge or a wing is degenerate (|e| or |N| zero).
template <class T>
inline bool dihedral_angle_gradients(vec4<T> x0, vec4<T> x1, vec4<T> x2, vec4<T> x3, vec4<T> g[4]) {
  const vec4<T> e = x1 - x0, a = x2 - x0, b = x3 - x0;
  const vec4<T> n1 = cross3(e, a), n2 = cross3(b, e);
  const T q1 = dot3(n1, n1), q2 = dot3(n2, n2), qe = dot3(e, e);
  if (!(q1 > T(0)) || !(q2 > T(0)) || !(qe > T(0))) {
    g[0] = g[1] = g[2] = g[3] = vec4<T>{T(0), T(0), T(0), T(0)};
    return false;
  }
  const T le = std::sqrt(qe);
  g[2] = (-le / q1) * n1;
  g[3] = (-le / q2) * n2;
  const T s2 = dot3(a, e) / qe, s3 = dot3(b, e) / qe;
  const vec4<T> zero{T(0), T(0), T(0), T(0)};
  g[1] = zero - (s2 * g[2] + s3 * g[3]);
  g[0] = zero - ((T(1) - s2) * g[2] + (T(1) - s3) * g[3]);
  return true;
}

/// Kelager et al. 2010: the distance |x_v - c| [m] of the middle vertex x_v
/// of a thread from the centroid c = (x_b0 + x_v + x_b1) / 3 of the triangle
/// it forms with its neighbours x_b0, x_b1; 0 when the thread is straight
/// and evenly divided there. The bending constraint is C = |x_v - c| - h0.
template <class T>
inline T line_bending_offset(vec4<T> b0, vec4<T> v, vec4<T> b1) {
  const vec4<T> d = v - (T(1) / T(3)) * (b0 + v + b1);
  return std::sqrt(dot3(d, d));
}

/// [out] g = (grad_b0, grad_v, grad_b1) of |x_v - c|: with n = (x_v - c) /
/// |x_v - c|, grad_v = 2 n / 3 and grad_b0 = grad_b1 = -n / 3. Returns false,
/// with g zero, when x_v is at the centroid (no direction).
template <class T>
inline bool line_bending_gradients(vec4<T> b0, vec4<T> v, vec4<T> b1, vec4<T> g[3]) {
  const vec4<T> d = v - (T(1) / T(3)) * (b0 + v + b1);
  const T len = std::sqrt(dot3(d, d));
  if (!(len > T(0))) {
    g[0] = g[1] = g[2] = vec4<T>{T(0), T(0), T(0), T(0)};
    return false;
  }
  const vec4<T> n = (T(1) / len) * d;
  g[1] = (T(2) / T(3)) * n;
  g[0] = g[2] = (T(-1) / T(3)) * n;
  return true;
}

}  // namespace thin
}  // namespace sinew::kernels
