// sutures.cpp — needles and the threads they pull through tissue (issue 13,
// part 4); see sutures.h, and kernels/shared/suture_params.h for the rows.
// After Moore et al., "The interactive medical simulation toolkit (iMSTK)",
// Frontiers in Virtual Reality 2023, section 2.5.
#include "runtime/sutures.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <tuple>

#include "runtime/suture_exemption.h"
#include "suture_params.h"

namespace sinew {
namespace {

using math::Vec3;

// How far behind the tip its path starts, and beyond its end it reaches
// [m]: a surface the tip holds (its contact keeps it at the tip, up to the
// sweeps' slop) is found again in the next frame.
constexpr double kTipReach = 2e-4;
// How far ahead of the needle's tip a puncture's tissue point may be
// before the needle counts as pulled out of it [m].
constexpr double kPulledOut = 5e-4;

Vec3 unit(const Vec3& v) {
  const double n = math::norm(v);
  return n > 0.0 ? math::mul(v, 1.0 / n) : Vec3{0.0, 0.0, 0.0};
}

}  // namespace

Result<std::unique_ptr<Sutures>> Sutures::create(const SceneDesc& scene, const CompiledScene& compiled,
                                                 Device& device) {
  auto out = std::unique_ptr<Sutures>(new Sutures());
  const auto& slot = compiled.order.device_of;
  for (std::size_t b = 0; b < scene.tet_bodies.size(); ++b) {
    const TetMesh& mesh = scene.tet_bodies[b].mesh;
    const std::uint32_t first = compiled.tet_body_first_particle[b];
    // Each face's opposite vertex in its tet: a boundary face has one tet.
    std::map<std::array<std::uint32_t, 3>, std::uint32_t> opposite;
    for (const auto& t : mesh.tets)
      for (int k = 0; k < 4; ++k) {
        std::array<std::uint32_t, 3> face{t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]};
        std::sort(face.begin(), face.end());
        opposite[face] = t[k];
      }
    Surface s;
    s.kind = BodyKind::tet;
    s.body = static_cast<std::uint32_t>(b);
    for (const auto& f : extract_boundary_surface(mesh).triangles) {
      std::array<std::uint32_t, 3> key{f[0], f[1], f[2]};
      std::sort(key.begin(), key.end());
      s.triangles.push_back({slot[first + f[0]], slot[first + f[1]], slot[first + f[2]]});
      s.opposite.push_back(slot[first + opposite.at(key)]);
    }
    out->surfaces_.push_back(std::move(s));
  }
  for (std::size_t b = 0; b < scene.tri_bodies.size(); ++b) {
    const std::uint32_t first = compiled.tri_body_first_particle[b];
    Surface s;
    s.kind = BodyKind::tri;
    s.body = static_cast<std::uint32_t>(b);
    for (const auto& f : scene.tri_bodies[b].mesh.triangles) {
      s.triangles.push_back({slot[first + f[0]], slot[first + f[1]], slot[first + f[2]]});
      s.opposite.push_back(kNone);
    }
    out->surfaces_.push_back(std::move(s));
  }
  for (std::size_t i = 0; i < scene.needles.size(); ++i) {
    Needle n;
    n.desc = scene.needles[i];
    n.position_start = n.position_end = n.desc.position;
    n.rotation_start = n.rotation_end = n.desc.rotation;
    n.body.position = n.desc.position;
    n.body.rotation = n.desc.rotation;
    if (n.desc.drive == NeedleDrive::force) {
      n.body.mass = n.desc.mass;
      n.body.inertia = n.desc.inertia;
      if (n.desc.gravity) n.body.gravity = scene.gravity;
    }
    if (n.desc.thread >= 0) {
      const auto body = static_cast<std::size_t>(n.desc.thread);
      const std::uint32_t first = compiled.line_body_first_particle[body];
      n.thread_first = static_cast<std::uint32_t>(out->slots_.size());
      n.thread_vertices = static_cast<std::uint32_t>(scene.line_bodies[body].vertices.size());
      for (std::uint32_t v = 0; v < n.thread_vertices; ++v) out->slots_.push_back(slot[first + v]);
      Row tie;
      const std::uint32_t tail = out->slots_[n.thread_first];
      tie.words = {SINEW_SUTURE_TIE, static_cast<std::uint32_t>(i), tail, tail, tail, n.thread_first,
                   n.thread_vertices, 0};
      tie.weights = {1.0f, 0.0f, 0.0f, 0.0f};
      n.rows.push_back(tie);
    }
    out->curve_points_ += static_cast<std::uint32_t>(n.desc.curve.size());
    out->needles_.push_back(std::move(n));
  }
  out->positions_.resize(compiled.positions.size() * 4);
  out->frame_ = scene.solver.time_step;
  out->stiffness_ = double(scene.solver.iterations) * scene.solver.substeps * scene.solver.substeps;
  out->rows_capacity_ = static_cast<std::uint32_t>(out->needles_.size()) * kRowsPerNeedle;
  SutureBuffers& b = out->buffers_;
  const std::size_t needles = out->needles_.size();
  for (auto [handle, bytes, label] :
       {std::tuple{&b.table, (1 + 2 * needles) * 4, "suture table"}, std::tuple{&b.needles, needles * 48, "needles"},
        std::tuple{&b.curve, std::size_t{out->curve_points_} * 32, "needle curves"},
        std::tuple{&b.slots, std::max<std::size_t>(out->slots_.size(), 1) * 4, "thread slots"},
        std::tuple{&b.rows, std::size_t{out->rows_capacity_} * 32, "suture rows"},
        std::tuple{&b.weights, std::size_t{out->rows_capacity_} * 16, "suture weights"},
        std::tuple{&b.lambda, std::size_t{out->rows_capacity_} * 48, "suture lambdas"}}) {
    auto made = device.create_buffer(std::max<std::size_t>(bytes, 16), label);
    if (!made) return made.error();
    *handle = *made;
  }
  if (!out->slots_.empty())
    if (Status s = device.write_buffer(b.slots, 0, out->slots_.data(), out->slots_.size() * 4); !s) return s.error();
  std::vector<float> params;
  for (const Needle& n : out->needles_)
    params.insert(params.end(), {float(n.desc.compliance), float(n.desc.thread_static_friction),
                                 float(n.desc.thread_dynamic_friction),
                                 float(std::min(std::tan(n.desc.max_puncture_angle), 1e6)),
                                 float(n.desc.shaft_friction), float(n.desc.shaft_static_friction),
                                 float(n.desc.shaft_viscous_friction), float(n.desc.shaft_stick_velocity),
                                 float(n.desc.cutting_force), float(n.desc.tip_radius), 0.0f, 0.0f});
  if (Status s = device.write_buffer(b.needles, 0, params.data(), params.size() * 4); !s) return s.error();
  return out;
}

