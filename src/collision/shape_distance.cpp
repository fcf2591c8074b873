// shape_distance.cpp — signed distances of the analytic shapes in double and
// a capsule's deepest point against them (see shape_distance.h). The
// primitives follow kernels/cpu/contact_kernels.cpp; a golden-section
// search minimises the distance along a segment (Kiefer, "Sequential
// minimax search for a maximum", Proc. AMS 4, 1953).
#include "collision/shape_distance.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace sinew::collision {
namespace {

using math::Vec3;

ShapeDistance sphere(double radius, const Vec3& l) {
  const double r = math::norm(l);
  if (r > 0.0) return {r - radius, math::mul(l, 1.0 / r)};
  return {-radius, {0.0, 1.0, 0.0}};
}

ShapeDistance capsule(double radius, double half_height, const Vec3& l) {
  const Vec3 v{l[0], l[1] - std::clamp(l[1], -half_height, half_height), l[2]};
  const double r = math::norm(v);
  if (r > 0.0) return {r - radius, math::mul(v, 1.0 / r)};
  return {-radius, {1.0, 0.0, 0.0}};
}

ShapeDistance box(const std::array<double, 3>& half, const Vec3& l) {
  Vec3 q, out;
  double outside = 0.0;
  int nearest = 0;
  for (int a = 0; a < 3; ++a) {
    q[a] = std::abs(l[a]) - half[a];
    out[a] = std::max(q[a], 0.0) * (l[a] < 0.0 ? -1.0 : 1.0);
    outside += out[a] * out[a];
    if (q[a] > q[nearest]) nearest = a;
  }
  if (outside > 0.0) {
    const double d = std::sqrt(outside);
    return {d, math::mul(out, 1.0 / d)};
  }
  Vec3 n{0.0, 0.0, 0.0};
  n[nearest] = l[nearest] < 0.0 ? -1.0 : 1.0;
  return {q[nearest], n};
}

ShapeDistance cylinder(double radius, double half_height, const Vec3& l) {
  const double r = std::hypot(l[0], l[2]);
  const double dr = r - radius, dy = std::abs(l[1]) - half_height, sy = l[1] < 0.0 ? -1.0 : 1.0;
  const double ux = r > 0.0 ? l[0] / r : 1.0, uz = r > 0.0 ? l[2] / r : 0.0;
  if (dr > 0.0 && dy > 0.0) {
    const double d = std::hypot(dr, dy);
    return {d, {dr * ux / d, dy * sy / d, dr * uz / d}};
  }
  if (dr > dy) return {dr, {ux, 0.0, uz}};
  return {dy, {0.0, sy, 0.0}};
}

ShapeDistance torus(double major, double minor, const Vec3& l) {
  const double r = std::hypot(l[0], l[2]);
  const double ux = r > 0.0 ? l[0] / r : 1.0, uz = r > 0.0 ? l[2] / r : 0.0;
  const double qr = r - major, len = std::hypot(qr, l[1]);
  if (!(len > 0.0)) return {-minor, {0.0, 1.0, 0.0}};
  return {len - minor, {qr * ux / len, l[1] / len, qr * uz / len}};
}

// A shape's distance at a point of its own frame, the normal in that frame.
ShapeDistance local_distance(const ColliderDesc& c, const Vec3& l);

ShapeDistance node_distance(const ImplicitNode& n, const Vec3& p) {
  const Vec3 l = math::rotate(math::conj(n.rotation), math::sub(p, n.position));
  ShapeDistance d;
  switch (n.op) {
    case ImplicitOp::half_space: d = {l[1], {0.0, 1.0, 0.0}}; break;
    case ImplicitOp::sphere: d = sphere(n.radius, l); break;
    case ImplicitOp::capsule: d = capsule(n.radius, n.half_height, l); break;
    case ImplicitOp::box: d = box(n.half_extents, l); break;
    case ImplicitOp::cylinder: d = cylinder(n.radius, n.half_height, l); break;
    case ImplicitOp::torus: d = torus(n.radius, n.minor_radius, l); break;
    default: break;
  }
  return {d.distance - n.rounding, math::rotate(n.rotation, d.normal)};
}

// The postfix CSG of the nodes (checked by scene_checks.cpp), as the kernels evaluate it.
ShapeDistance implicit(const std::vector<ImplicitNode>& nodes, const Vec3& p) {
  std::vector<ShapeDistance> stack;
  for (const ImplicitNode& n : nodes) {
    if (n.op != ImplicitOp::unite && n.op != ImplicitOp::intersect && n.op != ImplicitOp::subtract) {
      stack.push_back(node_distance(n, p));
      continue;
    }
    const ShapeDistance b = stack.back();
    stack.pop_back();
    ShapeDistance& a = stack.back();
    if (n.op == ImplicitOp::unite && b.distance < a.distance) a = b;
    else if (n.op == ImplicitOp::intersect && b.distance > a.distance) a = b;
    else if (n.op == ImplicitOp::subtract && -b.distance > a.distance) a = {-b.distance, math::mul(b.normal, -1.0)};
  }
  return stack.empty() ? ShapeDistance{} : stack.back();
}

ShapeDistance local_distance(const ColliderDesc& c, const Vec3& l) {
  switch (c.shape) {
    case ColliderShape::plane: return {l[1], {0.0, 1.0, 0.0}};
    case ColliderShape::sphere: return sphere(c.radius, l);
    case ColliderShape::capsule: return capsule(c.radius, c.half_height, l);
    case ColliderShape::box: return box(c.half_extents, l);
    case ColliderShape::cylinder: return cylinder(c.radius, c.half_height, l);
    case ColliderShape::implicit: return implicit(c.implicit, l);
    case ColliderShape::level_set: {
      // Its trilinear value and gradient, normalised (zero beyond its bands).
      if (!c.level_set) return {};
      const Vec3 g = c.level_set->gradient(l);
      const double n = math::norm(g);
      return {c.level_set->value(l), n > 0.0 ? math::mul(g, 1.0 / n) : Vec3{0.0, 0.0, 0.0}};
    }
  }
  return {};
}

// Golden-section search for the least of a unimodal `value` on [lo, hi]:
// `steps` shrinkings of the bracket by 0.618, then the bracket's midpoint.
template <class F>
double golden_section(double lo, double hi, int steps, F&& value) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = value(x1), f2 = value(x2);
  for (int k = 0; k < steps; ++k) {
    if (f1 <= f2) hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = value(x1);
    else lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = value(x2);
  }
  return 0.5 * (lo + hi);
}

}  // namespace

