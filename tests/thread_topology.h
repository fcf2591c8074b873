// thread_topology.h — topological checks for the threads in the tests
// (issue 13): the linking number of two closed polygons and which side of a
// membrane a point is on, from positions alone. Neither uses the solver's
// collision code, so they can catch it letting a crossing through.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace sinew::test {

using Point3 = std::array<double, 3>;

/// The two counts of a linking number by signed crossings in a projection:
/// `over` sums the crossings where polygon a passes over b, `under` those
/// where it passes under. For closed polygons in a generic projection they
/// are equal, and equal to the (Gauss) linking number, which changes only
/// when one polygon passes through the other.
struct LinkingCount {
  int over = 0, under = 0;
};

/// Projects closed polygons a and b (vertex i joined to i + 1, the last to
/// the first) along a fixed direction that no test geometry lines up with
/// (two irrational-looking rotations), and counts their signed crossings.
/// A crossing's sign is that of (upper strand's direction x lower's) along
/// the projection, oriented from a's direction to b's.
inline LinkingCount linking_count(const std::vector<Point3>& a, const std::vector<Point3>& b) {
  const double rx = 0.3137, ry = 0.7219;
  const auto turn = [&](Point3 p) {
    const double y = p[1] * std::cos(rx) - p[2] * std::sin(rx), z1 = p[1] * std::sin(rx) + p[2] * std::cos(rx);
    const double x = p[0] * std::cos(ry) + z1 * std::sin(ry), z = -p[0] * std::sin(ry) + z1 * std::cos(ry);
    return Point3{x, y, z};
  };
  std::vector<Point3> pa, pb;
  for (const Point3& p : a) pa.push_back(turn(p));
  for (const Point3& p : b) pb.push_back(turn(p));
  LinkingCount count;
  for (std::size_t i = 0; i < pa.size(); ++i)
    for (std::size_t j = 0; j < pb.size(); ++j) {
      const Point3 &p0 = pa[i], &p1 = pa[(i + 1) % pa.size()], &q0 = pb[j], &q1 = pb[(j + 1) % pb.size()];
      const double dx = p1[0] - p0[0], dy = p1[1] - p0[1], ex = q1[0] - q0[0], ey = q1[1] - q0[1];
      const double den = dx * ey - dy * ex;
      if (den == 0.0) continue;
      const double s = ((q0[0] - p0[0]) * ey - (q0[1] - p0[1]) * ex) / den;
      const double t = ((q0[0] - p0[0]) * dy - (q0[1] - p0[1]) * dx) / den;
      if (s < 0.0 || s >= 1.0 || t < 0.0 || t >= 1.0) continue;  // half-open: a shared vertex counts once
      const double za = p0[2] + s * (p1[2] - p0[2]), zb = q0[2] + t * (q1[2] - q0[2]);
      const int sign = den > 0.0 ? 1 : -1;  // a's direction to b's
      if (za > zb) count.over += sign;
      else count.under -= sign;  // b over a: the upper strand is b's
    }
  return count;
}

/// How many triangles of a mesh the ray from p straight up (+y) passes
/// through: odd when p is under a membrane that is a height field over it
/// (every vertical line meets it once), even (0) when it is above or
/// beside it. Triangles seen edge-on from above are skipped (they cannot be
/// the only crossing of a height field).
inline int crossings_above(const Point3& p, const std::vector<Point3>& vertices,
                           const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  int count = 0;
  for (const auto& t : triangles) {
    const Point3 &a = vertices[t[0]], &b = vertices[t[1]], &c = vertices[t[2]];
    // Barycentric coordinates of p's (x, z) in the triangle's (x, z).
    const double det = (b[0] - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (b[2] - a[2]);
    if (det == 0.0) continue;
    const double u = ((p[0] - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (p[2] - a[2])) / det;
    const double v = ((b[0] - a[0]) * (p[2] - a[2]) - (p[0] - a[0]) * (b[2] - a[2])) / det;
    if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
    const double y = a[1] + u * (b[1] - a[1]) + v * (c[1] - a[1]);
    if (y > p[1]) ++count;
  }
  return count;
}

}  // namespace sinew::test