namespace {

// The angle [rad] between two unit quaternions' rotations.
double turn_between(const math::Quat& a, const math::Quat& b) {
  return 2.0 * std::acos(std::min(1.0, std::abs(math::qdot(a, b))));
}

}  // namespace

Status Sutures::set_pose(std::size_t index, const Vec3& position, const math::Quat& rotation) {
  if (needles_[index].desc.drive != NeedleDrive::kinematic)
    return Error(ErrorCode::bad_parameter, "set_needle_pose: needle " + std::to_string(index) +
                                               " is force-driven (NeedleDrive::force): use apply_needle_force");
  // Its points move along straight lines within a frame (suture_params.h):
  // a turn of more than a quarter circle would fold the needle.
  const double turn = turn_between(needles_[index].rotation_start, rotation);
  if (turn > M_PI / 2)
    return Error(ErrorCode::bad_parameter, "set_needle_pose: needle " + std::to_string(index) + " would turn by " +
                                               std::to_string(turn) +
                                               " rad in one frame; at most pi/2 (its points move along chords "
                                               "within a frame: turn it over several)");
  needles_[index].position_end = position;
  needles_[index].rotation_end = rotation;
  return {};
}

Status Sutures::apply_force(std::size_t index, const Vec3& force, const Vec3& torque, double dt) {
  Needle& n = needles_[index];
  if (n.desc.drive != NeedleDrive::force)
    return Error(ErrorCode::bad_parameter, "apply_needle_force: needle " + std::to_string(index) +
                                               " is kinematic (NeedleDrive::kinematic): use set_needle_pose");
  return add_frame_force(n.body, force, torque, dt, "apply_needle_force: needle " + std::to_string(index));
}

std::vector<Vec3> Sutures::curve_at(const Needle& n, bool end) const {
  std::vector<Vec3> out;
  for (const auto& p : n.desc.curve)
    out.push_back(math::add(end ? n.position_end : n.position_start,
                            math::rotate(end ? n.rotation_end : n.rotation_start, p)));
  return out;
}