ShapeDistance shape_distance(const ColliderDesc& shape, const Vec3& position, const math::Quat& rotation,
                             const Vec3& p) {
  const ShapeDistance d = local_distance(shape, math::rotate(math::conj(rotation), math::sub(p, position)));
  return {d.distance, math::rotate(rotation, d.normal)};
}

CapsuleContact capsule_against(const ColliderDesc& shape, const Vec3& position, const math::Quat& rotation,
                               const Vec3& a, const Vec3& b, double radius) {
  const Vec3 ab = math::sub(b, a);
  auto at = [&](double t) { return math::add(a, math::mul(ab, t)); };
  auto f = [&](double t) { return shape_distance(shape, position, rotation, at(t)).distance; };
  double lo = 0.0, hi = 1.0;
  if (shape.shape == ColliderShape::implicit || shape.shape == ColliderShape::level_set) {
    // not convex: bracket the best of 33 samples
    constexpr int samples = 32;
    int best = 0;
    double best_f = f(0.0);
    for (int k = 1; k <= samples; ++k)
      if (const double v = f(double(k) / samples); v < best_f) best_f = v, best = k;
    lo = std::max(0.0, double(best - 1) / samples);
    hi = std::min(1.0, double(best + 1) / samples);
  }
  // Golden-section search for the least distance on [lo, hi].
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = f(x1), f2 = f(x2);
  while (hi - lo > 1e-12) {
    if (f1 <= f2) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - g * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + g * (hi - lo), f2 = f(x2);
    }
  }
  // The ends too: the least may sit exactly at one (a segment lying on a face).
  double t = 0.5 * (lo + hi);
  for (double end : {0.0, 1.0})
    if (f(end) < f(t)) t = end;
  const Vec3 p = at(t);
  const ShapeDistance d = shape_distance(shape, position, rotation, p);
  return {radius - d.distance, d.normal, math::sub(p, math::mul(d.normal, radius))};
}

