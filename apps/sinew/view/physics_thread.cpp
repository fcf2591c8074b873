// physics_thread.cpp — see physics_thread.h.
#include "view/physics_thread.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace sinew::view {
namespace {

// The haptic side of the viewer. The scenes' frames are long (1/60 s in
// tissue_sag) against haptic_drag's 1/250 s: the tool -> snapshot ->
// coupling -> feedback -> tool loop then holds about 25 ms of delay, which
// turns a spring K into a negative damper of about K x 25 ms (tool_bridge.h).
// A softer spring and more of the bridge's own damping (not felt, and
// stable while damping x time_step / mass stays well below 2) keep the
// probe from ringing.
constexpr double kCouplingStiffness = 300.0;  // [N/m]
constexpr double kCouplingDamping = 3.0;      // [N s/m]
constexpr double kToolDamping = 15.0;         // [N s/m]
constexpr double kToolAngularDamping = 2e-3;  // [N m s/rad]

}  // namespace

PhysicsThread::PhysicsThread(SceneFile file, DeviceOptions device, MouseDevice& mouse)
    : file_(std::move(file)), device_options_(std::move(device)), mouse_(mouse) {}

PhysicsThread::~PhysicsThread() { stop(); }

// Whether the file's scripted hands drive `tool` (the mouse then leaves it to them).
bool PhysicsThread::scripted(int tool) const {
  for (const haptics::ScriptedHandDesc& h : file_.hands)
    if (static_cast<int>(h.tool) == tool) return true;
  return false;
}

Status PhysicsThread::start() {
  // The mouse drives the first tool no scripted hand drives.
  for (std::size_t t = 0; t < file_.scene.tools.size(); ++t)
    if (!scripted(static_cast<int>(t))) {
      driven_tool_.store(static_cast<int>(t));
      break;
    }
  std::promise<Status> ready;
  std::future<Status> made = ready.get_future();
  thread_ = std::thread([this, p = std::move(ready)]() mutable { run(std::move(p)); });
  if (Status s = made.get(); !s) {
    stop();
    return s;
  }
  if (driven_tool_.load() < 0) return {};
  const ToolDesc& tool = file_.scene.tools[static_cast<std::size_t>(driven_tool_.load())];
  mouse_.place(tool.position);
  haptics::HapticLoopSettings settings;
  // The viewer is no real-time haptic rig: an ordinary thread (no
  // SCHED_FIFO spinning beside the renderer on a small machine).
  settings.realtime = false;
  settings.coupling.stiffness = kCouplingStiffness;
  settings.coupling.damping = kCouplingDamping;
  auto loop = haptics::HapticLoop::create(settings, mouse_, haptic_snapshots_, feedback_, clock_);
  if (!loop) {
    stop();
    return loop.error();
  }
  loop_ = std::move(*loop);
  if (Status s = loop_->start(); !s) {
    stop();
    return s;
  }
  haptic_description_ = "haptic loop at " + std::to_string(static_cast<int>(settings.rate_hz)) + " Hz, " +
                        loop_->scheduling().describe();
  return {};
}

