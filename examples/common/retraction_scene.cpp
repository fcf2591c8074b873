// retraction_scene.cpp — the S1 retraction scene (retraction_scene.h).
// The virtual coupling that renders the tools' forces: Colgate, Stanley and
// Brown, "Issues in the haptic display of tool use", IROS 1995.
#include "retraction_scene.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "sinew/graspers.h"
#include "sinew/mesh.h"
#include "sinew/tools.h"

namespace sinew::examples {

namespace {

using V3 = std::array<double, 3>;
using Q4 = std::array<double, 4>;

V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
// v rotated by unit quaternion q (w, x, y, z): v + 2 u x (u x v + w v).
V3 rotate(const Q4& q, const V3& v) {
  const V3 u{q[1], q[2], q[3]};
  const V3 t = add(cross(u, v), {q[0] * v[0], q[0] * v[1], q[0] * v[2]});
  const V3 c = cross(u, t);
  return {v[0] + 2 * c[0], v[1] + 2 * c[1], v[2] + 2 * c[2]};
}
Q4 conjugate(const Q4& q) { return {q[0], -q[1], -q[2], -q[3]}; }
V3 particle(const std::vector<float>& x, std::uint32_t i) { return {x[4 * i], x[4 * i + 1], x[4 * i + 2]}; }

// Smooth 0 -> 1 over [a, b] (a cosine ramp: zero velocity at both ends).
double ramp(double t, double a, double b) {
  if (t <= a) return 0.0;
  if (t >= b) return 1.0;
  return 0.5 - 0.5 * std::cos(M_PI * (t - a) / (b - a));
}

// The tools. The shaft carries the jaws below it; the probe's axis is along z
// (its tool frame's y axis turned 90 degrees about x).
constexpr double kShaftRadius = 0.003, kShaftHalfHeight = 0.015;
constexpr double kProbeRadius = 0.005, kProbeHalfHeight = 0.015;
constexpr double kToolMass = 0.3;          // [kg] each, heavy against the tissue's ~20 mg particles
constexpr V3 kJawHalf{0.003, 0.0025, 0.003};  // [m]
constexpr double kHoldStiffness = 600.0;   // [N/m], all the holds together (the pull is read from these springs)
constexpr double kPinDepth = 0.008;        // [m]
constexpr Q4 kProbeRotation{M_SQRT1_2, M_SQRT1_2, 0.0, 0.0};

ToolDesc capsule_tool(double radius, double half_height, const V3& position, const Q4& rotation) {
  ToolDesc t;
  t.radius = radius;
  t.half_height = half_height;
  t.mass = kToolMass;
  // The whole instrument's inertia, its handle included [kg m^2]. Why not the
  // capsule's own (m r^2 / 2 = 1.4e-6 about its axis): the bridge's angular
  // damping acts explicitly, stable while damping x dt / I < 2 (here 0.33).
  t.inertia = {1e-4, 1e-4, 1e-4};
  t.position = position;
  t.rotation = rotation;
  t.gravity = false;  // the hand carries the instrument
  t.static_friction = 0.4;
  t.dynamic_friction = 0.3;
  return t;
}

// The kidney at rest under gravity on its pins: kSettleFrames frames of the
// body alone, damped by kSettleDamping. Why: released from its rest shape the
// organ drops and swings (~1 m/s in its first 0.2 s at 10 kPa), and mesh
// collision's motion margin (2 |v|max dt) then spans centimetres: millions of
// candidate pairs a frame. An organ in a body starts at rest.
constexpr int kSettleFrames = 90;
constexpr double kSettleDamping = 20.0;  // [1/s]

Result<std::vector<Vec3d>> settle(const TetBodyDesc& body, const RetractionSettings& settings) {
  SceneDesc scene;
  scene.gravity = {0.0, -9.81, 0.0};
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = settings.substeps, .iterations = settings.iterations,
                  .measure_errors = false};
  scene.tet_bodies.push_back(body);
  scene.tet_bodies[0].velocity_damping = kSettleDamping;
  auto sim = Simulation::create(scene, {.backend = settings.backend, .threads = settings.threads, .quiet = true});
  if (!sim) return sim.error();
  for (int f = 0; f < kSettleFrames; ++f)
    if (auto st = sim->step(); !st) return st.error();
  std::vector<float> x;
  if (auto st = sim->read_positions(x); !st) return st.error();
  std::vector<Vec3d> out(x.size() / 4);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {x[4 * i], x[4 * i + 1], x[4 * i + 2]};
  return out;
}

}  // namespace