bool triangle_against(const ColliderDesc& shape, const Vec3& position, const math::Quat& rotation, const Vec3& a,
                      const Vec3& b, const Vec3& c, double reach, TriangleContact& out) {
  const Vec3 corner[3] = {a, b, c};
  const Vec3 centroid = math::mul(math::add(math::add(a, b), c), 1.0 / 3.0);
  double circumradius = 0.0;
  for (const Vec3& v : corner) circumradius = std::max(circumradius, math::norm(math::sub(v, centroid)));
  const auto at = [&](const std::array<double, 3>& w) {
    return math::add(math::add(math::mul(a, w[0]), math::mul(b, w[1])), math::mul(c, w[2]));
  };
  const auto f = [&](const std::array<double, 3>& w) { return shape_distance(shape, position, rotation, at(w)).distance; };
  if (f({1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0}) > reach + circumradius) return false;
  // Start from the best of seven points.
  const std::array<double, 3> starts[7] = {{1, 0, 0},     {0, 1, 0},     {0, 0, 1},
                                           {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5},
                                           {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0}};
  std::array<double, 3> w = starts[0];
  double best = f(w);
  int best_start = 0;
  for (int k = 1; k < 7; ++k)
    if (const double v = f(starts[k]); v < best) best = v, w = starts[k], best_start = k;
  // Every point of the triangle lies in one of the four smaller triangles
  // the edges' midpoints cut it into, within half the longest edge of that
  // one's corners, all of which are starts; the distance changes no faster than
  // the point moves, so nothing is within reach if the best start is more
  // than that beyond it. (Returning when the best start alone was beyond
  // the reach missed a thin tool pressed into a large triangle's middle.)
  double longest = 0.0;
  for (int k = 0; k < 3; ++k) longest = std::max(longest, math::norm(math::sub(corner[(k + 1) % 3], corner[k])));
  if (best > reach + 0.5 * longest) return false;
  // A corner where the distance grows along both edges is the minimum of
  // a convex distance over the triangle (first-order optimality): most
  // triangles against a shape smoother than they are end here.
  if (best_start < 3) {
    const Vec3 gradient = shape_distance(shape, position, rotation, corner[best_start]).normal;
    bool rises = true;
    for (int k = 0; k < 3; ++k)
      if (k != best_start) rises &= math::dot(gradient, math::sub(corner[k], corner[best_start])) >= 0.0;
    if (rises) {  // the least distance, at a corner
      if (best > reach) return false;
      out.weights = starts[best_start];
      return true;
    }
  }
  // For a convex shape, f(w) + gradient . (corner_s - q) bounds the least
  // distance over the triangle from below (the Frank-Wolfe gap; the
  // distance's gradient is the shape's normal): the largest of these
  // decides most near misses without the nested searches below.
  const bool convex = shape.shape != ColliderShape::implicit;
  double floor = -INFINITY;
  for (int iteration = 0; iteration < 16; ++iteration) {
    const Vec3 q = at(w);
    const Vec3 gradient = shape_distance(shape, position, rotation, q).normal;
    int s = 0;  // the corner the gradient descends to most
    for (int k = 1; k < 3; ++k)
      if (math::dot(gradient, corner[k]) < math::dot(gradient, corner[s])) s = k;
    floor = std::max(floor, best + math::dot(gradient, math::sub(corner[s], q)));
    if (!(math::dot(gradient, math::sub(corner[s], q)) < -1e-12 * circumradius)) break;  // no descent left
    std::array<double, 3> target{0, 0, 0};
    target[s] = 1.0;
    const auto blend = [&](double t) {
      return std::array<double, 3>{w[0] + t * (target[0] - w[0]), w[1] + t * (target[1] - w[1]),
                                   w[2] + t * (target[2] - w[2])};
    };
    const std::array<double, 3> next = blend(golden_section(0.0, 1.0, 24, [&](double t) { return f(blend(t)); }));
    const double v = f(next);
    if (!(v < best)) break;
    best = v, w = next;
  }
  // Frank-Wolfe may stop above the least distance (it zig-zags towards the
  // corners; tests/shape_distance_test.cpp measures how far). Whether the
  // triangle comes within reach is not left to it: when it stopped beyond
  // the reach and its lower bound does not settle it, nested golden-section
  // searches over the barycentric coordinates decide, for a convex shape to
  // within 0.618^28 ~ 1.4e-6 of the triangle's size (the least over s of the
  // least over t of a convex function; each search finds its minimum to
  // that fraction of its range, its ends included). They are not the
  // first choice: among the near-equal minima of a thin capsule lying along
  // a tilted triangle they find the one under its end cap, whose normal
  // slid a coarse membrane off the probe in MeshContact's thin-probe test,
  // where Frank-Wolfe's stays nearer the middle.
  if (best > reach && convex && floor > reach) return false;
  if (best > reach) {
    constexpr int kSteps = 28;
    const auto golden = [&](double lo, double hi, auto&& value, double& at_min) {
      at_min = golden_section(lo, hi, kSteps, value);
      double least = value(at_min);
      for (const double end : {lo, hi})  // a least on an edge or at a corner
        if (const double v = value(end); v < least) least = v, at_min = end;
      return least;
    };
    const auto inner = [&](double s, double& t) {
      return golden(0.0, 1.0 - s, [&](double u) { return f({std::max(0.0, 1.0 - s - u), s, u}); }, t);
    };
    double s_min = 0.0, t_min = 0.0;
    const double nested = golden(0.0, 1.0, [&](double s) { double t = 0.0; return inner(s, t); }, s_min);
    if (!(nested <= reach)) return false;
    (void)inner(s_min, t_min);
    w = {std::max(0.0, 1.0 - s_min - t_min), s_min, t_min};
  }
  const Vec3 q = at(w);
  const ShapeDistance d = shape_distance(shape, position, rotation, q);
  out.weights = w;
  out.distance = d.distance;
  out.normal = d.normal;
  out.surface = math::sub(q, math::mul(d.normal, d.distance));
  return true;
}

}  // namespace sinew::collision
