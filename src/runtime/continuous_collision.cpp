// continuous_collision.cpp — the threads' continuous collision detection in
// the solver (continuous_collision.h; issue 13, part 3).
#include "runtime/continuous_collision.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <string>

#include "math/proximity_math.h"
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
// at the start (`apart`, first point minus second); `apart` itself when the
// motion lies in that plane or the plane is undefined.
std::array<float, 3> contact_normal(Point plane, const Point& apart) {
  const double plane_length = std::sqrt(dot(plane, plane));
  const double apart_length = std::sqrt(dot(apart, apart));
  const double along = dot(plane, apart);
  Point n = plane;
  // In-plane motion: the side is not along the plane's normal.
  if (!(plane_length > 0.0) || std::abs(along) <= 1e-6 * plane_length * apart_length) n = apart;
  else if (along < 0.0) n = {-n[0], -n[1], -n[2]};
  double length = std::sqrt(dot(n, n));
  if (!(length > 0.0)) {  // touching at the start and no plane: any direction off the first primitive
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
    : segments_(std::move(segments)), triangles_(std::move(triangles)) {}

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

Status ContinuousSearch::find(std::span<const float> start, std::span<const float> end,
                              std::vector<Contact>& hits) {
  hits.clear();
  queries_ = 0;
  for (const auto* list : {&segments_, &triangles_})
    for (std::uint32_t p : *list)
      for (int a = 0; a < 3; ++a)
        if (!std::isfinite(start[std::size_t{p} * 4 + a]) || !std::isfinite(end[std::size_t{p} * 4 + a]))
          return Error(ErrorCode::bad_parameter, "continuous collision: particle " + std::to_string(p) +
                                                     " (device order) has a non-finite position");
  const ccd::Settings settings;  // min_separation 0: a true touch
  // Edge (a0, a1) against edge (b0, b1), particles as given.
  const auto edge_edge = [&](std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1) -> Status {
    const std::uint32_t p[4] = {a0, a1, b0, b1};
    if (!moves(start, end, p)) return {};
    const Motion m[4] = {motion_of(start, end, a0), motion_of(start, end, a1), motion_of(start, end, b0),
                         motion_of(start, end, b1)};
    ++queries_;
    const auto hit = ccd::edge_edge(m[0], m[1], m[2], m[3], settings);
    if (Status s = check_query(hit); !s) return s;
    if (!hit->touch) return {};
    // The touching points: the closest points at the time returned (the
    // hit's own parameters are only its box's corner, up to a box's width off).
    const double t = hit->time;
    const auto params = kernels::proximity::closest_between_segments(at(m[0], t), at(m[1], t), at(m[2], t), at(m[3], t));
    const double wa[2] = {1.0 - params.s, params.s}, wb[2] = {1.0 - params.t, params.t};
    const Point plane = cross(sub(lerp(m[1], t), lerp(m[0], t)), sub(lerp(m[3], t), lerp(m[2], t)));
    const Point apart = sub(weighted({m, 2}, wa, 0.0), weighted({m + 2, 2}, wb, 0.0));
    Contact c;
    c.kind = Contact::Kind::edge_edge;
    c.v = {a0, a1, b0, b1};
    c.w = {static_cast<float>(wa[0]), static_cast<float>(wa[1]), static_cast<float>(wb[0]), static_cast<float>(wb[1])};
    c.normal = contact_normal(plane, apart);
    hits.push_back(c);
    return {};
  };
  // Vertex q against triangle (a, b, c).
  const auto vertex_face = [&](std::uint32_t q, const std::uint32_t* tri) -> Status {
    const std::uint32_t p[4] = {q, tri[0], tri[1], tri[2]};
    if (!moves(start, end, p)) return {};
    const Motion m[4] = {motion_of(start, end, q), motion_of(start, end, tri[0]), motion_of(start, end, tri[1]),
                         motion_of(start, end, tri[2])};
    ++queries_;
    const auto hit = ccd::vertex_face(m[0], m[1], m[2], m[3], settings);
    if (Status s = check_query(hit); !s) return s;
    if (!hit->touch) return {};
    const double t = hit->time;
    const auto bary = kernels::proximity::closest_on_triangle(at(m[0], t), at(m[1], t), at(m[2], t), at(m[3], t));
    const double w[3] = {bary.wa, bary.wb, bary.wc};
    const Point plane = cross(sub(lerp(m[2], t), lerp(m[1], t)), sub(lerp(m[3], t), lerp(m[1], t)));
    const Point apart = sub(m[0][0], weighted({m + 1, 3}, w, 0.0));
    Contact c;
    c.kind = Contact::Kind::vertex_triangle;
    c.v = {q, tri[0], tri[1], tri[2]};
    c.w = {1.0f, static_cast<float>(w[0]), static_cast<float>(w[1]), static_cast<float>(w[2])};
    c.normal = contact_normal(plane, apart);
    hits.push_back(c);
    return {};
  };

  if (segments_.empty()) return {};
  fit(start, end, segments_, 2, segment_tree_);
  collision::self_overlapping_pairs(segment_tree_, collision::SharesVertexOf<2>{segments_}, pairs_);
  for (const collision::Pair& pr : pairs_) {
    const std::uint32_t* a = &segments_[std::size_t{pr.first} * 2];
    const std::uint32_t* b = &segments_[std::size_t{pr.second} * 2];
    if (Status s = edge_edge(a[0], a[1], b[0], b[1]); !s) return s;
  }
  if (!triangles_.empty()) {
    // The segment tree's boxes are still the segments' (fit above).
    fit(start, end, triangles_, 3, triangle_tree_);
    collision::overlapping_pairs(segment_tree_, triangle_tree_, pairs_);
    for (const collision::Pair& pr : pairs_) {
      const std::uint32_t* s = &segments_[std::size_t{pr.first} * 2];
      const std::uint32_t* t = &triangles_[std::size_t{pr.second} * 3];
      bool shared = false;  // a thread tied into a surface: its own triangles are its neighbours
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 3; ++j) shared |= s[i] == t[j];
      if (shared) continue;
      for (int i = 0; i < 2; ++i)
        if (Status st = vertex_face(s[i], t); !st) return st;
      for (int j = 0; j < 3; ++j)
        if (Status st = edge_edge(s[0], s[1], t[j], t[(j + 1) % 3]); !st) return st;
    }
  }
  collision::sort_unique_contacts(hits);
  return {};
}

ContinuousCollision::ContinuousCollision(std::vector<std::uint32_t> segments, std::vector<std::uint32_t> triangles,
                                         MeshCollision& mesh_collision, const XpbdBuffers& buffers, int repairs)
    : search_(std::move(segments), std::move(triangles)),
      mesh_collision_(mesh_collision),
      buffers_(buffers),
      repairs_(repairs) {}

void ContinuousCollision::begin_frame() {
  hits_ = repair_rounds_ = reverted_ = 0;
  wall_ms_ = 0.0;
}

Status ContinuousCollision::after_sweeps(Device& device, int /*substep*/, int round, bool& repair) {
  const auto began = std::chrono::steady_clock::now();
  repair = false;
  const std::size_t floats = mesh_collision_.particles() * 4;
  start_.resize(floats);
  end_.resize(floats);
  // The substep's start does not change across its rounds, but a round
  // costs one read more than it would need: kept simple.
  if (Status s = device.read_buffer(buffers_.previous, 0, start_.data(), floats * 4); !s) return s;
  if (Status s = device.read_buffer(buffers_.position, 0, end_.data(), floats * 4); !s) return s;
  if (Status s = search_.find(start_, end_, hits_found_); !s) return s;
  hits_ += static_cast<std::uint32_t>(hits_found_.size());
  Status done;
  if (!hits_found_.empty()) {
    bool appended = false;
    if (round < repairs_) {
      auto added = mesh_collision_.append_contacts(device, hits_found_);
      if (!added) return added.error();
      appended = *added;
    }
    if (appended) {
      repair = true;
      ++repair_rounds_;
    } else {
      done = stop_touching(device);
    }
  }
  wall_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - began).count();
  return done;
}

Status ContinuousCollision::stop_touching(Device& device) {
  while (!hits_found_.empty()) {
    const std::uint32_t before = reverted_;
    for (const Contact& c : hits_found_)
      for (std::uint32_t p : c.v) {
        const std::size_t at = std::size_t{p} * 4;
        if (!(end_[at + 3] > 0.0f)) continue;  // immovable
        bool moved = false;
        for (int a = 0; a < 3; ++a) moved |= end_[at + a] != start_[at + a];
        if (!moved) continue;
        for (int a = 0; a < 3; ++a) end_[at + a] = start_[at + a];
        ++reverted_;
      }
    // Every touching pair has a moving particle (find skips the others),
    // and only movable particles move: a round always stops one.
    if (reverted_ == before)
      return Error(ErrorCode::internal, "internal: the continuous collision's fail-safe stopped no particle");
    if (Status s = search_.find(start_, end_, hits_found_); !s) return s;
    hits_ += static_cast<std::uint32_t>(hits_found_.size());
  }
  return device.write_buffer(buffers_.position, 0, end_.data(), end_.size() * 4);
}

}  // namespace sinew
