// src/haptics/haptic_loop.cpp — the haptic servo loop: absolute-time paced
// thread (clock_nanosleep TIMER_ABSTIME through MonotonicClock), and the
// tick: newest snapshot -> interpolated tool -> watchdog -> virtual coupling
// (Colgate, Stanley, Brown, IROS 1995) -> safety chain -> device command ->
// feedback for the physics thread -> telemetry. A tick allocates nothing,
// takes no lock and does no I/O.
#include "sinew/haptics/haptic_loop.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <string>

#include "math/vec3.h"
#include "sinew/haptics/local_contacts.h"

namespace sinew::haptics {

Status check(const HapticLoopSettings& s) {
  // >= 1 Hz: the period is an int64 count of nanoseconds.
  if (!(s.rate_hz >= 1.0) || !std::isfinite(s.rate_hz) || s.rate_hz > 1e6)
    return Error(ErrorCode::bad_parameter,
                 "rate_hz must be >= 1 and at most 1e6 [Hz] (got " + std::to_string(s.rate_hz) + ")");
  if (s.realtime && (s.realtime_priority < 1 || s.realtime_priority > 99))
    return Error(ErrorCode::bad_parameter,
                 "realtime_priority must be in 1..99 (got " + std::to_string(s.realtime_priority) + ")");
  if (s.cpu < -1)
    return Error(ErrorCode::bad_parameter,
                 "cpu must be -1 (no pinning) or a CPU index (got " + std::to_string(s.cpu) + ")");
  if (s.telemetry_capacity < 1 || s.telemetry_capacity > kMaxTelemetryCapacity)
    return Error(ErrorCode::bad_parameter,
                 "telemetry_capacity must be in 1.." + std::to_string(kMaxTelemetryCapacity) + " ticks (got " +
                 std::to_string(s.telemetry_capacity) + ")");
  if (s.snapshot_read_attempts < 1) return Error(ErrorCode::bad_parameter, "snapshot_read_attempts must be >= 1");
  if (s.degrees_of_freedom != 3 && s.degrees_of_freedom != 6)
    return Error(ErrorCode::bad_parameter, "degrees_of_freedom must be 3 (force only) or 6 (force and torque) (got " +
                                               std::to_string(s.degrees_of_freedom) + ")");
  if (auto st = check(s.passivity); !st) return st;
  if (auto st = check(s.coupling); !st) return st;
  if (auto st = check(s.watchdog); !st) return st;
  return check(s.interpolation);
}

Result<std::unique_ptr<HapticLoop>> HapticLoop::create(const HapticLoopSettings& settings, HapticDevice& device,
                                                       SnapshotChannel& snapshots, FeedbackChannel& feedback,
                                                       Clock& clock) {
  if (auto s = check(settings); !s) return s.error();
  try {
    return std::unique_ptr<HapticLoop>(new HapticLoop(settings, device, snapshots, feedback, clock));
  } catch (const std::exception& e) {  // the telemetry ring (or the settings' copy) could not be allocated
    return Error(ErrorCode::out_of_memory,
                 "cannot create the haptic loop (telemetry_capacity " + std::to_string(settings.telemetry_capacity) +
                 "): " + e.what());
  }
}

HapticLoop::HapticLoop(const HapticLoopSettings& settings, HapticDevice& device, SnapshotChannel& snapshots,
                       FeedbackChannel& feedback, Clock& clock)
    : settings_(settings), device_(device), snapshots_(snapshots), feedback_(feedback), clock_(clock),
      period_ns_(std::max<std::int64_t>(1, seconds_to_ns(1.0 / settings.rate_hz))), coupling_(settings.coupling),
      drive_coupling_(settings.coupling),
      watchdog_(settings.watchdog), passivity_(settings.passivity),
      ring_(settings.telemetry_capacity) {  // value-initialised: pages touched
  // Its own id in every feedback: a later loop on the same channel starts
  // its impulse integral at zero, and the bridge must not difference the two.
  static std::atomic<std::uint64_t> loops{0};
  fb_.loop = loops.fetch_add(1, std::memory_order_relaxed) + 1;
}

HapticLoop::~HapticLoop() { stop(); }

HapticCounters HapticLoop::counters() const {
  const auto r = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  const AtomicCounters& c = counters_;
  return {r(c.ticks),      r(c.missed),        r(c.skipped),         r(c.non_finite),
          r(c.clamped),    r(c.slewed),        r(c.stale),           r(c.stalls),
          r(c.read_failures), r(c.device_failures), r(c.snapshots),  r(c.passivity),
          c.energy.load(std::memory_order_relaxed), c.min_window.load(std::memory_order_relaxed)};
}

Status HapticLoop::copy_telemetry(std::vector<TickRecord>& out) const {
  if (running())
    return Error(ErrorCode::bad_parameter,
                 "copy_telemetry: stop the haptic loop first (the ring is written without locks)");
  int idle = kIdle;
  if (!access_.compare_exchange_strong(idle, kCopying, std::memory_order_acquire, std::memory_order_relaxed))
    return Error(ErrorCode::bad_parameter,
                 "copy_telemetry: a tick() is in progress on another thread (stop calling tick() first)");
  struct Release {
    std::atomic<int>& a;
    ~Release() { a.store(kIdle, std::memory_order_release); }
  } release{access_};
  const std::size_t cap = ring_.size();
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(recorded_, cap));
  out.resize(n);
  const std::size_t first = recorded_ > cap ? static_cast<std::size_t>(recorded_ % cap) : 0;
  for (std::size_t i = 0; i < n; ++i) out[i] = ring_[(first + i) % cap];
  return {};
}