Result<std::unique_ptr<RetractionScene>> RetractionScene::create(const RetractionSettings& settings) {
  std::unique_ptr<RetractionScene> self(new RetractionScene());
  RetractionScene& s = *self;
  s.settings_ = settings;
  if (!(settings.probe_force >= 0.0 && std::isfinite(settings.probe_force)))
    return Error(ErrorCode::bad_parameter,
                 "retraction: probe_force must be finite and >= 0 (got " + std::to_string(settings.probe_force) + ")");
  if (!(settings.script_speed > 0.0 && std::isfinite(settings.script_speed)))
    return Error(ErrorCode::bad_parameter,
                 "retraction: script_speed must be finite and > 0 (got " + std::to_string(settings.script_speed) + ")");
  auto mesh = read_tet_mesh(settings.mesh);
  if (!mesh) return mesh.error();
  scale_mesh(*mesh, 1e-3);  // millimetres -> metres

  TetBodyDesc body;
  body.mesh = std::move(*mesh);
  body.density = 1060.0;  // [kg/m^3]
  if (auto st = body.set_material(TetMaterial::corotational, settings.young, settings.poisson); !st) return st.error();
  // Pinned along one side, its back (as a kidney lies on the abdominal wall):
  // the surface within kPinDepth of the lowest z. Why not a thin strip, as
  // organ_step's 5 mm of the lowest x: that cap carries the 0.3 kg organ's
  // weight at a stress above a 10 kPa modulus, and its tets invert.
  const auto& v = body.mesh.vertices;
  double lo = 1e30;
  for (const auto& p : v) lo = std::min(lo, p[2]);
  // Only the surface's vertices (the organ's capsule held to the wall): a pin
  // set cut through the volume by a plane leaves tets whose free vertex lies a
  // hair off their pinned face, which invert at once under the weight.
  std::vector<char> on_surface(v.size(), 0);
  for (const auto& f : extract_boundary_surface(body.mesh).triangles)
    for (std::uint32_t i : f) on_surface[i] = 1;
  std::vector<char> pin(v.size(), 0);
  for (std::uint32_t i = 0; i < v.size(); ++i) pin[i] = on_surface[i] && v[i][2] < lo + kPinDepth;
  // Then every vertex of a tet with three pinned vertices: its free fourth
  // vertex may lie a hair off their face, and flips across it and back each
  // substep (measured: 1-5 mm a frame at 16 substeps, which made mesh
  // collision's motion margin 10-37 mm for the whole surface, ~10^5 candidate
  // pairs a frame, and most of the inverted tets; with them pinned the fastest
  // vertex moves 0.06 mm a frame and the margin is 1.5 mm).
  {
    std::vector<char> more = pin;
    for (const auto& t : body.mesh.tets) {
      int n = 0;
      for (auto q : t) n += pin[q];
      if (n >= 3) for (auto q : t) more[q] = 1;
    }
    pin = more;
  }
  for (std::uint32_t i = 0; i < v.size(); ++i)
    if (pin[i]) body.pinned.push_back(i);
  auto settled = settle(body, settings);
  if (!settled) return settled.error();
  body.initial_vertices = std::move(*settled);
  const auto& x0 = body.initial_vertices;
  std::uint32_t pole = 0, side = 0;
  for (std::uint32_t i = 0; i < x0.size(); ++i) {
    if (x0[i][1] > x0[pole][1]) pole = i;
    if (x0[i][2] > x0[side][2]) side = i;
  }
  // The holds' compliance: their springs together kHoldStiffness, so that the
  // shaft (kToolMass) stays stable under their explicit pull at 60 Hz
  // (sqrt(k / M) dt = 0.75). The jaws' box holds the vertices inside it.
  std::size_t inside = 0;
  for (const auto& p : x0) {
    const V3 d = sub(p, x0[pole]);
    inside += std::abs(d[0]) <= kJawHalf[0] && std::abs(d[1]) <= kJawHalf[1] && std::abs(d[2]) <= kJawHalf[2];
  }
  s.hold_compliance_ = double(std::max<std::size_t>(inside, 1)) / kHoldStiffness;
  s.tets_ = body.mesh.tets;
  for (const auto& t : s.tets_) {
    const V3 a = sub(v[t[1]], v[t[0]]), b = sub(v[t[2]], v[t[0]]), c = sub(v[t[3]], v[t[0]]);
    const V3 ab = cross(a, b);
    s.rest_sign_.push_back(ab[0] * c[0] + ab[1] * c[1] + ab[2] * c[2] > 0 ? 1.0 : -1.0);
  }
  const V3 pole_x = x0[pole], side_x = x0[side];

  SceneDesc& scene = s.scene_;
  scene.gravity = {0.0, -9.81, 0.0};
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = settings.substeps;
  scene.solver.iterations = settings.iterations;
  scene.solver.measure_errors = settings.measure_errors;
  scene.solver.contact_sweeps = settings.contact_sweeps;
  scene.tet_bodies.push_back(std::move(body));
  // Tool 0: the grasper's shaft, straight above the upper pole (y up), the
  // jaws' box centred on the pole's top vertex.
  const double shaft_above = kJawHalf[1] + kToolGap + kShaftRadius + kShaftHalfHeight;
  s.jaw_offset_ = {0.0, -shaft_above, 0.0};
  s.jaw_half_ = kJawHalf;
  const V3 shaft_start = add(pole_x, {0.0, shaft_above, 0.0});
  scene.tools.push_back(capsule_tool(kShaftRadius, kShaftHalfHeight, shaft_start, {1, 0, 0, 0}));
  // Tool 1: the probe, its tip kToolGap off the front (the side of greatest z), pressing
  // along -z towards the pinned back.
  const V3 probe_start = add(side_x, {0.0, 0.0, kToolGap + kProbeRadius + kProbeHalfHeight});
  scene.tools.push_back(capsule_tool(kProbeRadius, kProbeHalfHeight, probe_start, kProbeRotation));
  scene.graspers.push_back({.capacity = 256, .point_capacity = 0, .compliance = s.hold_compliance_});
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.self_collision = settings.self_collision;

  auto sim = Simulation::create(scene, {.backend = settings.backend, .threads = settings.threads, .quiet = true});
  if (!sim) return sim.error();
  s.sim_.emplace(std::move(*sim));

  // The haptic side: a scripted hand per tool, its loop and its bridge.
  using namespace haptics;
  s.clock_ = settings.realtime_haptics ? static_cast<Clock*>(&s.wall_clock_) : &s.virtual_clock_;
  const double speed = settings.script_speed;
  auto pull = [shaft_start, speed](double t) {
    t *= speed;
    ScriptedPose p;
    p.position = add(shaft_start, {0.0, kPull * ramp(t, kPullStart, kPullEnd), 0.0});
    return p;
  };
  auto press = [probe_start, speed](double t) {
    t *= speed;
    ScriptedPose p;
    p.position = add(probe_start, {0.0, 0.0, -kPress * ramp(t, kPressStart, kPressEnd)});
    p.rotation = kProbeRotation;
    return p;
  };
  s.devices_.push_back(std::make_unique<ScriptedDevice>(pull));
  s.devices_.push_back(std::make_unique<ScriptedDevice>(press));
  for (std::size_t i = 0; i < 2; ++i) {
    HapticLoopSettings hs;
    hs.rate_hz = 1000.0;
    hs.realtime = settings.realtime_priority;
    // Damps the tool's swing on the coupling spring; passive (B > K T / 2 at 1 kHz).
    hs.coupling.damping = 3.0;
    hs.local_contacts = i == 1 && settings.local_contacts;
    hs.cpu = settings.haptic_cpus[i];
    auto loop = HapticLoop::create(hs, *s.devices_[i], s.snapshots_[i], s.feedback_[i], *s.clock_);
    if (!loop) return loop.error();
    s.loops_.push_back(std::move(*loop));
    s.bridges_.push_back(std::make_unique<HapticToolBridge>(i, s.snapshots_[i], s.feedback_[i], *s.clock_));
    // Why: the tool -> snapshot -> coupling -> tool loop is ~1.5 frames late
    // (25 ms at 60 Hz), a negative damping of about K x 25 ms = 12.5 N s/m
    // on the 500 N/m coupling; damping here acts without that delay
    // (tool_bridge.h; 20 x dt / M = 1.1 < 2).
    if (auto st = s.bridges_[i]->set_damping(20.0, 2e-3); !st) return st.error();
    if (hs.local_contacts) {
      auto builder = LocalContactBuilder::create(s.scene_, s.sim_->info(), i);
      if (!builder) return builder.error();
      if (auto st = s.bridges_[i]->set_local_contacts(std::move(*builder)); !st) return st.error();
    }
    if (auto st = s.bridges_[i]->publish(*s.sim_); !st) return st.error();
  }
  if (auto st = s.grasp(); !st) return st.error();
  if (!settings.realtime_haptics)
    for (auto& d : s.devices_)
      if (auto st = d->start(s.clock_->now_ns()); !st) return st.error();
  return self;
}