Vec3 Sutures::position_of(std::uint32_t slot) const {
  const std::size_t at = std::size_t{slot} * 4;
  return {positions_[at], positions_[at + 1], positions_[at + 2]};
}

Vec3 Sutures::point_of(const Row& row) const {
  Vec3 p{0.0, 0.0, 0.0};
  for (int k = 0; k < 3; ++k)
    p = math::add(p, math::mul(position_of(row.words[2 + k]), double(row.weights[k])));
  return p;
}

bool Sutures::first_crossing(const Vec3& a, const Vec3& b, bool entering, Needle& needle, Row& row) {
  const Vec3 dir = math::sub(b, a);
  Vec3 lo = a, hi = a;
  for (int k = 0; k < 3; ++k) lo[k] = std::min(a[k], b[k]), hi[k] = std::max(a[k], b[k]);
  double best = 2.0;
  for (std::uint32_t s = 0; s < surfaces_.size(); ++s) {
    const Surface& surface = surfaces_[s];
    if (!entering && surface.kind != BodyKind::tet) continue;  // a membrane has no inside
    // Leaving needs the tip inside: it entered that body more often than it
    // left (a tip pulled back out of a dent it pushed never entered).
    if (!entering) {
      int inside = 0;
      for (const Row& r : needle.rows)
        if (r.surface == s && (r.words[0] == SINEW_SUTURE_PUNCTURE || r.words[0] == SINEW_SUTURE_THREAD))
          inside += r.exit ? -1 : 1;
      if (inside <= 0) continue;
    }
    for (std::uint32_t t = 0; t < surface.triangles.size(); ++t) {
      const auto& tri = surface.triangles[t];
      const Vec3 A = position_of(tri[0]), B = position_of(tri[1]), C = position_of(tri[2]);
      bool apart = false;
      for (int k = 0; k < 3; ++k)
        apart |= std::max({A[k], B[k], C[k]}) < lo[k] || std::min({A[k], B[k], C[k]}) > hi[k];
      if (apart) continue;
      // The hole of a puncture the needle is in: its triangle and those
      // sharing a vertex with it (the tip leaves through them just after
      // puncturing). Holes on the thread no longer count: a later stitch
      // may pass close by.
      const bool held = std::any_of(needle.rows.begin(), needle.rows.end(), [&](const Row& r) {
        if (r.surface != s || r.words[0] != SINEW_SUTURE_PUNCTURE) return false;
        const auto& h = surface.triangles[r.triangle];
        for (std::uint32_t v : tri)
          if (v == h[0] || v == h[1] || v == h[2]) return true;
        return false;
      });
      if (held) continue;
      const Vec3 e1 = math::sub(B, A), e2 = math::sub(C, A);
      const Vec3 n = math::cross(e1, e2);  // outward on a tet body's surface
      const double longest = std::max({math::dot(e1, e1), math::dot(e2, e2), math::dot(math::sub(C, B), math::sub(C, B))});
      // A triangle with (next to) no area, within the path's box, has no
      // side and no barycentric point to hold: refused.
      if (!(math::norm(n) > 1e-6 * longest)) {
        ++needle.refused_degenerate;
        continue;
      }
      const double along = math::dot(dir, n);
      if (along == 0.0) continue;
      const double u = math::dot(math::sub(A, a), n) / along;
      if (!(u >= 0.0 && u <= 1.0)) continue;
      const Vec3 x = math::add(a, math::mul(dir, u));
      const Vec3 v2 = math::sub(x, A);
      const double d00 = math::dot(e1, e1), d01 = math::dot(e1, e2), d11 = math::dot(e2, e2);
      const double d20 = math::dot(v2, e1), d21 = math::dot(v2, e2);
      const double denominator = d00 * d11 - d01 * d01;
      const double wb = (d11 * d20 - d01 * d21) / denominator, wc = (d00 * d21 - d01 * d20) / denominator;
      const double wa = 1.0 - wb - wc;
      if (wa < 0.0 || wb < 0.0 || wc < 0.0) continue;
      // The path crosses it. A tet body's triangle whose tet is turned
      // inside out (its fourth vertex on the outer side) has no inside to
      // hold the point in: refused. Else it counts from its side.
      if (surface.opposite[t] != kNone && math::dot(n, math::sub(position_of(surface.opposite[t]), A)) >= 0.0) {
        ++needle.refused_inverted;
        continue;
      }
      if (surface.kind == BodyKind::tet && (entering ? along > 0.0 : along < 0.0)) continue;
      if (u >= best) continue;
      best = u;
      row.surface = s;
      row.triangle = t;
      row.words[2] = tri[0], row.words[3] = tri[1], row.words[4] = tri[2];
      row.weights = {float(wa), float(wb), float(wc), 0.0f};
    }
  }
  return best <= 1.0;
}