TickRecord HapticLoop::tick() noexcept {
  if (running()) return {};
  // Never waits: a copy_telemetry() (or another tick()) in progress skips this tick.
  int idle = kIdle;
  if (!access_.compare_exchange_strong(idle, kTicking, std::memory_order_acquire, std::memory_order_relaxed)) return {};
  const TickRecord rec = tick_at(0, false);
  access_.store(kIdle, std::memory_order_release);
  return rec;
}

namespace {
// Relaxed increment by the single writing thread (no read-modify-write needed).
inline void bump(std::atomic<std::uint64_t>& a, std::uint64_t by = 1) {
  a.store(a.load(std::memory_order_relaxed) + by, std::memory_order_relaxed);
}
}  // namespace

std::uint32_t HapticLoop::observe_passivity(Vec3& force, Vec3& torque, TickRecord& rec) noexcept {
  // The device's pose this tick (the previous sample when none came: no motion).
  std::uint32_t flags = 0;
  const PassivityParams& ps = settings_.passivity;
  const CouplingParams& c = settings_.coupling;
  if (ps.controller && have_sample_ &&
      passivity_.control(sample_.position, sample_.rotation, sample_.velocity, sample_.angular_velocity,
                         ns_to_seconds(period_ns_), c.max_force, c.max_torque, settings_.degrees_of_freedom == 6,
                         force, torque))
    flags |= kPassivityDamping;
  const PassivityReading p = passivity_.observe(sample_.position, sample_.rotation, force, torque);
  rec.passivity_energy = p.energy;
  rec.window_energy = p.window_energy;
  counters_.energy.store(p.energy, std::memory_order_relaxed);
  counters_.min_window.store(passivity_.min_window_energy(), std::memory_order_relaxed);
  if (!p.violation) return flags;
  bump(counters_.passivity);
  return flags | kPassivityViolation;
}

