// suture_scene.cpp — the S3 suture scene (suture_scene.h). The stitch and the
// knot as examples/suturing.cpp makes them (docs/needles.md); the thread's
// continuous collision: Bridson, Fedkiw and Anderson, "Robust treatment of
// collisions, contact and friction for cloth animation", SIGGRAPH 2002
// (docs/collision.md).
#include "suture_scene.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "sinew/mesh.h"

namespace sinew::examples {

namespace {

constexpr double kRadius = kSutureNeedleRadius, kAbove = kSutureNeedleAbove;
constexpr double kSlit = 0.002;              // the slit's width [m]
constexpr double kThreadLength = 0.1;        // [m]
constexpr double kThreadMass = 1e-3;         // the whole thread [kg]
constexpr const double (&kStitchZ)[2] = kSutureStitchZ;
// The pull: up and away from the cut at this speed [m per frame] until the
// knot holds at the first puncture, then kTighten frames more, then held for
// kHold frames; at most kMostPull frames to reach the knot.
constexpr double kPullSpeed = 4.25e-4;
constexpr int kTighten = 10, kHold = 30, kMostPull = 500;
constexpr int kStitched = kSutureStitchFrames;

Error bad(const std::string& what) { return Error(ErrorCode::bad_parameter, "suture scene: " + what); }

double segment_distance(const float* p0, const float* p1, const float* q0, const float* q1);

}  // namespace

SutureNeedlePose suture_script(int f, double pulled) {
  constexpr int turn = kSutureTurnFrames, second = kSutureTurnFrames + kSutureShiftFrames;
  constexpr double last_angle = 2.0 * M_PI - 0.2;  // a turn short of the whole circle: the tip stays outside
  if (f < turn) return {{0.0, kAbove, kStitchZ[0]}, last_angle * (f + 1) / turn};
  if (f < second) {  // over to the second stitch, the tip above the left lip
    const double u = double(f - turn + 1) / kSutureShiftFrames;
    return {{0.0, kAbove, kStitchZ[0] + u * (kStitchZ[1] - kStitchZ[0])}, last_angle};
  }
  if (f < kStitched) return {{0.0, kAbove, kStitchZ[1]}, last_angle + last_angle * (f - second + 1) / turn};
  return {{0.5 * pulled, kAbove + pulled, kStitchZ[1]}, 2.0 * last_angle};  // up and away from the cut
}

Result<SutureScene> SutureScene::create(const SutureSettings& settings) {
  const SutureSettings& s = settings;
  if (!(s.cell > 0.0 && std::isfinite(s.cell))) return bad("cell must be finite and > 0");
  const double slit_cells = kSlit / s.cell;
  if (std::abs(slit_cells - std::round(slit_cells)) > 1e-6)
    return bad("the 2 mm slit must be a whole number of cells (cell = " + std::to_string(s.cell) + " m)");
  // The needle enters sqrt(R^2 - kAbove^2) = 7.75 mm either side of the cut
  // and reaches kRadius - kAbove = 6 mm deep: the pad must hold both.
  if (s.nx * s.cell / 2 < 0.009 || s.ny * s.cell < 0.007 || s.nz * s.cell / 2 < 0.007 ||
      (s.nx - int(std::lround(slit_cells))) % 2 != 0)
    return bad("the pad must reach 9 mm either side of the cut, 7 mm deep and 7 mm along z, the slit in its middle (nx - slit cells even)");
  if (s.thread_segments < 2) return bad("thread_segments must be >= 2");

  SutureScene self;
  self.settings_ = s;
  auto grid = make_tet_grid({.nx = s.nx, .ny = s.ny, .nz = s.nz,
                             .origin = {-s.nx * s.cell / 2, -s.ny * s.cell, -s.nz * s.cell / 2},
                             .cell_size = {s.cell, s.cell, s.cell}});
  if (!grid) return grid.error();
  TetMesh pad = std::move(*grid);
  // The cut: the slit's cells removed above the bottom layer. Every vertex
  // stays used (the slit's faces are the vertex planes either side of it).
  const double bottom = -(s.ny - 1) * s.cell;
  std::erase_if(pad.tets, [&](const std::array<std::uint32_t, 4>& t) {
    double x = 0.0, y = 0.0;
    for (std::uint32_t v : t) x += pad.vertices[v][0] / 4, y += pad.vertices[v][1] / 4;
    return std::abs(x) < kSlit / 2 && y > bottom;
  });

  SceneDesc& scene = self.scene_;
  scene.gravity = {0.0, 0.0, 0.0};  // on a table
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = s.substeps;
  scene.solver.iterations = s.iterations;
  TetBodyDesc body;
  body.mesh = pad;
  if (auto st = body.set_elastic(s.young, 0.45); !st) return st.error();
  body.velocity_damping = 5.0;
  const double half = s.nx * s.cell / 2;
  for (std::uint32_t v = 0; v < pad.vertices.size(); ++v) {
    const auto& p = pad.vertices[v];
    if (std::abs(std::abs(p[0]) - half) < 1e-9 || p[1] < -s.ny * s.cell + 1e-9) body.pinned.push_back(v);
    // The slit's faces at the stitches' depth (the needle's deepest point)
    // and at the stitches' z: where the gap is measured.
    const double deepest = kAbove - kRadius;
    if (std::abs(p[1] - std::round(deepest / s.cell) * s.cell) > 1e-9) continue;
    bool at_stitch = false;
    for (double z : kStitchZ) at_stitch |= std::abs(p[2] - std::round(z / s.cell) * s.cell) < 1e-9;
    if (!at_stitch) continue;
    if (std::abs(p[0] + kSlit / 2) < 1e-9) self.left_face_.push_back(v);
    if (std::abs(p[0] - kSlit / 2) < 1e-9) self.right_face_.push_back(v);
  }
  if (self.left_face_.empty() || self.left_face_.size() != self.right_face_.size())
    return bad("the slit's faces have no vertices at the stitches' depth");
  for (const auto& t : extract_boundary_surface(pad).triangles) {
    std::array<double, 3> c{};
    for (std::uint32_t v : t)
      for (int k = 0; k < 3; ++k) c[k] += pad.vertices[v][k] / 3;
    self.surface_points_.push_back(c);
  }
  scene.tet_bodies.push_back(std::move(body));

  NeedleDesc needle;
  for (int i = 0; i <= 16; ++i)
    needle.curve.push_back({kRadius * std::cos(M_PI * i / 16), kRadius * std::sin(M_PI * i / 16), 0.0});
  needle.position = {0.0, kAbove, kStitchZ[0]};
  needle.puncture_force = 0.01;
  needle.thread = 0;
  // The thread hangs straight up from the needle's tail.
  LineBodyDesc thread;
  const double piece = kThreadLength / s.thread_segments;
  for (int i = 0; i <= s.thread_segments; ++i) {
    thread.vertices.push_back({kRadius, kAbove + piece * i, kStitchZ[0]});
    thread.masses.push_back(kThreadMass / (s.thread_segments + 1));
    if (i < s.thread_segments) thread.segments.push_back({std::uint32_t(i), std::uint32_t(i + 1)});
  }
  thread.bending_compliance = 10.0;
  thread.velocity_damping = 5.0;
  scene.line_bodies.push_back(std::move(thread));
  scene.needles.push_back(needle);
  // The thread against itself and the tissue: contacts and CCD (the pad's
  // own self-collision off: its lips stay apart, and its surface is the
  // scene's largest cost to test against itself).
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 5e-4;
  scene.mesh_collision.self_collision = false;
  scene.mesh_collision.continuous = s.continuous;

  auto sim = Simulation::create(scene, {.backend = s.backend, .threads = s.threads, .quiet = true});
  if (!sim) return sim.error();
  self.sim_.emplace(std::move(*sim));
  return self;
}

Status SutureScene::frame() {
  if (done()) return bad("the script is over");
  auto needles = sim_->needles();
  auto id = needles.needle(0);
  if (!id) return id.error();
  const SutureNeedlePose p = suture_script(frames_, pulled_);
  const std::array<double, 4> q{std::cos(p.angle / 2), 0.0, 0.0, std::sin(p.angle / 2)};
  if (auto st = needles.set_pose(*id, p.position, q); !st) return st;
  if (auto st = sim_->step(); !st) return st;
  const int f = frames_++;
  if (f < kStitched) return {};
  // The pull: until the knot holds at the first puncture, then kTighten frames more.
  auto state = needles.state(*id);
  if (!state) return state.error();
  const bool knotted = !state->punctures.empty() && state->punctures[0].on_thread &&
                       int(state->punctures[0].thread_segment) + 1 == settings_.thread_segments;
  if (knot_frame_ < 0 && knotted) knot_frame_ = f, last_ = f + kTighten + kHold;
  if (knot_frame_ < 0 && f - kStitched >= kMostPull)
    return bad("the knot never reached the first puncture in " + std::to_string(kMostPull) + " frames of pulling");
  if (knot_frame_ < 0 || f < knot_frame_ + kTighten) pulled_ += kPullSpeed;
  return {};
}

Status SutureScene::read() { return sim_->read_positions(x_); }

Result<double> SutureScene::gap() {
  if (auto st = read(); !st) return st.error();
  const std::uint32_t first = sim_->info().tet_body_first_particle[0];
  double sum = 0.0;
  for (std::size_t k = 0; k < left_face_.size(); ++k)
    sum += x_[4 * (first + right_face_[k])] - x_[4 * (first + left_face_[k])];
  return sum / double(left_face_.size());
}

Result<SutureCheck> SutureScene::check() {
  SutureCheck c;
  auto g = gap();  // reads the positions
  if (!g) return g.error();
  c.gap = *g;
  for (float v : x_) c.finite = c.finite && std::isfinite(v);
  auto needles = sim_->needles();
  auto id = needles.needle(0);
  if (!id) return id.error();
  auto state = needles.state(*id);
  if (!state) return state.error();
  c.punctures = state->punctures.size();
  for (const auto& h : state->punctures) {
    if (h.triangle >= surface_points_.size()) return bad("a puncture names a triangle the pad does not have");
    (surface_points_[h.triangle][0] < 0.0 ? c.left_lip : c.right_lip) += 1;
    c.on_thread += h.on_thread;
  }
  c.knot_holds = !state->punctures.empty() && state->punctures[0].on_thread &&
                 int(state->punctures[0].thread_segment) + 1 == settings_.thread_segments;
  // Every pair of thread segments that shares no vertex (brute force: 2 x 10^4 pairs).
  const std::uint32_t t0 = sim_->info().line_body_first_particle[0];
  const int n = settings_.thread_segments;
  c.thread_min_distance = INFINITY;
  for (int i = 0; i < n; ++i)
    for (int j = i + 2; j < n; ++j) {
      const float* a = &x_[4 * (t0 + i)];
      const float* b = &x_[4 * (t0 + j)];
      const double d = segment_distance(a, a + 4, b, b + 4);
      if (d < c.thread_min_distance) c.thread_min_distance = d, c.thread_closest = {i, j};
    }
  return c;
}

namespace {

// The distance between segments p0p1 and q0q1 (Ericson, "Real-Time Collision
// Detection", 2005, 5.1.9: the closest points' parameters clamped to [0, 1]).
double segment_distance(const float* p0, const float* p1, const float* q0, const float* q1) {
  double d1[3], d2[3], r[3];
  for (int k = 0; k < 3; ++k) d1[k] = p1[k] - p0[k], d2[k] = q1[k] - q0[k], r[k] = p0[k] - q0[k];
  auto dot = [](const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r), c = dot(d1, r), b = dot(d1, d2);
  const double denom = a * e - b * b;
  double s = a > 0.0 && denom > 1e-30 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  double t = e > 0.0 ? (b * s + f) / e : 0.0;
  if (t < 0.0) t = 0.0, s = a > 0.0 ? std::clamp(-c / a, 0.0, 1.0) : 0.0;
  else if (t > 1.0) t = 1.0, s = a > 0.0 ? std::clamp((b - c) / a, 0.0, 1.0) : 0.0;
  double d = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double w = r[k] + d1[k] * s - d2[k] * t;
    d += w * w;
  }
  return std::sqrt(d);
}

}  // namespace

}  // namespace sinew::examples