Status Sutures::read_positions(Device& device, const XpbdBuffers& scene_buffers) {
  if (mirror_) return mirror_->copy_to(device, scene_buffers.position, positions_.size(), positions_);
  if (Status s = device.read_buffer(scene_buffers.position, 0, positions_.data(), positions_.size() * 4); !s) return s;
  return {};
}

Status Sutures::before_frame(Device& device, const XpbdBuffers& scene_buffers) {
  if (Status s = read_positions(device, scene_buffers); !s) return s;
  for (std::size_t i = 0; i < needles_.size(); ++i) {
    Needle& n = needles_[i];
    if (n.desc.drive == NeedleDrive::force) {
      // Its pose at the frame's end, from the force on it and the last
      // frame's reaction (rigid_tool.h).
      integrate_tool(n.body, frame_, stiffness_);
      const double turn = turn_between(n.rotation_start, n.body.rotation);
      if (!(turn <= M_PI / 2) || !std::isfinite(math::norm(n.body.position)))
        return Error(ErrorCode::bad_parameter,
                     "needle " + std::to_string(i) + " (force-driven) would turn by " + std::to_string(turn) +
                         " rad in one frame; at most pi/2 (the torque on it is too large for its inertia and the "
                         "time step)");
      n.position_end = n.body.position;
      n.rotation_end = n.body.rotation;
    }
    std::erase_if(n.rows, [](const Row& r) { return r.words[0] == SINEW_SUTURE_TIP || r.words[0] == SINEW_SUTURE_BLUNT; });
    const std::vector<Vec3> start = curve_at(n, false), end = curve_at(n, true);
    const Vec3 d0 = unit(math::sub(start.back(), start[start.size() - 2]));
    const Vec3 d1 = unit(math::sub(end.back(), end[end.size() - 2]));
    Row tip;
    if (first_crossing(math::sub(start.back(), math::mul(d0, kTipReach)), math::add(end.back(), math::mul(d1, kTipReach)),
                       true, n, tip)) {
      tip.words[0] = SINEW_SUTURE_TIP;
      tip.words[1] = static_cast<std::uint32_t>(i);
      if (n.rows.size() >= kRowsPerNeedle)
        return Error(ErrorCode::capacity_exceeded, "needle " + std::to_string(i) + " holds more than " +
                                                       std::to_string(kRowsPerNeedle) + " punctures");
      n.rows.push_back(tip);
      if (n.desc.tip_radius > 0.0)
        if (Status s = add_blunt_rows(n, i, tip.surface, start.back(), end.back(), d0); !s) return s;
    }
    if (n.desc.shaft_friction > 0.0 || n.desc.shaft_static_friction > 0.0 || n.desc.shaft_viscous_friction > 0.0 ||
        n.desc.cutting_force > 0.0)
      set_shaft_lengths(n, start);
  }
  return upload(device);
}

Status Sutures::upload(Device& device) {
  std::vector<std::uint32_t> table{0};
  std::vector<std::uint32_t> words;
  std::vector<float> weights, curve;
  std::uint32_t first_point = 0;
  for (const Needle& n : needles_) {
    table.insert(table.end(), {first_point, static_cast<std::uint32_t>(n.desc.curve.size())});
    first_point += static_cast<std::uint32_t>(n.desc.curve.size());
    const std::vector<Vec3> start = curve_at(n, false), end = curve_at(n, true);
    for (std::size_t k = 0; k < start.size(); ++k)
      curve.insert(curve.end(), {float(start[k][0]), float(start[k][1]), float(start[k][2]), 0.0f, float(end[k][0]),
                                 float(end[k][1]), float(end[k][2]), 0.0f});
    for (const Row& r : n.rows) {
      words.insert(words.end(), r.words.begin(), r.words.end());
      weights.insert(weights.end(), r.weights.begin(), r.weights.end());
    }
  }
  table[0] = static_cast<std::uint32_t>(weights.size() / 4);
  if (Status s = device.write_buffer(buffers_.table, 0, table.data(), table.size() * 4); !s) return s;
  if (Status s = device.write_buffer(buffers_.curve, 0, curve.data(), curve.size() * 4); !s) return s;
  if (table[0] == 0) return {};
  if (Status s = device.write_buffer(buffers_.rows, 0, words.data(), words.size() * 4); !s) return s;
  if (Status s = device.write_buffer(buffers_.weights, 0, weights.data(), weights.size() * 4); !s) return s;
  // The multipliers start at zero; a puncture's slide speed carries over.
  std::vector<float> lambda(std::size_t{table[0]} * 12, 0.0f);
  std::size_t k = 0;
  for (const Needle& n : needles_)
    for (const Row& r : n.rows) lambda[12 * k++ + 2] = r.slip;
  return device.write_buffer(buffers_.lambda, 0, lambda.data(), lambda.size() * 4);
}