void PhysicsThread::stop() {
  if (loop_) loop_->stop();
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

Status PhysicsThread::make_simulation() {
  bridge_.reset();
  player_.reset();
  hands_.reset();
  sim_.reset();  // the old device goes first: two at once may not fit
  auto sim = Simulation::create(file_.scene, device_options_);
  if (!sim) return sim.error();
  sim_.emplace(std::move(*sim));
  player_.emplace(file_.script);
  // The file's scripted hands, on the frames' clock (they follow simulated time, as in sinew run).
  if (!file_.hands.empty()) {
    auto hands = haptics::ScriptedHands::create(file_.hands, *sim_, file_.scene.solver.time_step);
    if (!hands) return hands.error();
    hands_ = std::move(*hands);
  }
  bridged_tool_ = -1;
  ++generation_;
  frame_ = 0;
  shape_version_ = 0;
  surfaces_version_ = UINT64_MAX;
  line_segments_.clear();
  for (const LineBodyDesc& b : file_.scene.line_bodies) line_segments_.push_back(b.segments);
  return {};
}

void PhysicsThread::note_change(const TopologyEvent& event) {
  ++shape_version_;
  if (event.body_kind != BodyKind::line || event.segments_removed.empty()) return;
  // No accessor lists a thread's live segments: the events say which broke.
  const std::vector<std::array<std::uint32_t, 2>>& all = file_.scene.line_bodies[event.body].segments;
  std::vector<std::array<std::uint32_t, 2>>& live = line_segments_[event.body];
  for (std::uint32_t s : event.segments_removed)
    if (s < all.size()) std::erase(live, all[s]);
}

// The live boundary of each tet body and the live triangles of each tri
// body, and the level-set colliders' surfaces, when they changed.
void PhysicsThread::refresh_shapes() {
  if (surfaces_version_ == shape_version_) return;
  surfaces_version_ = shape_version_;
  const SceneDesc& scene = file_.scene;
  tet_surfaces_.resize(scene.tet_bodies.size());
  for (std::size_t b = 0; b < scene.tet_bodies.size(); ++b) {
    TetMesh mesh{scene.tet_bodies[b].mesh.vertices, scene.tet_bodies[b].mesh.tets};
    if (scene.topology_changes)
      if (auto id = sim_->topology().tet_body(b))
        if (auto tets = sim_->topology().current_tets(*id)) mesh.tets = std::move(*tets);
    tet_surfaces_[b] = extract_boundary_surface(mesh).triangles;
  }
  tri_surfaces_.resize(scene.tri_bodies.size());
  for (std::size_t b = 0; b < scene.tri_bodies.size(); ++b) {
    tri_surfaces_[b] = scene.tri_bodies[b].mesh.triangles;
    if (scene.topology_changes)
      if (auto id = sim_->topology().tri_body(b))
        if (auto triangles = sim_->topology().current_triangles(*id)) tri_surfaces_[b] = std::move(*triangles);
  }
  auto surfaces = std::make_shared<std::vector<TriMesh>>(scene.colliders.size());
  for (std::size_t c = 0; c < scene.colliders.size(); ++c)
    if (scene.colliders[c].level_set) (*surfaces)[c] = scene.colliders[c].level_set->surface();
  collider_surfaces_ = std::move(surfaces);
}

Status PhysicsThread::step_frame() {
  const int tool = scripted(driven_tool_.load()) ? -1 : driven_tool_.load();
  if (tool != bridged_tool_) {
    bridge_.reset();
    if (tool >= 0 && static_cast<std::size_t>(tool) < file_.scene.tools.size()) {
      bridge_.emplace(static_cast<std::size_t>(tool), haptic_snapshots_, feedback_, clock_);
      if (Status s = bridge_->set_damping(kToolDamping, kToolAngularDamping); !s) return s;
      if (Status s = bridge_->publish(*sim_); !s) return s;
    }
    bridged_tool_ = tool;
  }
  if (bridge_)
    if (Status s = bridge_->apply_feedback(*sim_); !s) return s;
  if (hands_)
    if (Status s = hands_->before_step(*sim_); !s) return s;
  results_.clear();
  const int frame = static_cast<int>(frame_ + 1);
  if (Status s = player_->before_frame(*sim_, frame, results_); !s) return s;
  for (const ScriptEvent& r : results_) {
    if (r.kind == ScriptActionKind::cut || r.kind == ScriptActionKind::cauterize ||
        r.kind == ScriptActionKind::remove)
      note_change(r.topology);
    if (r.kind == ScriptActionKind::cut_collider) ++shape_version_;
  }
  if (Status s = sim_->step(); !s) return s;
  ++frame_;
  if (file_.scene.topology_changes)
    for (const TopologyEvent& e : sim_->topology().last_tears()) note_change(e);
  if (bridge_)
    if (Status s = bridge_->publish(*sim_); !s) return s;
  if (hands_)
    if (Status s = hands_->after_step(*sim_); !s) return s;
  return {};
}

Status PhysicsThread::fill_snapshot(ViewSnapshot& out) {
  refresh_shapes();
  out.generation = generation_;
  out.frame = frame_;
  out.shape_version = shape_version_;
  if (Status s = sim_->read_positions(out.positions); !s) return s;
  out.tet_first = sim_->info().tet_body_first_particle;
  out.tri_first = sim_->info().tri_body_first_particle;
  out.line_first = sim_->info().line_body_first_particle;
  if (Status s = sim_->read_velocities(velocities_); !s) return s;
  out.speeds.resize(velocities_.size() / 4);
  for (std::size_t p = 0; p < out.speeds.size(); ++p) {
    const float* v = &velocities_[4 * p];
    out.speeds[p] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  out.tet_surfaces = tet_surfaces_;
  out.tri_surfaces = tri_surfaces_;
  out.line_segments = line_segments_;
  const SceneDesc& scene = file_.scene;
  out.tools.resize(scene.tools.size());
  for (std::size_t t = 0; t < scene.tools.size(); ++t) {
    auto id = sim_->tools().tool(t);
    if (!id) return id.error();
    auto state = sim_->tools().state(*id);
    if (!state) return state.error();
    out.tools[t] = *state;
  }
  // Colliders: where the script put them (no accessor reads a collider's
  // pose back; the script is the only thing that moves them).
  out.colliders.resize(scene.colliders.size());
  for (std::size_t c = 0; c < scene.colliders.size(); ++c)
    out.colliders[c] = {.position = scene.colliders[c].position, .rotation = scene.colliders[c].rotation};
  for (const ScriptTrack& track : file_.script.poses)
    if (track.subject == ScriptSubject::collider && track.index < out.colliders.size()) {
      const ScriptKey key = interpolate_keys(track.keys, static_cast<int>(frame_));
      out.colliders[track.index] = {.position = key.position, .rotation = key.rotation};
    }
  out.needles.resize(scene.needles.size());
  for (std::size_t n = 0; n < scene.needles.size(); ++n) {
    auto id = sim_->needles().needle(n);
    if (!id) return id.error();
    auto state = sim_->needles().state(*id);
    if (!state) return state.error();
    out.needles[n] = std::move(*state);
    out.needles[n].punctures.clear();
  }
  out.fluid.clear();
  if (scene.fluid) {
    if (Status s = sim_->fluid().read(fluid_); !s) return s;
    for (const FluidParticle& p : fluid_) out.fluid.insert(out.fluid.end(), p.position.begin(), p.position.end());
  }
  out.collider_surfaces = collider_surfaces_;
  out.stats = sim_->last_frame();
  out.physics_hz = physics_hz_;
  out.paused = paused_.load();
  out.error = error_;
  return {};
}

void PhysicsThread::run(std::promise<Status> ready) {
  Status made = make_simulation();
  if (made) device_name_ = sim_->device_name();  // before start() returns: the viewer reads it from then on
  if (made)
    if (Status s = fill_snapshot(snapshots_.back()); !s) made = s;
  const bool ok = static_cast<bool>(made);
  ready.set_value(std::move(made));
  if (!ok) return;
  snapshots_.publish();

  using clock = std::chrono::steady_clock;
  const auto frame_time = std::chrono::duration_cast<clock::duration>(
      std::chrono::duration<double>(file_.scene.solver.time_step));
  auto next = clock::now();
  auto rate_start = next;
  int rate_frames = 0;
  while (!stop_.load()) {
    if (reset_requested_.exchange(false)) {
      error_.clear();
      if (Status s = make_simulation(); !s) {
        error_ = "reset: " + s.error().message();
      } else if (Status f = fill_snapshot(snapshots_.back()); !f) {
        error_ = f.error().message();
      } else {
        snapshots_.publish();
      }
      next = clock::now();
    }
    const bool run_free = !paused_.load() && error_.empty() && sim_;
    const bool step_one = !run_free && error_.empty() && sim_ && step_requests_.load() > 0;
    if (!run_free && !step_one) {
      // Paused (or stopped by an error): the snapshot says so; wait a little.
      if (sim_)
        if (Status f = fill_snapshot(snapshots_.back()); f) snapshots_.publish();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      next = clock::now();
      rate_start = next, rate_frames = 0, physics_hz_ = 0.0;
      continue;
    }
    if (step_one) step_requests_.fetch_sub(1);
    if (Status s = step_frame(); !s) {
      error_ = "frame " + std::to_string(frame_ + 1) + ": " + s.error().message();
      continue;
    }
    ++rate_frames;
    const auto now = clock::now();
    const double seconds = std::chrono::duration<double>(now - rate_start).count();
    if (seconds >= 0.5) {
      physics_hz_ = rate_frames / seconds;
      rate_start = now, rate_frames = 0;
    }
    if (Status f = fill_snapshot(snapshots_.back()); !f) {
      error_ = f.error().message();
      continue;
    }
    snapshots_.publish();
    // The scene's own rate: one time_step of wall clock per frame. A frame
    // that took longer is not caught up on (the scene then runs slower than
    // real time, as fast as it can).
    next += frame_time;
    if (next < now) next = now;
    std::this_thread::sleep_until(next);
  }
  bridge_.reset();
  player_.reset();
  sim_.reset();
}

}  // namespace sinew::view
