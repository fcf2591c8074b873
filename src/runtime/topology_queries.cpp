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

std::array<double, 2> project(std::span<const Point3> points, const Point3& axis) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Point3& p : points) {
    const double d = dot(p, axis);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  return {lo, hi};
}

// An element's corners at the current positions (up to 4).
struct Corners {
  std::array<Point3, 4> p;
  std::uint32_t n = 0;
  [[nodiscard]] std::span<const Point3> span() const { return {p.data(), n}; }
};
Corners corners(const ElementView& body, std::uint32_t e, const BodyPositions& x) {
  Corners c;
  c.n = body.arity;
  for (std::uint32_t k = 0; k < body.arity; ++k) c.p[k] = x.at(body.of(e)[k]);
  return c;
}

}  // namespace

bool triangle_touches_element(const std::array<Point3, 3>& tri, std::span<const Point3> element) {
  // An axis separates when the two projections do not overlap. A zero axis
  // (parallel edges, a degenerate face) separates nothing and is skipped.
  const auto separates = [&](const Point3& axis) {
    if (dot(axis, axis) <= 0.0) return false;
    const auto a = project(tri, axis), b = project(element, axis);
    return a[1] < b[0] || b[1] < a[0];
  };
  const auto edge = [](std::span<const Point3> q, const int e[2]) { return sub(q[e[1]], q[e[0]]); };
  const std::uint32_t arity = static_cast<std::uint32_t>(element.size());
  // The faces' normals.
  const Point3 n = cross(sub(tri[1], tri[0]), sub(tri[2], tri[0]));
  if (separates(n)) return false;
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  const std::span<const int[3]> faces = arity == 4 ? std::span<const int[3]>(kFaces) : std::span<const int[3]>(&kFaces[3], 1);
  for (const auto& f : faces)
    if (separates(cross(sub(element[f[1]], element[f[0]]), sub(element[f[2]], element[f[0]])))) return false;
  // The edges' cross products.
  for (const auto& i : kTriangleEdges)
    for (const auto& k : element_edges(arity))
      if (separates(cross(edge(tri, i), edge(element, k)))) return false;
  // The flat sets' in-plane edge normals.
  for (const auto& i : kTriangleEdges)
    if (separates(cross(n, edge(tri, i)))) return false;
  if (arity == 3) {
    const Point3 m = cross(sub(element[1], element[0]), sub(element[2], element[0]));
    for (const auto& k : kTriangleEdges)
      if (separates(cross(m, edge(element, k)))) return false;
  }
  return true;
}

namespace {

// Per vertex of the body, its outcode against the box [lo, hi] (Cohen and
// Sutherland's clipping codes): a bit for each side of the box it lies
// beyond. An element whose corners all share a bit lies wholly beyond that
// side, so it misses the box. Why: testing an element's corners costs four
// random reads into the positions (an organ in the mesher's order misses
// the cache on most), where its corners' codes are four bytes that a body
// of 10^4-10^5 vertices keeps in the first-level cache: on kidney_57k the
// cut query went from 0.9-1.3 ms to 0.27-0.29 ms.
std::vector<std::uint8_t> outcodes(const ElementView& body, const BodyPositions& x, const Point3& lo, const Point3& hi) {
  std::vector<std::uint8_t> code(body.rest.size());
  for (std::uint32_t v = 0; v < code.size(); ++v) {
    const Point3 p = x.at(v);
    std::uint8_t c = 0;
    for (int a = 0; a < 3; ++a) c |= std::uint8_t((p[a] < lo[a] ? 1u : 0u) << (2 * a)) | std::uint8_t((p[a] > hi[a] ? 2u : 0u) << (2 * a));
    code[v] = c;
  }
  return code;
}

// Whether element e lies wholly beyond one side of the box its `code`s were made for.
bool beyond(const ElementView& body, const std::vector<std::uint8_t>& code, std::uint32_t e) {
  std::uint8_t all = 0x3f;
  for (std::uint32_t k = 0; k < body.arity; ++k) all &= code[body.of(e)[k]];
  return all != 0;
}

}  // namespace

std::vector<std::uint32_t> elements_cut(const ElementView& body, const BodyPositions& x, const Point3& a0,
                                        const Point3& b0, const Point3& a1, const Point3& b1) {
  const std::array<Point3, 3> t0{a0, b0, b1}, t1{a0, b1, a1};
  // The quad's box first: most elements are far from the blade.
  Point3 lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::min({a0[a], b0[a], a1[a], b1[a]});
    hi[a] = std::max({a0[a], b0[a], a1[a], b1[a]});
  }
  const std::vector<std::uint8_t> code = outcodes(body, x, lo, hi);
  std::vector<std::uint32_t> out;
  for (std::uint32_t e = 0; e < body.size(); ++e) {
    if (!body.alive[e] || beyond(body, code, e)) continue;
    const Corners c = corners(body, e, x);
    if (triangle_touches_element(t0, c.span()) || triangle_touches_element(t1, c.span())) out.push_back(e);
  }
  return out;
}

EdgeList unique_edges(const ElementView& body) {
  std::vector<std::array<std::uint32_t, 2>> edges;
  for (std::uint32_t e = 0; e < body.size(); ++e)
    for (const auto& k : element_edges(body.arity)) {
      const std::uint32_t u = body.of(e)[k[0]], v = body.of(e)[k[1]];
      edges.push_back({std::min(u, v), std::max(u, v)});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  EdgeList out;
  out.edges = std::move(edges);
  for (const auto& [u, v] : out.edges) {
    const Point3 rest = sub(body.rest[v], body.rest[u]);
    out.rest2.push_back(dot(rest, rest));
  }
  return out;
}

std::vector<std::uint32_t> elements_torn(const ElementView& body, const EdgeList& edges, const BodyPositions& x,
                                         double strain) {
  const double limit = (1.0 + strain) * (1.0 + strain);
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < edges.edges.size(); ++i) {
    const auto [u, v] = edges.edges[i];
    const Point3 now = sub(x.at(v), x.at(u));
    if (!(dot(now, now) > limit * edges.rest2[i])) continue;
    for (std::uint32_t k = body.around_first[u]; k < body.around_first[u + 1]; ++k) {
      const std::uint32_t e = body.around[k];
      const std::uint32_t* q = body.of(e);
      if (body.alive[e] && std::find(q, q + body.arity, v) != q + body.arity) out.push_back(e);
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
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

std::vector<std::uint32_t> elements_burned(const ElementView& body, const BodyPositions& x, const Point3& centre,
                                           double radius, double seconds, double dwell, std::vector<double>& heat) {
  // The ball's box first: an element whose corners all lie beyond one side
  // of it has its centroid there too, outside the ball.
  const Point3 lo{centre[0] - radius, centre[1] - radius, centre[2] - radius};
  const Point3 hi{centre[0] + radius, centre[1] + radius, centre[2] + radius};
  const std::vector<std::uint8_t> code = outcodes(body, x, lo, hi);
  std::vector<std::uint32_t> out;
  for (std::uint32_t e = 0; e < body.size(); ++e) {
    if (!body.alive[e] || beyond(body, code, e)) continue;
    const Corners c = corners(body, e, x);
    Point3 m{};
    for (std::uint32_t k = 0; k < c.n; ++k)
      for (int a = 0; a < 3; ++a) m[a] += c.p[k][a] / c.n;
    const Point3 d = sub(m, centre);
    if (dot(d, d) > radius * radius) continue;
    heat[e] += seconds;
    if (heat[e] >= dwell) out.push_back(e);
  }
  return out;
}

}  // namespace sinew