Status Sutures::after_frame(Device& device, const XpbdBuffers& scene_buffers, double h, double frame) {
  std::size_t rows = 0;
  for (const Needle& n : needles_) rows += n.rows.size();
  std::vector<std::uint32_t> words(rows * 8);
  std::vector<float> weights(rows * 4), lambda(rows * 12);
  if (rows > 0) {
    if (Status s = device.read_buffer(buffers_.rows, 0, words.data(), words.size() * 4); !s) return s;
    if (Status s = device.read_buffer(buffers_.weights, 0, weights.data(), weights.size() * 4); !s) return s;
    if (Status s = device.read_buffer(buffers_.lambda, 0, lambda.data(), lambda.size() * 4); !s) return s;
  }
  if (Status s = read_positions(device, scene_buffers); !s) return s;
  std::size_t at = 0;
  for (std::size_t i = 0; i < needles_.size(); ++i) {
    Needle& n = needles_[i];
    const std::vector<Vec3> start = curve_at(n, false), end = curve_at(n, true);
    const Vec3 tip = end.back(), d = unit(math::sub(end.back(), end[end.size() - 2]));
    n.tip_force = 0.0;
    for (std::size_t k = 0; k < n.rows.size(); ++k) {
      n.rows[k].slip = lambda[(at + k) * 12 + 2];
      std::copy_n(&words[(at + k) * 8], 8, n.rows[k].words.begin());
      std::copy_n(&weights[(at + k) * 4], 4, n.rows[k].weights.begin());
    }
    add_reactions(n, end, &lambda[at * 12], h, frame);
    if (n.desc.drive == NeedleDrive::kinematic) {  // its motion over the frame, for NeedleState
      n.body.velocity = math::mul(math::sub(n.position_end, n.position_start), 1.0 / frame);
      n.body.angular_velocity = math::angular_velocity(n.rotation_start, n.rotation_end, frame);
      n.body.position = n.position_end;
      n.body.rotation = n.rotation_end;
    }
    // A blunt tip's rows push with the tip contact (their impulse counts
    // towards the puncture) and are made afresh every frame.
    Vec3 blunt{0.0, 0.0, 0.0};
    for (std::size_t k = 0; k < n.rows.size(); ++k) {
      if (n.rows[k].words[0] != SINEW_SUTURE_BLUNT) continue;
      const float* l = &lambda[(at + k) * 12];
      blunt = math::add(blunt, Vec3{double(l[8]) + l[4], double(l[9]) + l[5], double(l[10]) + l[6]});
      n.rows[k].words[0] = SINEW_SUTURE_DEAD;
    }
    for (Row& r : n.rows) {
      const float* l = &lambda[at * 12];
      ++at;
      if (r.words[0] == SINEW_SUTURE_TIP) {
        const auto& tri = surfaces_[r.surface].triangles[r.triangle];
        const Vec3 A = position_of(tri[0]);
        const Vec3 normal = unit(math::cross(math::sub(position_of(tri[1]), A), math::sub(position_of(tri[2]), A)));
        // The frame's impulse on the tissue, (sum + last) / h [N s], averaged
        // over the frame, into the surface (the kernel pushes along the
        // normal turned the way the tip goes).
        const Vec3 own{double(l[8]) + l[4], double(l[9]) + l[5], double(l[10]) + l[6]};
        const Vec3 impulse = n.desc.tip_radius > 0.0 ? math::add(own, blunt) : own;
        n.tip_force = std::abs(math::dot(impulse, normal)) / (h * frame);
        if (n.tip_force < n.desc.puncture_force) continue;
        // The angle to the inward normal (a membrane's: the side the tip is on).
        const double cosine = surfaces_[r.surface].kind == BodyKind::tet ? -math::dot(d, normal)
                                                                         : std::abs(math::dot(d, normal));
        if (cosine < std::cos(n.desc.max_puncture_angle)) {
          ++n.refused_angle;
          continue;
        }
        r.words[0] = SINEW_SUTURE_PUNCTURE;
        r.words[5] = n.thread_first, r.words[6] = n.thread_vertices;
      } else if (r.words[0] == SINEW_SUTURE_PUNCTURE) {
        // Pulled back out: the tissue point ahead of the tip, past its last segment.
        const Vec3 p = point_of(r);
        const Vec3 e = math::sub(end.back(), end[end.size() - 2]);
        const double u = math::dot(math::sub(p, end[end.size() - 2]), e) / math::dot(e, e);
        if (u > 1.0 && math::dot(d, math::sub(p, tip)) > kPulledOut) r.words[0] = SINEW_SUTURE_DEAD;
      }
    }
    std::erase_if(n.rows, [](const Row& r) { return r.words[0] == SINEW_SUTURE_DEAD; });
    n.position_start = n.position_end;  // the next frame starts where this one ended
    n.rotation_start = n.rotation_end;
    // Leaving a tet body: its surface crossed from inside by the tip's path.
    Row exit;
    if (first_crossing(start.back(), end.back(), false, n, exit)) {
      if (n.rows.size() >= kRowsPerNeedle)
        return Error(ErrorCode::capacity_exceeded, "needle " + std::to_string(i) + " holds more than " +
                                                       std::to_string(kRowsPerNeedle) + " punctures");
      exit.words[0] = SINEW_SUTURE_PUNCTURE;
      exit.words[1] = static_cast<std::uint32_t>(i);
      exit.words[5] = n.thread_first, exit.words[6] = n.thread_vertices;
      exit.exit = true;
      n.rows.push_back(exit);
    }
  }
  mark_exemption();
  return {};
}