RetractionScene::~RetractionScene() { stop_haptics(); }

double probe_contact_time() {
  return kPressStart + (kPressEnd - kPressStart) * std::acos(1.0 - 2.0 * kToolGap / kPress) / M_PI;
}

Status RetractionScene::grasp() {
  auto tool = sim_->tools().tool(0);
  auto grasper = sim_->graspers().grasper(0);
  if (!tool) return tool.error();
  if (!grasper) return grasper.error();
  auto state = sim_->tools().state(*tool);
  if (!state) return state.error();
  jaws_ = {.position = add(state->position, rotate(state->rotation, jaw_offset_)), .rotation = state->rotation};
  auto held = sim_->graspers().close(*grasper, jaws_, jaw_half_);
  if (!held) return held.error();
  if (held->empty()) return Error(ErrorCode::bad_parameter, "retraction: the grasper's jaws hold no vertex of the pole");
  held_ = std::move(*held);
  if (auto st = sim_->read_positions(x_); !st) return st;
  grasp_centre_ = {};
  for (std::uint32_t i : held_) {
    const V3 p = particle(x_, i);
    held_local_.push_back(rotate(conjugate(jaws_.rotation), sub(p, jaws_.position)));
    for (int k = 0; k < 3; ++k) grasp_centre_[k] += p[k] / double(held_.size());
  }
  return {};
}

