// topology_queries.cpp — see topology_queries.h.
#include "runtime/topology_queries.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sinew {

namespace {

Point3 sub(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Point3 cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

template <std::size_t N>
std::array<double, 2> project(const std::array<Point3, N>& points, const Point3& axis) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Point3& p : points) {
    const double d = dot(p, axis);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  return {lo, hi};
}

std::array<Point3, 4> corners(const TetMesh& mesh, std::uint32_t t, const BodyPositions& x) {
  const auto& q = mesh.tets[t];
  return {x.at(q[0]), x.at(q[1]), x.at(q[2]), x.at(q[3])};
}

}  // namespace

bool triangle_touches_tet(const std::array<Point3, 3>& tri, const std::array<Point3, 4>& tet) {
  // An axis separates when the two projections do not overlap. A zero axis
  // (parallel edges, a degenerate face) separates nothing and is skipped.
  const auto separates = [&](const Point3& axis) {
    if (dot(axis, axis) <= 0.0) return false;
    const auto a = project(tri, axis), b = project(tet, axis);
    return a[1] < b[0] || b[1] < a[0];
  };
  if (separates(cross(sub(tri[1], tri[0]), sub(tri[2], tri[0])))) return false;
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (const auto& f : kFaces)
    if (separates(cross(sub(tet[f[1]], tet[f[0]]), sub(tet[f[2]], tet[f[0]])))) return false;
  for (int i = 0; i < 3; ++i) {
    const Point3 e = sub(tri[(i + 1) % 3], tri[i]);
    for (const auto& k : kTetEdges)
      if (separates(cross(e, sub(tet[k[1]], tet[k[0]])))) return false;
  }
  return true;
}

std::vector<std::uint32_t> tets_cut(const TetMesh& mesh, std::span<const std::uint8_t> alive, const BodyPositions& x,
                                    const Point3& a0, const Point3& b0, const Point3& a1, const Point3& b1) {
  const std::array<Point3, 3> t0{a0, b0, b1}, t1{a0, b1, a1};
  // The quad's box first: most tets are far from the blade.
  Point3 lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::min({a0[a], b0[a], a1[a], b1[a]});
    hi[a] = std::max({a0[a], b0[a], a1[a], b1[a]});
  }
  std::vector<std::uint32_t> out;
  for (std::uint32_t t = 0; t < mesh.tets.size(); ++t) {
    if (!alive[t]) continue;
    const auto c = corners(mesh, t, x);
    bool apart = false;
    for (int a = 0; a < 3 && !apart; ++a) {
      const double l = std::min({c[0][a], c[1][a], c[2][a], c[3][a]}), h = std::max({c[0][a], c[1][a], c[2][a], c[3][a]});
      apart = h < lo[a] || l > hi[a];
    }
    if (!apart && (triangle_touches_tet(t0, c) || triangle_touches_tet(t1, c))) out.push_back(t);
  }
  return out;
}

std::vector<std::uint32_t> tets_torn(const TetMesh& mesh, std::span<const std::uint8_t> alive, const BodyPositions& x,
                                     double strain) {
  const double limit = (1.0 + strain) * (1.0 + strain);
  std::vector<std::uint32_t> out;
  for (std::uint32_t t = 0; t < mesh.tets.size(); ++t) {
    if (!alive[t]) continue;
    const auto& q = mesh.tets[t];
    for (const auto& e : kTetEdges) {
      const Point3 now = sub(x.at(q[e[1]]), x.at(q[e[0]]));
      const Point3 rest = sub(mesh.vertices[q[e[1]]], mesh.vertices[q[e[0]]]);
      if (dot(now, now) > limit * dot(rest, rest)) {
        out.push_back(t);
        break;
      }
    }
  }
  return out;
}

std::vector<std::uint32_t> segments_torn(const LineBodyDesc& line, std::span<const std::uint8_t> whole,
                                         const BodyPositions& x, double strain) {
  const double limit = (1.0 + strain) * (1.0 + strain);
  std::vector<std::uint32_t> out;
  for (std::uint32_t s = 0; s < line.segments.size(); ++s) {
    if (!whole[s]) continue;
    const auto [a, b] = line.segments[s];
    const Point3 now = sub(x.at(b), x.at(a)), rest = sub(line.vertices[b], line.vertices[a]);
    if (dot(now, now) > limit * dot(rest, rest)) out.push_back(s);
  }
  return out;
}

std::vector<std::uint32_t> tets_burned(const TetMesh& mesh, std::span<const std::uint8_t> alive,
                                       const BodyPositions& x, const Point3& centre, double radius, double seconds,
                                       double dwell, std::vector<double>& heat) {
  std::vector<std::uint32_t> out;
  for (std::uint32_t t = 0; t < mesh.tets.size(); ++t) {
    if (!alive[t]) continue;
    const auto c = corners(mesh, t, x);
    Point3 m{};
    for (const Point3& p : c)
      for (int a = 0; a < 3; ++a) m[a] += 0.25 * p[a];
    const Point3 d = sub(m, centre);
    if (dot(d, d) > radius * radius) continue;
    heat[t] += seconds;
    if (heat[t] >= dwell) out.push_back(t);
  }
  return out;
}

}  // namespace sinew