void Sutures::add_reactions(Needle& n, const std::vector<Vec3>& end, const float* lambda, double h, double frame) {
  ToolBody& b = n.body;
  n.reaction_force = n.reaction_torque = Vec3{0.0, 0.0, 0.0};
  b.coupling_force = b.coupling_torque = Vec3{0.0, 0.0, 0.0};
  b.touching_mass = 0.0;
  b.touching_inertia = {};
  const Vec3 origin = n.position_end;
  for (std::size_t k = 0; k < n.rows.size(); ++k) {
    const Row& r = n.rows[k];
    const std::uint32_t kind = r.words[0];
    if (kind != SINEW_SUTURE_TIE && kind != SINEW_SUTURE_TIP && kind != SINEW_SUTURE_PUNCTURE &&
        kind != SINEW_SUTURE_BLUNT)
      continue;
    const float* l = lambda + 12 * k;  // (lambda, lambda_t), the last substep's impulse, the earlier ones'
    // Where the row pulls the needle: its tail (the tie), its tip, or the
    // curve's closest point to the tissue point (a puncture).
    Vec3 point = kind == SINEW_SUTURE_TIE ? end.front() : end.back();
    if (kind == SINEW_SUTURE_PUNCTURE) {
      const Vec3 p = point_of(r);
      double best = INFINITY;
      for (std::size_t j = 0; j + 1 < end.size(); ++j) {
        const Vec3 e = math::sub(end[j + 1], end[j]);
        const double u = std::clamp(math::dot(math::sub(p, end[j]), e) / math::dot(e, e), 0.0, 1.0);
        const Vec3 q = math::add(end[j], math::mul(e, u));
        const double d = math::norm(math::sub(p, q));
        if (d < best) best = d, point = q;
      }
    }
    if (kind == SINEW_SUTURE_BLUNT) {  // on the flat end, across the axis from the tip
      const Vec3 axis = unit(math::sub(end.back(), end[end.size() - 2]));
      const Vec3 off = math::sub(position_of(r.words[2]), end.back());
      point = math::add(end.back(), math::sub(off, math::mul(axis, math::dot(axis, off))));
    }
    const Vec3 arm = math::sub(point, origin);
    // The tissue (or thread vertex) was moved by the impulse lambda; the
    // needle takes the opposite: per substep lambda / h [N s].
    const Vec3 last{l[4], l[5], l[6]};
    const Vec3 all = math::add(last, Vec3{l[8], l[9], l[10]});
    const Vec3 frame_impulse = math::mul(all, -1.0 / h), last_impulse = math::mul(last, -1.0 / h);
    n.reaction_force = math::add(n.reaction_force, math::mul(frame_impulse, 1.0 / frame));
    n.reaction_torque = math::add(n.reaction_torque, math::mul(math::cross(arm, frame_impulse), 1.0 / frame));
    b.coupling_force = math::add(b.coupling_force, math::mul(last_impulse, 1.0 / h));
    b.coupling_torque = math::add(b.coupling_torque, math::mul(math::cross(arm, last_impulse), 1.0 / h));
    if ((kind == SINEW_SUTURE_TIP || kind == SINEW_SUTURE_BLUNT) && !(l[0] > 0.0f))
      continue;  // not pushing at the frame's end
    // The particles it holds stand in for a tool's touching particles
    // (their mass c / w and its inertia about the needle's origin).
    const std::uint32_t count = kind == SINEW_SUTURE_TIE ? 1 : 3;
    for (std::uint32_t v = 0; v < count; ++v) {
      const double c = kind == SINEW_SUTURE_TIE ? 1.0 : double(r.weights[v]);
      const std::size_t at = std::size_t{r.words[2 + v]} * 4;
      const double w = positions_[at + 3];
      if (!(c > 0.0) || !(w > 0.0)) continue;
      const double m = c / w;
      const Vec3 rk = math::sub(position_of(r.words[2 + v]), origin);
      b.touching_mass += m;
      const double r2 = math::dot(rk, rk);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) b.touching_inertia[std::size_t(3 * i + j)] += m * ((i == j ? r2 : 0.0) - rk[i] * rk[j]);
    }
  }
  b.contact_force = n.reaction_force;
  b.contact_torque = n.reaction_torque;
}