Status RetractionScene::start_haptics() {
  if (!settings_.realtime_haptics) return Error(ErrorCode::bad_parameter, "retraction: start_haptics needs realtime_haptics");
  t0_ = clock_->now_ns() - static_cast<std::int64_t>(frames_ * 1e9 * frame_time());
  for (auto& d : devices_) d->set_origin(t0_);
  for (auto& l : loops_)
    if (auto st = l->start(); !st) return st;
  running_ = true;
  return {};
}

void RetractionScene::stop_haptics() {
  if (!running_) return;
  for (auto& l : loops_) l->stop();
  running_ = false;
}

Status RetractionScene::frame() {
  ++frames_;
  if (!settings_.realtime_haptics) {
    // The loops' ticks over this frame's simulated time, 1 ms apart, as a
    // device SDK's 1 kHz scheduler would call them.
    const std::int64_t end = static_cast<std::int64_t>(std::llround(double(frames_) * frame_time() * 1e9));
    for (std::int64_t t = (virtual_clock_.now_ns() / 1'000'000 + 1) * 1'000'000; t <= end; t += 1'000'000) {
      virtual_clock_.set(t);
      for (auto& l : loops_) (void)l->tick();
    }
    virtual_clock_.set(end);
  }
  auto tool = sim_->tools().tool(0);
  auto grasper = sim_->graspers().grasper(0);
  if (!tool) return tool.error();
  if (!grasper) return grasper.error();
  for (std::size_t i = 0; i < bridges_.size(); ++i)
    if (i != 1 || settings_.probe_force <= 0.0)
      if (auto st = bridges_[i]->apply_feedback(*sim_); !st) return st;
  if (settings_.probe_force > 0.0)
    if (auto st = press_probe(); !st) return st;
  // The tissue's pull on the jaws acts on the shaft (at its centre: the hand
  // holds the instrument's orientation, the coupling's torque keeps it).
  if (auto st = sim_->tools().apply_force(*tool, pull_, {0.0, 0.0, 0.0}); !st) return st;
  auto state = sim_->tools().state(*tool);
  if (!state) return state.error();
  jaws_ = {.position = add(state->position, rotate(state->rotation, jaw_offset_)), .rotation = state->rotation};
  if (auto st = sim_->graspers().move(*grasper, jaws_); !st) return st;
  if (auto st = sim_->step(); !st) return st;
  for (auto& b : bridges_)
    if (auto st = b->publish(*sim_); !st) return st;
  return measure_pull();
}