TickRecord HapticLoop::tick_at(std::int64_t scheduled_ns, bool use_scheduled) noexcept {
  const std::int64_t start = clock_.now_ns();
  TickRecord rec;
  rec.scheduled_ns = use_scheduled ? scheduled_ns : start;
  rec.start_ns = start;
  std::uint32_t flags = 0;
  const double dt = have_prev_tick_ ? ns_to_seconds(start - prev_start_ns_) : ns_to_seconds(period_ns_);
  if (have_prev_tick_ && start - prev_start_ns_ > 2 * period_ns_) {
    flags |= kMissedDeadline;
    bump(counters_.missed);
  }

  // 1. The newest snapshot (bounded seqlock read: never waits for the writer).
  std::uint64_t version = 0;
  if (snapshots_.try_read(scratch_, settings_.snapshot_read_attempts, &version)) {
    if (version != last_version_) {
      history_.push(scratch_);
      last_version_ = version;
      bump(counters_.snapshots);
    }
  } else if (snapshots_.published() > 0) {
    bump(counters_.read_failures);
  }

  // 2. The newest device sample.
  if (device_.sample(start, sample_)) {
    have_sample_ = true;
  } else {
    flags |= kNoDeviceSample;
    bump(counters_.device_failures);
  }

  // 3. The tool state at this tick's time.
  tool_ = history_.render(start, settings_.interpolation);
  if (!tool_.valid()) flags |= kNoSnapshot;
  if (tool_.mode == RenderMode::extrapolated) flags |= kExtrapolated;
  if (tool_.mode == RenderMode::held) flags |= kHeld;

  // 4. Watchdog: stale snapshots or device samples fade the force.
  const double inf = std::numeric_limits<double>::infinity();
  const double device_age = have_sample_ ? ns_to_seconds(start - sample_.time_ns) : inf;
  const double gain = watchdog_.update(tool_.valid() ? tool_.snapshot_age : inf, device_age, dt);
  if (watchdog_.stale()) {
    flags |= kStale;
    bump(counters_.stale);
  }
  if (gain < 1.0) flags |= kFading;

  // 5. Virtual coupling through the safety chain; 6. the device.
  const DeviceSample no_sample{};
  const RenderedTool no_tool{};
  const DeviceSample& device = have_sample_ ? sample_ : no_sample;
  const RenderedTool& tool = have_sample_ ? tool_ : no_tool;
  CouplingOutput out, drive;
  Vec3 rendered_position = tool_.position;
  LocalContactSolution contacts{};
  if (settings_.local_contacts) {
    // The device gets the coupling to the proxy solved against the newest
    // local contact model (its velocity: the device's, as the proxy follows
    // it, d proxy / d device); the physics' tool keeps the coupling to its
    // interpolated state.
    RenderedTool proxy = tool;
    if (tool.valid()) {
      contacts = local_.render(history_.newest().local_contacts, history_.newest().sequence, device.position,
                               prev_rendered_force_, settings_.coupling.stiffness);
      const auto& m = contacts.sensitivity;
      const Vec3& v = device.velocity;
      proxy.position = contacts.proxy;
      proxy.velocity = {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
                        m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
      rendered_position = proxy.position;
    }
    out = coupling_.evaluate(device, proxy, gain);
    drive = drive_coupling_.evaluate(device, tool, gain);
  } else {
    out = drive = coupling_.evaluate(device, tool, gain);
  }
  flags |= out.flags;
  if (out.flags & kNonFinite) bump(counters_.non_finite);
  if (out.flags & kClamped) bump(counters_.clamped);
  if (out.flags & kSlewLimited) bump(counters_.slewed);
  // A 3-DOF device gets no torque; the feedback below still carries it to
  // the tool. The passivity controller's damper goes to the device only.
  Vec3 device_force = out.force;
  Vec3 device_torque = settings_.degrees_of_freedom == 6 ? out.torque : Vec3{0.0, 0.0, 0.0};
  flags |= observe_passivity(device_force, device_torque, rec);
  device_.command(device_force, device_torque, start);

  // 7. Feedback: the impulse integral (zero-order hold of the previous tick's
  // output up to now), then this tick's output.
  if (have_prev_tick_) {
    fb_.impulse = math::add(fb_.impulse, math::mul(prev_force_, dt));
    fb_.angular_impulse = math::add(fb_.angular_impulse, math::mul(prev_torque_, dt));
  }
  const std::uint64_t tick_no = counters_.ticks.load(std::memory_order_relaxed) + 1;
  fb_.ticks = tick_no;
  fb_.time_ns = start;
  fb_.force = drive.force;
  fb_.torque = drive.torque;
  fb_.rendered_force = device_force;
  fb_.device_position = sample_.position;
  fb_.device_rotation = sample_.rotation;
  fb_.gain = gain;
  fb_.flags = flags;
  feedback_.publish(fb_);
  prev_force_ = drive.force;
  prev_torque_ = drive.torque;
  prev_rendered_force_ = device_force;  // with the passivity controller's damper: what the hand pushed against
  prev_start_ns_ = start;
  have_prev_tick_ = true;
  if (watchdog_.stalls() != counters_.stalls.load(std::memory_order_relaxed))
    counters_.stalls.store(watchdog_.stalls(), std::memory_order_relaxed);

  // 8. Telemetry into the preallocated ring.
  rec.tick = tick_no;
  rec.snapshot_age = tool_.valid() ? tool_.snapshot_age : inf;
  rec.render_age = tool_.valid() ? tool_.render_age : inf;
  rec.device_position = sample_.position;
  rec.tool_position = rendered_position;
  rec.contact_energy = contacts.energy;
  rec.local_contacts = contacts.active;
  rec.contact_gap_offset = local_.gap_offset();
  rec.raw_force = out.raw_force;
  rec.force = device_force;
  rec.torque = device_torque;
  rec.gain = gain;
  rec.flags = flags;
  rec.device_buttons = sample_.buttons;
  rec.end_ns = clock_.now_ns();
  ring_[static_cast<std::size_t>(recorded_ % ring_.size())] = rec;
  ++recorded_;
  counters_.ticks.store(tick_no, std::memory_order_release);
  return rec;
}

Status HapticLoop::start() {
  if (running()) return Error(ErrorCode::bad_parameter, "the haptic loop is already running");
  if (auto s = device_.start(clock_.now_ns()); !s)
    return Error(s.error().code(), "device " + device_.name() + ": " + s.error().message());
  std::string latency = "not requested";
  if (settings_.zero_cpu_latency) qos_fd_ = hold_cpu_latency(0, latency);
  stop_.store(false, std::memory_order_relaxed);
  ready_.store(false, std::memory_order_relaxed);
  running_.store(true, std::memory_order_release);
  try {
    thread_ = std::thread([this] { run(); });
  } catch (const std::exception& e) {
    running_.store(false, std::memory_order_release);
    release_cpu_latency(qos_fd_);
    qos_fd_ = -1;
    device_.stop();
    return Error(ErrorCode::internal, std::string("cannot create the haptic thread: ") + e.what());
  }
  ready_.wait(false, std::memory_order_acquire);  // scheduling_ is set
  scheduling_.cpu_latency = latency;
  return {};
}

void HapticLoop::stop() noexcept {
  if (!thread_.joinable()) return;
  stop_.store(true, std::memory_order_release);
  thread_.join();
  device_.command({0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, clock_.now_ns());
  device_.stop();
  // The device held zero force since; a restart ramps up from zero again,
  // and its first tick takes one period as its dt (not the stopped time:
  // that would ramp the gain straight to 1 and count a missed deadline).
  prev_force_ = prev_torque_ = prev_rendered_force_ = {0.0, 0.0, 0.0};
  have_prev_tick_ = false;
  local_.reset();
  coupling_.reset();
  drive_coupling_.reset();
  watchdog_.reset();
  passivity_.reset();  // the device held zero force since; the energy it saw is history
  release_cpu_latency(qos_fd_);
  qos_fd_ = -1;
  running_.store(false, std::memory_order_release);
}

void HapticLoop::run() {
  scheduling_ = set_thread_scheduling(settings_.realtime, settings_.realtime_priority, settings_.cpu);
  if (settings_.on_thread_start) settings_.on_thread_start();
  {  // Touch the stack a tick may use, so the first ticks take no page faults.
    volatile char stack[64 * 1024];
    for (std::size_t i = 0; i < sizeof(stack); i += 4096) stack[i] = 0;
  }
  ready_.store(true, std::memory_order_release);
  ready_.notify_all();

  const std::int64_t period = period_ns_;
  std::int64_t next = clock_.now_ns() + period;
  while (!stop_.load(std::memory_order_acquire)) {
    clock_.sleep_until(next);  // absolute deadline: no drift
    tick_at(next, true);
    next += period;
    // More than a period behind (a long preemption): skip the slots already
    // past instead of running them back to back.
    const std::int64_t now = clock_.now_ns();
    if (now > next + period) {
      const std::int64_t behind = (now - next) / period;
      next += behind * period;
      bump(counters_.skipped, static_cast<std::uint64_t>(behind));
    }
  }
}

}  // namespace sinew::haptics