Status Sutures::add_blunt_rows(Needle& n, std::size_t index, std::uint32_t surface_index, const Vec3& tip_start,
                               const Vec3& tip_end, const Vec3& axis) {
  // Every surface vertex of the pushed body within tip_radius of the tip's
  // axis, on a triangle facing the tip (a tet body's outward normal against
  // the axis; a membrane either way), from just behind the rounded end at
  // the frame's start to a radius past the tip at its end: the tissue the
  // end may meet in this frame. A
  // vertex it does not reach keeps an idle row (a unilateral C > 0).
  const Surface& surface = surfaces_[surface_index];
  const double radius = n.desc.tip_radius;
  const double reach = math::dot(axis, math::sub(tip_end, tip_start)) + radius;
  std::vector<std::uint32_t> vertices;
  for (const auto& tri : surface.triangles) {
    const Vec3 A = position_of(tri[0]);
    const Vec3 outward = math::cross(math::sub(position_of(tri[1]), A), math::sub(position_of(tri[2]), A));
    if (surface.kind == BodyKind::tet && !(math::dot(outward, axis) < 0.0)) continue;
    for (std::uint32_t v : tri) {
      const Vec3 off = math::sub(position_of(v), tip_start);
      const double along = math::dot(axis, off);
      const double across = math::norm(math::sub(off, math::mul(axis, along)));
      if (across > n.desc.tip_radius) continue;
      // The rounded end at `across` from the axis is this far behind the tip.
      const double setback = radius - std::sqrt(radius * radius - across * across);
      if (along < -setback - kTipReach || along > reach) continue;
      vertices.push_back(v);
    }
  }
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  if (n.rows.size() + vertices.size() > kRowsPerNeedle)
    return Error(ErrorCode::capacity_exceeded,
                 "needle " + std::to_string(index) + ": its blunt tip (tip_radius " + std::to_string(n.desc.tip_radius) +
                     " m) meets " + std::to_string(vertices.size()) + " surface vertices, more than its " +
                     std::to_string(kRowsPerNeedle) + " rows hold with its punctures (a smaller radius, or a "
                     "coarser surface)");
  for (std::uint32_t v : vertices) {
    Row row;
    row.words = {SINEW_SUTURE_BLUNT, static_cast<std::uint32_t>(index), v, v, v, 0, 0, 0};
    row.weights = {1.0f, 0.0f, 0.0f, 0.0f};
    row.surface = surface_index;
    n.rows.push_back(row);
  }
  return {};
}

