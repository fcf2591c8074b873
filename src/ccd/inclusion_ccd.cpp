// inclusion_ccd.cpp — continuous collision detection by an inclusion-based
// root finder (sinew/ccd.h; Wang, Ferguson, Schneider, Jiang, Attene,
// Panozzo, "A Large Scale Benchmark and an Inclusion-Based Algorithm for
// Continuous Collision Detection", ACM TOG 40(5), 2021), written from the
// paper's idea with its own error bound (below).
//
// The function. Every point moves as x(t) = x0 + t (x1 - x0). Vertex-face:
//   F(t, u, v) = [p(t) - a(t)] - u [b(t) - a(t)] - v [c(t) - a(t)],
// u, v >= 0, u + v <= 1; edge-edge:
//   F(t, u, v) = [a0(t) - b0(t)] + u [a1(t) - a0(t)] - v [b1(t) - b0(t)],
// u, v in [0, 1]. Each coordinate of F is affine in t, in u and in v
// separately, so its extremes over a box of (t, u, v) are among the box's
// eight corners. Vertex-face boxes may reach past u + v = 1 (a superset:
// never a miss); a box wholly past it is dropped.
//
// The rounding bound (eps = 2^-53, M = the largest |coordinate| on the axis
// over the eight input points, t, u, v in [0, 1] exact):
//  - x(t) = fl(x0 + fl(t fl(x1 - x0))) is within 7.01 eps M of the exact
//    value, whose magnitude is <= M (a convex combination);
//  - a difference of two of them (q = p - a, e = b - a; or a0 - b0, a1 - a0,
//    b1 - b0) is within 2 x 7.01 + 2 (its own rounding of a value <= 2M)
//    = 16.02 eps M, and <= 2M (1 + 9 eps);
//  - fl(u e) adds its own rounding of a value <= 2M: 16.02 + 2 = 18.02;
//    w = fl(q - u e), |w| <= 4M, adds 4 eps M: 16.02 + 18.02 + 4 = 38.04;
//    fl(w - v e'), a value <= 6M, adds 18.02 + 6: 62.06 eps M.
// So every corner value is within 64 eps M of the exact one (64 with room
// for the second-order terms), on its axis, and |F_k| <= 6 M_k (1 + small).
// (A review measured the actual worst case against exact arithmetic: 8.5
// eps M; the bound is loose, not tight.) Fused multiply-adds only remove
// roundings, so the bound holds with or without -ffp-contract=off. A box is dropped only when on
// some axis all eight corner values exceed min_separation + 64 eps M (the
// sum itself rounded up), or all are below minus that: then the exact F is
// beyond min_separation there on the whole box. Underflow (values below
// 2^-1022) could add absolute errors of 2^-1074 per operation; 1e-300 more
// covers them.
#include "sinew/ccd.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace sinew::ccd {
namespace {

constexpr double kEps = 1.1102230246251565e-16;  // 2^-53
constexpr double kLargest = 1e100;               // |coordinate| allowed (no overflow in any product)
constexpr double kFinestWidth = 1.0 / (1u << 31);  // the narrowest box side: 31-bit dyadic corners stay exact

struct Box {
  double t0, t1, u0, u1, v0, v1;
};

// The eight input points (start, end) and what every box reuses.
struct Query {
  bool vertex_face = true;
  double x0[4][3], d[4][3];  // point i at t = 0, and fl(x1 - x0)
  double threshold[3];       // per axis: min_separation + 64 eps M, rounded up
  double close[3];           // per axis: threshold + tolerance (a box within it is a touch at that resolution)
  double tol[3];             // per dimension (t, u, v): the widest box side that is fine enough
  // More directions to separate along (see include() and solve()), and
  // their thresholds.
  static constexpr int kMaxDirections = 5;
  int directions = 0;
  double normal[kMaxDirections][3];
  double normal_threshold[kMaxDirections];
};

enum class Inclusion {
  apart,       // on some axis F stays beyond the threshold over the whole box: no touch in it
  maybe,       // F may reach 0 in it
  close_late,  // maybe, and F comes within the threshold plus the tolerance at a corner at box.t1
  close,       // F comes within the threshold plus the tolerance on every axis at a corner at box.t0
};

// Where F over `box` lies against the threshold: its eight corner values
// per axis bound it (affine in each parameter).
Inclusion include(const Query& q, const Box& box) {
  double f[2][2][2][3];  // [t][u][v][axis]
  const double ts[2] = {box.t0, box.t1}, us[2] = {box.u0, box.u1}, vs[2] = {box.v0, box.v1};
  // Axis by axis, each tested as soon as its eight values are known: most
  // boxes are dropped by the first axis that separates them.
  for (int k = 0; k < 3; ++k) {
    double lo = INFINITY, hi = -INFINITY;
    for (int it = 0; it < 2; ++it) {
      double x[4];
      for (int i = 0; i < 4; ++i) x[i] = q.x0[i][k] + ts[it] * q.d[i][k];
      // vertex-face: points p, a, b, c; edge-edge: a0, a1, b0, b1.
      double base, e1, e2;
      if (q.vertex_face) {
        base = x[0] - x[1];
        e1 = x[2] - x[1];
        e2 = x[3] - x[1];
      } else {
        base = x[0] - x[2];
        e1 = -(x[1] - x[0]);  // F = base + u (a1 - a0) - v (b1 - b0) = (base - u e1) - v e2; negation is exact
        e2 = x[3] - x[2];
      }
      for (int iu = 0; iu < 2; ++iu) {
        const double w = base - us[iu] * e1;
        for (int iv = 0; iv < 2; ++iv) {
          const double value = w - vs[iv] * e2;
          f[it][iu][iv][k] = value;
          lo = std::min(lo, value);
          hi = std::max(hi, value);
        }
      }
    }
    if (lo > q.threshold[k] || hi < -q.threshold[k]) return Inclusion::apart;
  }
  // Along a fixed direction n, n . F is affine in each parameter too, so its
  // corner values bound it as well: a box whose corners all lie beyond the
  // direction's threshold on one side holds no touch (|n . F| <= |n|_1
  // max_k |F_k|). The normals separate near misses across a face or
  // between crossing edges that the axes alone separate only in small boxes.
  for (int d = 0; d < q.directions; ++d) {
    const double* n = q.normal[d];
    double g_lo = INFINITY, g_hi = -INFINITY;
    for (int it = 0; it < 2; ++it)
      for (int iu = 0; iu < 2; ++iu)
        for (int iv = 0; iv < 2; ++iv) {
          const double* value = f[it][iu][iv];
          const double g = n[0] * value[0] + n[1] * value[1] + n[2] * value[2];
          g_lo = std::min(g_lo, g);
          g_hi = std::max(g_hi, g);
        }
    if (g_lo > q.normal_threshold[d] || g_hi < -q.normal_threshold[d]) return Inclusion::apart;
  }
  // A corner at the box's start time where the primitives' points are within
  // the tolerance (and the separation) on every axis: a touch at the
  // resolution asked for, at box.t0 (the time returned). Corners at box.t1
  // do not count: a box wide in time, close only at its end, would return a
  // time far before the touch (found in review: a vertex reaching a
  // triangle's corner at t = 1 came back at t = 0). For vertex-face, only
  // corners on the face (u + v <= 1) count.
  // A close corner at box.t1 says a touch lies within the box's time: the
  // box is then split in time first (the search narrows onto it).
  bool late = false;
  for (int it = 0; it < 2; ++it)
    for (int iu = 0; iu < 2; ++iu)
      for (int iv = 0; iv < 2; ++iv) {
        if (q.vertex_face && us[iu] + vs[iv] > 1.0) continue;
        const double* value = f[it][iu][iv];
        if (std::abs(value[0]) <= q.close[0] && std::abs(value[1]) <= q.close[1] && std::abs(value[2]) <= q.close[2]) {
          if (it == 0) return Inclusion::close;
          late = true;
        }
      }
  return late ? Inclusion::close_late : Inclusion::maybe;
}

Result<Hit> solve(Query& q, const double (&start)[4][3], const double (&end)[4][3], const Settings& s) {
  if (!(s.min_separation >= 0.0) || !std::isfinite(s.min_separation))
    return Error(ErrorCode::bad_parameter,
                 "ccd: the minimum separation must be finite and >= 0 [m] (got " + std::to_string(s.min_separation) + ")");
  if (!(s.tolerance > 0.0) || !std::isfinite(s.tolerance))
    return Error(ErrorCode::bad_parameter,
                 "ccd: the tolerance must be finite and > 0 [m] (got " + std::to_string(s.tolerance) + ")");
  if (s.max_boxes == 0) return Error(ErrorCode::bad_parameter, "ccd: max_boxes must be > 0");
  double m[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k)
      for (const double x : {start[i][k], end[i][k]}) {
        if (!std::isfinite(x) || std::abs(x) > kLargest)
          return Error(ErrorCode::bad_parameter, "ccd: point " + std::to_string(i) + " has coordinate " +
                                                     std::to_string(x) + ": it must be finite and within 1e100");
        m[k] = std::max(m[k], std::abs(x));
      }
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) q.x0[i][k] = start[i][k], q.d[i][k] = end[i][k] - start[i][k];
  for (int k = 0; k < 3; ++k)
    q.threshold[k] = (s.min_separation + (64.0 * kEps * m[k] + 1e-300)) * (1.0 + 4.0 * kEps);
  for (int k = 0; k < 3; ++k) q.close[k] = q.threshold[k] + s.tolerance;
  // Directions to separate along: the primitives' normals at the start and
  // the end (the face's (b - a) x (c - a), or the edges' (a1 - a0) x
  // (b1 - b0)), and in the plane of the mid-step normal, the normals of the
  // face's three edges (a vertex passing beside the face) or of the two
  // edges (edges in one plane, whose common normal separates nothing). Any
  // vectors would be sound; these separate most near misses. Threshold: a
  // touch has every |F_k| <= min_separation, so |n . F| <= min_separation
  // |n|_1; plus the corner values' error, sum |n_k| 64 eps M_k, and the dot
  // product's own rounding, 3 eps sum |n_k| |F_k| with |F_k| <= 6.1 M_k
  // (6 M_k, the header's bound, plus rounding): 84 eps sum |n_k| M_k in all,
  // rounded up.
  const auto cross = [](const double* a, const double* b, double* out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  };
  const auto add_direction = [&](const double* n) {
    const double scale = std::max({std::abs(n[0]), std::abs(n[1]), std::abs(n[2])});
    if (!(scale > 0.0) || !std::isfinite(scale)) return;  // no direction
    double* stored = q.normal[q.directions];
    double norm1 = 0.0, weighted = 0.0;
    for (int k = 0; k < 3; ++k) {
      stored[k] = n[k] / scale;  // |n|_inf = 1: no overflow in n . F
      norm1 += std::abs(stored[k]), weighted += std::abs(stored[k]) * m[k];
    }
    q.normal_threshold[q.directions] =
        (s.min_separation * norm1 + (84.0 * kEps * weighted + 1e-300)) * (1.0 + 8.0 * kEps);
    ++q.directions;
  };
  q.directions = 0;
  const int e1_from = q.vertex_face ? 1 : 0, e1_to = q.vertex_face ? 2 : 1;
  const int e2_from = q.vertex_face ? 1 : 2, e2_to = 3;
  double middle[4][3];
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) middle[i][k] = 0.5 * start[i][k] + 0.5 * end[i][k];
  for (const auto* x : {&start, &end}) {
    double e1[3], e2[3], n[3];
    for (int k = 0; k < 3; ++k) e1[k] = (*x)[e1_to][k] - (*x)[e1_from][k], e2[k] = (*x)[e2_to][k] - (*x)[e2_from][k];
    cross(e1, e2, n);
    add_direction(n);
  }
  double e1[3], e2[3], plane[3];
  for (int k = 0; k < 3; ++k) e1[k] = middle[e1_to][k] - middle[e1_from][k], e2[k] = middle[e2_to][k] - middle[e2_from][k];
  cross(e1, e2, plane);
  if (q.vertex_face) {
    double e3[3], n[3];
    for (int k = 0; k < 3; ++k) e3[k] = middle[3][k] - middle[2][k];  // c - b
    for (const double* e : {e1, e2, e3}) {
      cross(plane, e, n);
      add_direction(n);
    }
  } else {
    double n[3];
    for (const double* e : {e1, e2}) {
      cross(plane, e, n);
      add_direction(n);
    }
  }
  // How far the points move per unit of each parameter (the box sizes that
  // keep F within about the tolerance): time, the largest displacement;
  // u and v, the longest extent of the edge they run along.
  double speed = 0.0, along_u = 0.0, along_v = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) speed = std::max(speed, std::abs(q.d[i][k]));
  const int u_from = q.vertex_face ? 1 : 0, u_to = q.vertex_face ? 2 : 1;
  const int v_from = q.vertex_face ? 1 : 2, v_to = 3;
  for (const auto* x : {&start, &end})
    for (int k = 0; k < 3; ++k) {
      along_u = std::max(along_u, std::abs((*x)[u_to][k] - (*x)[u_from][k]));
      along_v = std::max(along_v, std::abs((*x)[v_to][k] - (*x)[v_from][k]));
    }
  const double scale[3] = {speed, along_u, along_v};
  for (int d = 0; d < 3; ++d) q.tol[d] = scale[d] > 0.0 ? std::max(kFinestWidth, std::min(1.0, s.tolerance / scale[d])) : 1.0;

  // Depth first, the earlier half of a box split in time first, keeping
  // `earliest`: the start of the earliest box found close or fine enough.
  // A box that starts at or after it is skipped (what it holds cannot come
  // first); the search goes on until no box is open, so every touch before
  // `earliest` has been looked for, and the time returned is never later
  // than the first touch (a box holding one is never dropped nor skipped
  // before a box at or before it is found). Depth first, two parallel edges
  // that overlap along their length and pass through each other end after a
  // few hundred boxes; taking the earliest box first from a heap instead,
  // they took 10^6 (every box along the line of touching parameters, all
  // starting at one coarse time, was split before any was refined in time).
  Hit hit;
  double earliest = INFINITY;
  thread_local std::vector<Box> open;  // storage each thread keeps: a query allocates nothing once warm
  open.clear();
  open.push_back({0.0, 1.0, 0.0, 1.0, 0.0, 1.0});
  while (!open.empty()) {
    const Box box = open.back();
    open.pop_back();
    if (box.t0 >= earliest) continue;
    if (hit.boxes == s.max_boxes) {  // no proof either way: a touch, no later than any box still open
      double first = std::min(earliest, box.t0);
      for (const Box& b : open) first = std::min(first, b.t0);
      if (!hit.touch) hit.u = box.u0, hit.v = box.v0;
      hit.touch = true, hit.gave_up = true, hit.time = first;
      return hit;
    }
    ++hit.boxes;
    const Inclusion inclusion = include(q, box);
    if (inclusion == Inclusion::apart) continue;
    const double width[3] = {box.t1 - box.t0, box.u1 - box.u0, box.v1 - box.v0};
    // The side widest against its tolerance; but once a touch is known, a
    // box reaching past it is split in time first: its later part is then
    // skipped, its earlier part mostly dropped, instead of splitting it
    // along the primitives into boxes that each need that. (Splitting by
    // width alone, two parallel edges that overlap along their length and
    // pass through each other took 10^6 boxes: every box along the line of
    // touching parameters was split across the primitives before in time.)
    int split = -1;
    if ((box.t1 > earliest || inclusion == Inclusion::close_late) && width[0] > q.tol[0]) {
      split = 0;
    } else {
      double widest = 1.0;
      for (int d = 0; d < 3; ++d)
        if (width[d] > q.tol[d] && width[d] / q.tol[d] > widest) widest = width[d] / q.tol[d], split = d;
    }
    if (split < 0 || inclusion == Inclusion::close) {  // a touch at this resolution, from box.t0 on
      earliest = box.t0;
      hit.touch = true, hit.time = box.t0, hit.u = box.u0, hit.v = box.v0;
      continue;
    }
    Box low = box, high = box;
    double* lo_hi[3][2] = {{&low.t1, &high.t0}, {&low.u1, &high.u0}, {&low.v1, &high.v0}};
    const double lo_end[3] = {box.t0, box.u0, box.v0}, hi_end[3] = {box.t1, box.u1, box.v1};
    const double mid = 0.5 * (lo_end[split] + hi_end[split]);  // exact: dyadic corners of at most 31 bits
    *lo_hi[split][0] = mid;
    *lo_hi[split][1] = mid;
    // The later half first onto the stack, so the earlier one is searched first.
    for (const Box& half : {high, low})
      if (!q.vertex_face || half.u0 + half.v0 <= 1.0) open.push_back(half);  // wholly past u + v = 1: off the face
  }
  return hit;
}

}  // namespace

