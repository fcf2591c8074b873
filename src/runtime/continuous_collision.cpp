// continuous_collision.cpp — the threads' continuous collision detection in
// the solver (continuous_collision.h; issue 13, part 3).
#include "runtime/continuous_collision.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <string>

#include "math/proximity_math.h"
#include "runtime/suture_exemption.h"
#include "sinew/ccd.h"

namespace sinew {
namespace {

using collision::Contact;
using ccd::Point;
using Motion = std::array<Point, 2>;  // a particle at the substep's start and end

Motion motion_of(std::span<const float> start, std::span<const float> end, std::uint32_t p) {
  const std::size_t at = std::size_t{p} * 4;
  return {Point{start[at], start[at + 1], start[at + 2]}, Point{end[at], end[at + 1], end[at + 2]}};
}

Point lerp(const Motion& m, double t) {
  return {m[0][0] + t * (m[1][0] - m[0][0]), m[0][1] + t * (m[1][1] - m[0][1]), m[0][2] + t * (m[1][2] - m[0][2])};
}
Point sub(const Point& a, const Point& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Point cross(const Point& a, const Point& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Point& a, const Point& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
kernels::double4 at(const Motion& m, double t) {
  const Point p = lerp(m, t);
  return {p[0], p[1], p[2], 0.0};
}

// The point of weights w on up to three motions at time t: sum_k w_k x_k(t).
Point weighted(std::span<const Motion> m, std::span<const double> w, double t) {
  Point p{0.0, 0.0, 0.0};
  for (std::size_t k = 0; k < m.size(); ++k) {
    const Point x = lerp(m[k], t);
    for (int a = 0; a < 3; ++a) p[a] += w[k] * x[a];
  }
  return p;
}

// The contact normal (continuous_collision.h): `plane`, the normal of the
// plane the primitives meet in, turned towards the first primitive's side
// at the start (`apart`, first point minus second). When they start closer
// to that plane than kSameSide, the side is the one the first moved away
// from (`moved`, the first point's displacement over the substep minus the
// second's). When neither tells a side (motion within the plane, or no
// plane), the normal is `apart`'s direction, else -`moved`'s.
constexpr double kSameSide = 1e-9;  // [m], below a float coordinate's resolution at 10 cm
std::array<float, 3> contact_normal(Point plane, const Point& apart, const Point& moved) {
  const double plane_length = std::sqrt(dot(plane, plane));
  const double apart_length = std::sqrt(dot(apart, apart));
  Point n{0.0, 0.0, 0.0};
  if (plane_length > 0.0) {
    const double side = dot(plane, apart) / plane_length;   // [m]
    const double went = dot(plane, moved) / plane_length;   // [m]
    const double sign = std::abs(side) > std::max(1e-6 * apart_length, kSameSide) ? side
                        : std::abs(went) > std::max(1e-6 * std::sqrt(dot(moved, moved)), kSameSide) ? -went
                                                                                                        : 0.0;
    if (sign != 0.0) n = sign > 0.0 ? plane : Point{-plane[0], -plane[1], -plane[2]};
  }
  if (dot(n, n) == 0.0) n = apart_length > 0.0 ? apart : Point{-moved[0], -moved[1], -moved[2]};
  double length = std::sqrt(dot(n, n));
  if (!(length > 0.0)) {  // touching at the start, not moving apart, no plane: any direction
    n = {0.0, 1.0, 0.0};
    length = 1.0;
  }
  return {static_cast<float>(n[0] / length), static_cast<float>(n[1] / length), static_cast<float>(n[2] / length)};
}

// Whether any of the particles moved in the substep (bitwise).
bool moves(std::span<const float> start, std::span<const float> end, std::span<const std::uint32_t> particles) {
  for (std::uint32_t p : particles)
    for (int a = 0; a < 3; ++a)
      if (start[std::size_t{p} * 4 + a] != end[std::size_t{p} * 4 + a]) return true;
  return false;
}

Status check_query(const Result<ccd::Hit>& hit) {
  if (hit) return {};
  return Error(ErrorCode::bad_parameter, "continuous collision: " + hit.error().message());
}

}  // namespace

ContinuousSearch::ContinuousSearch(std::vector<std::uint32_t> segments, std::vector<std::uint32_t> triangles)
    : segments_(std::move(segments)), triangles_(std::move(triangles)) {
  triangle_vertices_ = triangles_;
  std::sort(triangle_vertices_.begin(), triangle_vertices_.end());
  triangle_vertices_.erase(std::unique(triangle_vertices_.begin(), triangle_vertices_.end()), triangle_vertices_.end());
}

void ContinuousSearch::set_reference(std::span<const float> positions) {
  reference_.assign(positions.begin(), positions.end());
  if (!triangles_.empty()) fit(reference_, reference_, triangles_, 3, triangle_tree_);
}

double ContinuousSearch::drift(std::span<const float> start, std::span<const float> end) const {
  float farthest = 0.0f;
  for (std::uint32_t p : triangle_vertices_)
    for (int a = 0; a < 3; ++a) {
      const std::size_t at = std::size_t{p} * 4 + a;
      farthest = std::max({farthest, std::abs(start[at] - reference_[at]), std::abs(end[at] - reference_[at])});
    }
  // The float differences are exact up to half an ulp of the coordinates: a
  // relative 2^-23 of the largest one covers it.
  return double(farthest) * (1.0 + 1e-6) + 1e-9;
}

namespace {

// `boxes` grown by d [m] on every side, rounded outwards to float.
void grow(std::vector<collision::Aabb>& boxes, double d) {
  for (collision::Aabb& b : boxes)
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = std::nextafter(static_cast<float>(double(b.lo[a]) - d), -INFINITY);
      b.hi[a] = std::nextafter(static_cast<float>(double(b.hi[a]) + d), INFINITY);
    }
}

}  // namespace

void ContinuousSearch::fit(std::span<const float> start, std::span<const float> end,
                           std::span<const std::uint32_t> indices, int arity, collision::Bvh& tree) {
  boxes_.resize(indices.size() / arity);
  for (std::size_t i = 0; i < boxes_.size(); ++i) {
    collision::Aabb& b = boxes_[i];
    for (int a = 0; a < 3; ++a) b.lo[a] = b.hi[a] = start[std::size_t{indices[i * arity]} * 4 + a];
    for (int k = 0; k < arity; ++k)
      for (const std::span<const float> x : {start, end})
        for (int a = 0; a < 3; ++a) {
          const float c = x[std::size_t{indices[i * arity + k]} * 4 + a];
          b.lo[a] = std::min(b.lo[a], c), b.hi[a] = std::max(b.hi[a], c);
        }
  }
  if (tree.empty()) tree.build(boxes_);
  else tree.update(boxes_);
}

namespace {

// A touch found by a query: the weights of the two primitives' points
// (edge-edge: (1 - s, s, 1 - t, t); vertex-face: (1, wa, wb, wc)), the
// normal of the plane they meet in, the first point minus the second at the
// start, and how that difference moved.
struct Touch {
  double w[4];
  Point plane, apart, moved;
};

// Edge (m[0], m[1]) against edge (m[2], m[3]), given as motions; [out]
// touch. Counts the query in `queries`.
Result<bool> touch_edges(const Motion* m, double separation, Touch& touch, std::uint64_t& queries) {
  ccd::Settings settings;
  settings.min_separation = separation;
  ++queries;
  const auto hit = ccd::edge_edge(m[0], m[1], m[2], m[3], settings);
  if (Status s = check_query(hit); !s) return s.error();
  if (!hit->touch) return false;
  // The touching points: the closest points at the time returned (the
  // hit's own parameters are only its box's corner, up to a box's width off).
  const double t = hit->time;
  const auto st = kernels::proximity::closest_between_segments(at(m[0], t), at(m[1], t), at(m[2], t), at(m[3], t));
  touch.w[0] = 1.0 - st.s, touch.w[1] = st.s, touch.w[2] = 1.0 - st.t, touch.w[3] = st.t;
  touch.plane = cross(sub(lerp(m[1], t), lerp(m[0], t)), sub(lerp(m[3], t), lerp(m[2], t)));
  touch.apart = sub(weighted({m, 2}, {touch.w, 2}, 0.0), weighted({m + 2, 2}, {touch.w + 2, 2}, 0.0));
  touch.moved = sub(sub(weighted({m, 2}, {touch.w, 2}, 1.0), weighted({m + 2, 2}, {touch.w + 2, 2}, 1.0)), touch.apart);
  return true;
}

// Vertex m[0] against triangle m[1..3].
Result<bool> touch_vertex_face(const Motion* m, double separation, Touch& touch, std::uint64_t& queries) {
  ccd::Settings settings;
  settings.min_separation = separation;
  ++queries;
  const auto hit = ccd::vertex_face(m[0], m[1], m[2], m[3], settings);
  if (Status s = check_query(hit); !s) return s.error();
  if (!hit->touch) return false;
  const double t = hit->time;
  const auto w = kernels::proximity::closest_on_triangle(at(m[0], t), at(m[1], t), at(m[2], t), at(m[3], t));
  touch.w[0] = 1.0, touch.w[1] = w.wa, touch.w[2] = w.wb, touch.w[3] = w.wc;
  touch.plane = cross(sub(lerp(m[2], t), lerp(m[1], t)), sub(lerp(m[3], t), lerp(m[1], t)));
  touch.apart = sub(m[0][0], weighted({m + 1, 3}, {touch.w + 1, 3}, 0.0));
  touch.moved = sub(sub(m[0][1], weighted({m + 1, 3}, {touch.w + 1, 3}, 1.0)), touch.apart);
  return true;
}

void motions_of(std::span<const float> start, std::span<const float> end, std::span<const std::uint32_t> particles,
                Motion* m) {
  for (std::size_t k = 0; k < particles.size(); ++k) m[k] = motion_of(start, end, particles[k]);
}

Contact contact_of(Contact::Kind kind, std::array<std::uint32_t, 4> v, const Touch& touch) {
  Contact c;
  c.kind = kind;
  c.v = v;
  for (int k = 0; k < 4; ++k) c.w[k] = static_cast<float>(touch.w[k]);
  c.normal = contact_normal(touch.plane, touch.apart, touch.moved);
  return c;
}

// The touch of tissue `p` (arity 2 or 3) with capsule c, as a shape_face hit.
Contact capsule_contact(std::span<const std::uint32_t> p, std::uint32_t c, const double* w, const Touch& t) {
  Contact hit;
  hit.kind = Contact::Kind::shape_face;
  if (p.size() == 3) {
    hit.v = {p[0], p[0], p[1], p[2]};
    hit.w = {0.0f, float(w[0]), float(w[1]), float(w[2])};
  } else {
    hit.v = {p[0], p[0], p[1], p[1]};
    hit.w = {0.0f, float(w[0]), 0.0f, float(w[1])};
  }
  hit.normal = contact_normal(t.plane, t.apart, t.moved);
  hit.shape = c;
  return hit;
}

}  // namespace

Status ContinuousSearch::check_finite(std::span<const float> start, std::span<const float> end) const {
  // Every vertex of a segment or triangle, once (a NaN would fail every
  // box test silently).
  for (const auto* list : {&segments_, &triangle_vertices_})
    for (std::uint32_t p : *list)
      for (int a = 0; a < 3; ++a)
        if (!std::isfinite(start[std::size_t{p} * 4 + a]) || !std::isfinite(end[std::size_t{p} * 4 + a]))
          return Error(ErrorCode::bad_parameter, "continuous collision: particle " + std::to_string(p) +
                                                     " (device order) has a non-finite position");
  return {};
}

Status ContinuousSearch::find(std::span<const float> start, std::span<const float> end,
                              std::vector<Contact>& hits, std::span<const Capsule> capsules,
                              std::span<const std::uint32_t> carried) {
  hits.clear();
  queries_ = 0;
  if (Status s = check_finite(start, end); !s) return s;
  if (!segments_.empty()) {
    fit(start, end, segments_, 2, segment_tree_);
    segment_boxes_ = boxes_;
  }
  // Against the triangles: boxes grown by the drift from the triangles' reference.
  const bool surfaces = !triangles_.empty() && (!segments_.empty() || !capsules.empty());
  double reach = 0.0;
  if (surfaces) {
    if (reference_.size() != start.size()) set_reference(start);
    reach = drift(start, end);
  }
  if (surfaces && !segments_.empty()) {
    boxes_ = segment_boxes_;
    grow(boxes_, reach);
    segment_reach_tree_.build(boxes_);
  }
  if (!segments_.empty())
    if (Status s = thread_against_thread(start, end, hits); !s) return s;
  if (!segments_.empty() && !triangles_.empty())
    if (Status s = thread_against_surfaces(start, end, hits); !s) return s;
  if (!capsules.empty())
    if (Status s = capsules_against_tissue(start, end, hits, capsules, carried, surfaces, reach); !s) return s;
  collision::sort_unique_contacts(hits);
  return {};
}

// Two primitives of the threads and surfaces, `p` as edge-edge (a0, a1, b0,
// b1) or vertex-triangle (v, t0, t1, t2): a query unless none of them
// moves, and its touch as a contact of `kind`.
Status ContinuousSearch::test_primitives(std::span<const float> start, std::span<const float> end,
                                         std::array<std::uint32_t, 4> p, Contact::Kind kind,
                                         std::vector<Contact>& hits) {
  if (!moves(start, end, p)) return {};
  Motion m[4];
  motions_of(start, end, p, m);
  Touch touch;
  auto hit = kind == Contact::Kind::edge_edge ? touch_edges(m, 0.0, touch, queries_)
                                              : touch_vertex_face(m, 0.0, touch, queries_);
  if (!hit) return hit.error();
  if (*hit) hits.push_back(contact_of(kind, p, touch));
  return {};
}

Status ContinuousSearch::thread_against_thread(std::span<const float> start, std::span<const float> end,
                                               std::vector<Contact>& hits) {
  collision::self_overlapping_pairs(segment_tree_, collision::SharesVertexOf<2>{segments_}, pairs_);
  for (const collision::Pair& pr : pairs_) {
    const std::uint32_t* a = &segments_[std::size_t{pr.first} * 2];
    const std::uint32_t* b = &segments_[std::size_t{pr.second} * 2];
    if (Status s = test_primitives(start, end, {a[0], a[1], b[0], b[1]}, Contact::Kind::edge_edge, hits); !s)
      return s;
  }
  return {};
}

// Thread against surfaces: each end against the face, the segment against its edges.
Status ContinuousSearch::thread_against_surfaces(std::span<const float> start, std::span<const float> end,
                                                 std::vector<Contact>& hits) {
  collision::overlapping_pairs(segment_reach_tree_, triangle_tree_, pairs_);
  for (const collision::Pair& pr : pairs_) {
    const std::uint32_t* s = &segments_[std::size_t{pr.first} * 2];
    const std::uint32_t* t = &triangles_[std::size_t{pr.second} * 3];
    bool shared = false;  // a thread tied into a surface: its own triangles are its neighbours
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 3; ++j) shared |= s[i] == t[j];
    if (shared) continue;
    const std::uint32_t joined[5] = {s[0], s[1], t[0], t[1], t[2]};
    if (suture_exempt(exempt_, joined)) continue;  // the thread runs through a puncture here
    for (int i = 0; i < 2; ++i)
      if (Status st = test_primitives(start, end, {s[i], t[0], t[1], t[2]}, Contact::Kind::vertex_triangle, hits);
          !st)
        return st;
    for (int j = 0; j < 3; ++j)
      if (Status st = test_primitives(start, end, {s[0], s[1], t[j], t[(j + 1) % 3]}, Contact::Kind::edge_edge, hits);
          !st)
        return st;
  }
  return {};
}

// Capsules' axes against the threads and the surfaces. The tissue is the
// first primitive (its weights first), the axis the second.
Status ContinuousSearch::capsules_against_tissue(std::span<const float> start, std::span<const float> end,
                                                 std::vector<Contact>& hits, std::span<const Capsule> capsules,
                                                 std::span<const std::uint32_t> carried, bool surfaces,
                                                 double reach) {
  capsule_boxes_.resize(capsules.size());
  for (std::size_t i = 0; i < capsules.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      double lo = capsules[i].ends[0][0][a], hi = lo;
      for (const Motion& e : capsules[i].ends)
        for (const Point& x : e) lo = std::min(lo, x[a]), hi = std::max(hi, x[a]);
      // Widened by the stray and rounded outwards to float.
      capsule_boxes_[i].lo[a] = std::nextafter(static_cast<float>(lo - capsules[i].stray), -INFINITY);
      capsule_boxes_[i].hi[a] = std::nextafter(static_cast<float>(hi + capsules[i].stray), INFINITY);
    }
  capsule_tree_.build(capsule_boxes_);
  if (surfaces) {
    boxes_ = capsule_boxes_;
    grow(boxes_, reach);
    capsule_reach_tree_.build(boxes_);
  }
  if (Status s = capsule_against(start, end, hits, capsules, carried, segment_tree_, capsule_tree_, segments_, 2); !s)
    return s;
  if (surfaces)
    if (Status s = capsule_against(start, end, hits, capsules, carried, triangle_tree_, capsule_reach_tree_,
                                   triangles_, 3);
        !s)
      return s;
  return {};
}

Status ContinuousSearch::capsule_against(std::span<const float> start, std::span<const float> end,
                                         std::vector<Contact>& hits, std::span<const Capsule> capsules,
                                         std::span<const std::uint32_t> carried, const collision::Bvh& tree,
                                         const collision::Bvh& capsule_tree,
                                         const std::vector<std::uint32_t>& indices, int arity) {
  if (indices.empty()) return {};
  // Whether capsule c carries all of the particles (they cannot cross it).
  const auto all_carried = [&](std::span<const std::uint32_t> particles, std::uint32_t c) {
    if (carried.empty()) return false;
    for (std::uint32_t p : particles)
      if (carried[p] != c) return false;
    return true;
  };
  Touch touch;
  collision::overlapping_pairs(tree, capsule_tree, pairs_);
  for (const collision::Pair& pr : pairs_) {
    const Capsule& cap = capsules[pr.second];
    const std::span<const std::uint32_t> p(&indices[std::size_t{pr.first} * arity], std::size_t(arity));
    if (all_carried(p, pr.second)) continue;
    Motion m[4];
    const Motion& a0 = cap.ends[0];
    const Motion& a1 = cap.ends[1];
    if (a0[0] == a0[1] && a1[0] == a1[1] && !moves(start, end, p)) continue;  // neither moves
    // The tissue's edges against the axis.
    for (int j = 0; j < (arity == 3 ? 3 : 1); ++j) {
      m[0] = motion_of(start, end, p[j]), m[1] = motion_of(start, end, p[(j + 1) % arity]);
      m[2] = a0, m[3] = a1;
      auto hit = touch_edges(m, cap.stray, touch, queries_);
      if (!hit) return hit.error();
      if (!*hit) continue;
      double w[3] = {0.0, 0.0, 0.0};
      w[j] = touch.w[0], w[(j + 1) % arity] = touch.w[1];
      hits.push_back(capsule_contact(p, pr.second, w, touch));
    }
    if (arity != 3) continue;
    // The axis' ends against the face: the touch's normal is the face's,
    // towards the side the face came from (from the axis to the face).
    for (const Motion& tip : {a0, a1}) {
      m[0] = tip;
      for (int k = 0; k < 3; ++k) m[k + 1] = motion_of(start, end, p[k]);
      auto hit = touch_vertex_face(m, cap.stray, touch, queries_);
      if (!hit) return hit.error();
      if (!*hit) continue;
      touch.apart = {-touch.apart[0], -touch.apart[1], -touch.apart[2]};
      touch.moved = {-touch.moved[0], -touch.moved[1], -touch.moved[2]};
      hits.push_back(capsule_contact(p, pr.second, touch.w + 1, touch));
    }
  }
  return {};
}

ContinuousCollision::ContinuousCollision(std::vector<std::uint32_t> segments, std::vector<std::uint32_t> triangles,
                                         MeshCollision& mesh_collision, const XpbdBuffers& buffers,
                                         const MeshCollisionDesc& desc, int substeps)
    : search_(std::move(segments), std::move(triangles)),
      mesh_collision_(mesh_collision),
      buffers_(buffers),
      thickness_(desc.thickness),
      repairs_(desc.continuous_repairs),
      substeps_(substeps) {}

void ContinuousCollision::begin_frame(std::vector<FrameCapsule> capsules) {
  frame_capsules_ = std::move(capsules);
  hits_ = repair_rounds_ = reverted_ = carried_count_ = forced_ = 0;
  wall_ms_ = 0.0;
}

namespace {

// A capsule's pose at fraction u of the frame, as the kernels interpolate
// it (contact_params.h): position linearly, rotation by normalised lerp.
PosedShape pose_at(const FrameCapsule& c, double u) {
  PosedShape p = c.start;
  for (int a = 0; a < 3; ++a) p.position[a] = c.start.position[a] + u * (c.end.position[a] - c.start.position[a]);
  p.rotation = math::nlerp(c.start.rotation, c.end.rotation, u);
  return p;
}

// The ends of a capsule's axis at a pose.
std::array<math::Vec3, 2> axis_ends(const PosedShape& s) {
  const math::Vec3 axis = math::rotate(s.rotation, math::Vec3{0.0, s.shape->half_height, 0.0});
  return {math::sub(s.position, axis), math::add(s.position, axis)};
}

}  // namespace

void ContinuousCollision::substep_capsules(int substep) {
  capsules_.clear();
  substep_poses_.clear();
  for (const FrameCapsule& c : frame_capsules_) {
    const PosedShape from = pose_at(c, double(substep) / substeps_), to = pose_at(c, double(substep + 1) / substeps_);
    substep_poses_.push_back({from, to});
    const auto a = axis_ends(from), b = axis_ends(to);
    ContinuousSearch::Capsule cap;
    for (int k = 0; k < 2; ++k) cap.ends[k] = {Point{a[k][0], a[k][1], a[k][2]}, Point{b[k][0], b[k][1], b[k][2]}};
    // Linearising the ends' motion: a rotation by theta moves them along an
    // arc of radius L (the half-height), at most L theta^2 / 8 from its
    // chord, and the normalised lerp's pace differs from the chord's by
    // O(L theta^3): L (theta^2 / 4 + theta^3) bounds both, plus 1e-7 m for
    // the kernels' float poses against these double ones.
    const double cos_half = std::min(1.0, std::abs(math::qdot(from.rotation, to.rotation)));
    const double theta = 2.0 * std::acos(cos_half);
    cap.stray = c.start.shape->half_height * (theta * theta / 4.0 + theta * theta * theta) + 1e-7;
    capsules_.push_back(cap);
  }
}

Contact ContinuousCollision::capsule_contact(const Contact& hit) const {
  const FrameCapsule& capsule = frame_capsules_[hit.shape];
  const math::Vec3 n{hit.normal[0], hit.normal[1], hit.normal[2]};
  // thickness - the largest n . p over the capsule at a pose: the plane
  // that touches it, `thickness` out along n.
  const auto offset_at = [&](const PosedShape& pose) {
    const auto e = axis_ends(pose);
    return thickness_ - (std::max(math::dot(n, e[0]), math::dot(n, e[1])) + pose.shape->radius);
  };
  Contact c = hit;
  c.offset = static_cast<float>(offset_at(capsule.end));
  c.motion = static_cast<float>(offset_at(capsule.start)) - c.offset;
  c.shape = capsule.tool;
  return c;
}

Status ContinuousCollision::after_sweeps(Device& device, int substep, int round, bool& repair) {
  const auto began = std::chrono::steady_clock::now();
  repair = false;
  const std::size_t floats = mesh_collision_.particles() * 4;
  start_.resize(floats);
  end_.resize(floats);
  if (round == 0) {
    substep_capsules(substep);
    carried_.assign(floats / 4, kNotCarried);
    // The substep's start does not change across its rounds.
    if (Status s = device.read_buffer(buffers_.previous, 0, start_.data(), floats * 4); !s) return s;
    if (substep == 0) search_.set_reference(start_);  // the frame's start
  }
  if (Status s = device.read_buffer(buffers_.position, 0, end_.data(), floats * 4); !s) return s;
  if (Status s = search_.find(start_, end_, hits_found_, capsules_); !s) return s;
  hits_ += static_cast<std::uint32_t>(hits_found_.size());
  Status done;
  if (!hits_found_.empty()) {
    bool appended = false;
    if (round < repairs_) {
      contacts_.clear();
      for (const Contact& h : hits_found_)
        contacts_.push_back(h.kind == Contact::Kind::shape_face ? capsule_contact(h) : h);
      auto added = mesh_collision_.append_contacts(device, contacts_);
      if (!added) return added.error();
      appended = *added > 0;
    }
    if (appended) {
      repair = true;
      ++repair_rounds_;
    } else {
      done = fail_safe(device);
    }
  }
  wall_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - began).count();
  return done;
}