void Sutures::set_shaft_lengths(Needle& n, const std::vector<Vec3>& curve) {
  // Each puncture's place along the needle (arc length from the tail [m]).
  std::vector<double> arc(n.rows.size(), 0.0);
  double total = 0.0;
  for (std::size_t j = 0; j + 1 < curve.size(); ++j) total += math::norm(math::sub(curve[j + 1], curve[j]));
  for (std::size_t k = 0; k < n.rows.size(); ++k) {
    if (n.rows[k].words[0] != SINEW_SUTURE_PUNCTURE) continue;
    const Vec3 p = point_of(n.rows[k]);
    double best = INFINITY, before = 0.0;
    for (std::size_t j = 0; j + 1 < curve.size(); ++j) {
      const Vec3 e = math::sub(curve[j + 1], curve[j]);
      const double length = math::norm(e);
      const double u = std::clamp(math::dot(math::sub(p, curve[j]), e) / (length * length), 0.0, 1.0);
      const double d = math::norm(math::sub(p, math::add(curve[j], math::mul(e, u))));
      if (d < best) best = d, arc[k] = before + u * length;
      before += length;
    }
  }
  // An entering puncture of a tet body grips the shaft from its point to
  // the body's next exit along the needle, or to the tip: the length the
  // shaft's friction scales with. The tip is inside the body whose entry
  // has no exit beyond it: that row also carries the cutting force. Exit
  // punctures and membranes (no inside) grip nothing.
  for (std::size_t k = 0; k < n.rows.size(); ++k) {
    Row& r = n.rows[k];
    if (r.words[0] != SINEW_SUTURE_PUNCTURE) continue;
    r.words[7] = 0;
    r.weights[3] = 0.0f;
    if (r.exit || surfaces_[r.surface].kind != BodyKind::tet) continue;
    double out = total;
    for (std::size_t j = 0; j < n.rows.size(); ++j)
      if (n.rows[j].words[0] == SINEW_SUTURE_PUNCTURE && n.rows[j].exit && n.rows[j].surface == r.surface &&
          arc[j] > arc[k])
        out = std::min(out, arc[j]);
    r.weights[3] = float(std::max(0.0, out - arc[k]));
    r.words[7] = out == total ? 1u : 0u;
  }
}

void Sutures::mark_exemption() {
  exempt_.assign(positions_.size() / 4, 0);
  for (const Needle& n : needles_) {
    bool holds = false;
    for (const Row& r : n.rows) {
      if (r.words[0] != SINEW_SUTURE_PUNCTURE && r.words[0] != SINEW_SUTURE_THREAD) continue;
      holds = true;
      // The hole: every triangle of the surface sharing a vertex with the punctured one.
      const Surface& surface = surfaces_[r.surface];
      const auto& hole = surface.triangles[r.triangle];
      for (const auto& t : surface.triangles)
        for (std::uint32_t v : t)
          if (v == hole[0] || v == hole[1] || v == hole[2]) {
            for (std::uint32_t u : t) exempt_[u] |= kSutureHole;
            break;
          }
    }
    if (holds)
      for (std::uint32_t k = 0; k < n.thread_vertices; ++k) exempt_[slots_[n.thread_first + k]] |= kSutureThread;
  }
}

NeedleState Sutures::state(std::size_t index) const {
  const Needle& n = needles_[index];
  NeedleState out;
  out.position = n.position_start;
  out.rotation = n.rotation_start;
  out.velocity = n.body.velocity;
  out.angular_velocity = n.body.angular_velocity;
  out.reaction_force = n.reaction_force;
  out.reaction_torque = n.reaction_torque;
  out.tip_force = n.tip_force;
  out.refused_degenerate = n.refused_degenerate;
  out.refused_inverted = n.refused_inverted;
  out.refused_angle = n.refused_angle;
  for (const Row& r : n.rows) {
    if (r.words[0] == SINEW_SUTURE_TIP) out.pushing = true;
    if (r.words[0] != SINEW_SUTURE_PUNCTURE && r.words[0] != SINEW_SUTURE_THREAD) continue;
    Puncture p;
    p.body_kind = surfaces_[r.surface].kind;
    p.body = surfaces_[r.surface].body;
    p.triangle = r.triangle;
    p.weights = {r.weights[0], r.weights[1], r.weights[2]};
    p.exit = r.exit;
    p.on_thread = r.words[0] == SINEW_SUTURE_THREAD;
    // (A puncture on the needle keeps its cutting flag and shaft length there.)
    p.thread_segment = p.on_thread ? r.words[7] : 0;
    p.thread_s = p.on_thread ? r.weights[3] : 0.0;
    out.punctures.push_back(p);
  }
  return out;
}

}  // namespace sinew
