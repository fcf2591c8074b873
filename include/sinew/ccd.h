// sinew/ccd.h — continuous collision detection of two primitives moving
// linearly within a step (docs/collision.md): a vertex against a triangle, an edge
// against an edge. Never a false negative: when the primitives touch (come
// within the minimum separation) at some time of the step, the query says
// so, and the time it returns is never later than the first touch.
//
// Method: an inclusion-based root finder (Wang, Ferguson, Schneider, Jiang,
// Attene, Panozzo, "A Large Scale Benchmark and an Inclusion-Based
// Algorithm for Continuous Collision Detection", ACM TOG 40(5), 2021). The
// primitives touch when F(t, u, v) = 0 for some time t in [0, 1] and
// parameters (u, v) on the primitives, F being the vector between the two
// points the parameters name. F is affine in each of t, u and v, so over a
// box of parameters every coordinate of F takes its extremes at the box's
// eight corners: the corners' values bound it exactly, and so do they bound
// n . F along any fixed direction n (sinew tests the primitives' normals
// and, in their plane, the normals of their edges, which separate near
// misses the axes alone separate only in tiny boxes). A box whose bound
// excludes 0 on an axis or a direction (widened by the minimum separation
// and by a certified bound of the double-precision rounding, see below)
// holds no root and is dropped; the others are split, depth first and
// earlier times first, until they are narrower than the tolerance or a
// corner of them at the box's start time is within the tolerance of
// touching; the search goes on below the earliest such box's start, which
// is the time returned.
//
// Guarantee and its assumptions:
//  - inputs are finite doubles with |coordinate| <= 1e100 (checked; larger
//    ones could overflow the products), and the motion is linear in t;
//  - every corner value is computed in a fixed order whose rounding error is
//    at most 64 eps M_k on axis k (eps = 2^-53, M_k the largest |coordinate
//    k| over the eight input points), 84 eps sum_k |n_k| M_k along a
//    direction n (derivations in src/ccd/inclusion_ccd.cpp), and a box is
//    dropped only when its corners' values exceed that bound plus the
//    minimum separation (times |n|_1 along n): so a box holding a touching
//    point is never dropped, whatever the rounding;
//  - the parameters of box corners are dyadic fractions of at most 31 bits,
//    exact in double;
//  - "touch within the minimum separation d" means a pair of points, one
//    on each primitive, with every coordinate of their difference within d
//    (so any pair closer than d in Euclidean distance counts; pairs up to
//    sqrt(3) d apart may count too).
// False positives: a query may report a touch for primitives that come
// within about `tolerance` of each other (the boxes it stops splitting at)
// without touching, or when it gives up after `max_boxes` boxes (reported
// as a touch at the earliest time still open, never as a miss).
#pragma once

#include <array>
#include <cstdint>

#include "sinew/result.h"

namespace sinew::ccd {

using Point = std::array<double, 3>;  ///< [m]

/// How a query decides (vertex_face, edge_edge).
struct Settings {
  /// Distance the primitives may keep and still count as touching [m], >= 0.
  double min_separation = 0.0;
  /// Boxes are split until moving across one changes the primitives'
  /// points by at most about this much [m] (> 0): the resolution of the
  /// answer, and how near a miss may be reported as a touch. A box side
  /// never goes below 2^-31 of the step (its corners stay exact): with more
  /// than 2^31 tolerances of motion in a step the resolution is coarser.
  double tolerance = 1e-6;
  /// The most boxes one query examines (> 0); past it the query reports a
  /// touch at the earliest time still open (conservative, counted as
  /// Hit::gave_up).
  std::uint32_t max_boxes = 1u << 20;
};

/// A query's answer.
struct Hit {
  bool touch = false;  ///< the primitives come within min_separation in [0, 1]
  /// A time no later than the first touch, in [0, 1] (1 when no touch).
  double time = 1.0;
  /// Parameters on the primitives near the touch (the lower corner of the
  /// earliest box found): vertex-face, the face point a + u (b - a) + v
  /// (c - a); edge-edge, a0 + u (a1 - a0) and b0 + v (b1 - b0).
  double u = 0.0;  ///< see above
  double v = 0.0;  ///< see above
  bool gave_up = false;      ///< max_boxes reached: a touch reported without proof
  std::uint32_t boxes = 0;   ///< boxes examined
};

/// Vertex p against triangle (a, b, c), each moving linearly from its
/// position at the step's start (index 0) to its end (index 1).
/// Errors (bad_parameter): a non-finite or too large coordinate, a bad
/// setting, each named.
Result<Hit> vertex_face(const std::array<Point, 2>& p, const std::array<Point, 2>& a, const std::array<Point, 2>& b,
                        const std::array<Point, 2>& c, const Settings& settings = {});

/// Edge (a0, a1) against edge (b0, b1), each end moving linearly from
/// index 0 to index 1. Errors as vertex_face.
Result<Hit> edge_edge(const std::array<Point, 2>& a0, const std::array<Point, 2>& a1, const std::array<Point, 2>& b0,
                      const std::array<Point, 2>& b1, const Settings& settings = {});

}  // namespace sinew::ccd