// The probe pressed by a force (RetractionSettings::probe_force) over the
// coming frame, ramped in with the script's press from the frame's start,
// held on its axis and in its orientation by ProbeHold's spring-dampers.
Status RetractionScene::press_probe() {
  auto probe = sim_->tools().tool(1);
  if (!probe) return probe.error();
  auto state = sim_->tools().state(*probe);
  if (!state) return state.error();
  const ToolDesc& start = scene_.tools[1];
  const double t = double(frames_ - 1) * frame_time() * settings_.script_speed;
  V3 force{}, torque{};
  for (int k = 0; k < 3; ++k)
    force[k] = (k == 2 ? 0.0 : -ProbeHold::stiffness * (state->position[k] - start.position[k])) -
               ProbeHold::damping * state->velocity[k];
  force[2] -= settings_.probe_force * ramp(t, kPressStart, kPressEnd);
  // The rotation from the start's orientation, q q0^-1, as a small rotation vector.
  const Q4 q{state->rotation[0], state->rotation[1], state->rotation[2], state->rotation[3]};
  const Q4 q0 = conjugate({start.rotation[0], start.rotation[1], start.rotation[2], start.rotation[3]});
  const Q4 e{q[0] * q0[0] - q[1] * q0[1] - q[2] * q0[2] - q[3] * q0[3],
             q[0] * q0[1] + q[1] * q0[0] + q[2] * q0[3] - q[3] * q0[2],
             q[0] * q0[2] - q[1] * q0[3] + q[2] * q0[0] + q[3] * q0[1],
             q[0] * q0[3] + q[1] * q0[2] - q[2] * q0[1] + q[3] * q0[0]};
  const double sign = e[0] < 0.0 ? -1.0 : 1.0;
  for (int k = 0; k < 3; ++k)
    torque[k] = -ProbeHold::angular_stiffness * 2.0 * sign * e[k + 1] -
                ProbeHold::angular_damping * state->angular_velocity[k];
  return sim_->tools().apply_force(*probe, force, torque);
}

Status RetractionScene::measure_pull() {
  if (auto st = sim_->read_positions(x_); !st) return st;
  pull_ = {};
  for (std::size_t k = 0; k < held_.size(); ++k) {
    const V3 target = add(jaws_.position, rotate(jaws_.rotation, held_local_[k]));
    const V3 d = sub(particle(x_, held_[k]), target);
    for (int c = 0; c < 3; ++c) pull_[c] += d[c] / hold_compliance_;
  }
  return {};
}

Result<RetractionCheck> RetractionScene::check() {
  RetractionCheck c;
  c.contact_violation = sim_->last_frame().contact_violation;
  c.grasp_force = pull_;
  c.device_force = devices_[0]->last_force();
  V3 mean{};
  for (std::size_t k = 0; k < held_.size(); ++k) {
    const V3 p = particle(x_, held_[k]);
    const V3 d = sub(p, add(jaws_.position, rotate(jaws_.rotation, held_local_[k])));
    c.max_slip = std::max(c.max_slip, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    for (int i = 0; i < 3; ++i) mean[i] += p[i] / double(held_.size());
  }
  c.pole_lift = mean[1] - grasp_centre_[1];
  const FrameStats& stats = sim_->last_frame();
  c.self_violation = stats.counter("mesh collision", "self_violation_m");
  c.tool_violation = stats.counter("mesh collision", "tool_violation_m");
  // The probe's capsule: its axis is its frame's y, +-half_height.
  auto probe = sim_->tools().tool(1);
  if (!probe) return probe.error();
  auto state = sim_->tools().state(*probe);
  if (!state) return state.error();
  const ToolDesc& tool = scene_.tools[1];
  const Q4 q{state->rotation[0], state->rotation[1], state->rotation[2], state->rotation[3]};
  const V3 axis = rotate(q, {0.0, tool.half_height, 0.0});
  const V3 end0 = sub(state->position, axis), span{2 * axis[0], 2 * axis[1], 2 * axis[2]};
  const double span2 = span[0] * span[0] + span[1] * span[1] + span[2] * span[2];
  for (std::size_t i = 0; i < x_.size() / 4; ++i) {
    const V3 d = sub(particle(x_, static_cast<std::uint32_t>(i)), end0);
    const double u = std::clamp((d[0] * span[0] + d[1] * span[1] + d[2] * span[2]) / span2, 0.0, 1.0);
    const V3 r{d[0] - u * span[0], d[1] - u * span[1], d[2] - u * span[2]};
    c.probe_penetration = std::max(c.probe_penetration, tool.radius - std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]));
  }
  c.probe_force = state->contact_force[2];
  c.probe_depth = tool.position[2] - state->position[2];
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    const auto& e = tets_[t];
    const V3 o = particle(x_, e[0]);
    const V3 a = sub(particle(x_, e[1]), o), b = sub(particle(x_, e[2]), o), d = sub(particle(x_, e[3]), o);
    const V3 ab = cross(a, b);
    if ((ab[0] * d[0] + ab[1] * d[1] + ab[2] * d[2]) * rest_sign_[t] <= 0.0) ++c.inverted_tets;
  }
  return c;
}

}  // namespace sinew::examples