Result<Hit> vertex_face(const std::array<Point, 2>& p, const std::array<Point, 2>& a, const std::array<Point, 2>& b,
                        const std::array<Point, 2>& c, const Settings& settings) {
  Query q;
  q.vertex_face = true;
  const double start[4][3] = {{p[0][0], p[0][1], p[0][2]}, {a[0][0], a[0][1], a[0][2]}, {b[0][0], b[0][1], b[0][2]},
                              {c[0][0], c[0][1], c[0][2]}};
  const double end[4][3] = {{p[1][0], p[1][1], p[1][2]}, {a[1][0], a[1][1], a[1][2]}, {b[1][0], b[1][1], b[1][2]},
                            {c[1][0], c[1][1], c[1][2]}};
  return solve(q, start, end, settings);
}

Result<Hit> edge_edge(const std::array<Point, 2>& a0, const std::array<Point, 2>& a1, const std::array<Point, 2>& b0,
                      const std::array<Point, 2>& b1, const Settings& settings) {
  Query q;
  q.vertex_face = false;
  const double start[4][3] = {{a0[0][0], a0[0][1], a0[0][2]}, {a1[0][0], a1[0][1], a1[0][2]},
                              {b0[0][0], b0[0][1], b0[0][2]}, {b1[0][0], b1[0][1], b1[0][2]}};
  const double end[4][3] = {{a0[1][0], a0[1][1], a0[1][2]}, {a1[1][0], a1[1][1], a1[1][2]},
                            {b0[1][0], b0[1][1], b0[1][2]}, {b1[1][0], b1[1][1], b1[1][2]}};
  return solve(q, start, end, settings);
}

}  // namespace sinew::ccd