Status ContinuousCollision::fail_safe(Device& device) {
  const auto moving = [&](std::uint32_t p) {
    const std::size_t at = std::size_t{p} * 4;
    return end_[at + 3] > 0.0f && (end_[at] != start_[at] || end_[at + 1] != start_[at + 1] || end_[at + 2] != start_[at + 2]);
  };
  while (!hits_found_.empty()) {
    bool acted = false;
    for (const Contact& c : hits_found_) {
      bool here = false;
      if (c.kind == Contact::Kind::shape_face) {
        // Against a capsule: the tissue's movable particles move with it
        // (the capsule's rigid motion over the substep), so the axis cannot
        // cross them. Those another capsule carries stay with that one: a
        // pair left touching is forced.
        const auto& [from, to] = substep_poses_[c.shape];
        for (std::uint32_t p : c.v) {
          const std::size_t at = std::size_t{p} * 4;
          if (!(end_[at + 3] > 0.0f) || carried_[p] != kNotCarried) continue;
          const math::Vec3 local = math::rotate(math::conj(from.rotation),
                                                math::sub(math::Vec3{start_[at], start_[at + 1], start_[at + 2]}, from.position));
          const math::Vec3 x = math::add(to.position, math::rotate(to.rotation, local));
          for (int a = 0; a < 3; ++a) end_[at + a] = static_cast<float>(x[a]);
          carried_[p] = c.shape;
          ++carried_count_;
          here = true;
        }
      } else {
        // Between tissues: the moving particles stop where the substep
        // started (those a capsule carries keep moving with it).
        for (std::uint32_t p : c.v) {
          if (carried_[p] != kNotCarried || !moving(p)) continue;
          const std::size_t at = std::size_t{p} * 4;
          for (int a = 0; a < 3; ++a) end_[at + a] = start_[at + a];
          ++reverted_;
          here = true;
        }
      }
      acted |= here;
    }
    // The pairs left are those nothing can be done for: a capsule forcing
    // tissue it carries, or pinned tissue, through other tissue. Counted,
    // let through (FrameStats::ccd_forced).
    if (!acted) {
      forced_ += static_cast<std::uint32_t>(hits_found_.size());
      break;
    }
    if (Status s = search_.find(start_, end_, hits_found_, capsules_, carried_); !s) return s;
    hits_ += static_cast<std::uint32_t>(hits_found_.size());
  }
  return device.write_buffer(buffers_.position, 0, end_.data(), end_.size() * 4);
}

}  // namespace sinew
