// sinew/haptics/haptic_loop.h — the haptic servo loop: its own thread at
// 1 kHz (configurable), paced by absolute-time sleeps, SCHED_FIFO where the
// system grants it; each tick reads the newest snapshot and device sample,
// evaluates the virtual coupling through the safety chain, commands the
// device and publishes the feedback for the physics thread.
//
//   sinew::haptics::MonotonicClock clock;
//   sinew::haptics::SnapshotChannel snapshots;   // physics -> haptics
//   sinew::haptics::FeedbackChannel feedback;    // haptics -> physics
//   auto loop = sinew::haptics::HapticLoop::create({}, device, snapshots, feedback, clock);
//   if (auto s = (*loop)->start(); !s) ...;       // then (*loop)->scheduling() says what was obtained
//   ... physics thread: HapticToolBridge (tool_bridge.h) around Simulation::step() ...
//   (*loop)->stop();
//
// A tick allocates nothing, takes no lock, does no I/O and logs nothing:
// telemetry goes into a ring preallocated by create(), counters are relaxed
// atomics. The thread's own stack is touched before the first tick.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "sinew/haptics/clock.h"
#include "sinew/haptics/haptic_device.h"
#include "sinew/haptics/local_contacts.h"
#include "sinew/haptics/passivity_observer.h"
#include "sinew/haptics/snapshot_channel.h"
#include "sinew/haptics/snapshot_interpolator.h"
#include "sinew/haptics/virtual_coupling.h"
#include "sinew/haptics/watchdog.h"
#include "sinew/result.h"

namespace sinew::haptics {

/// The largest HapticLoopSettings::telemetry_capacity: 2^24 ticks (4.6 h
/// at 1 kHz), 2.5 GiB of TickRecords.
inline constexpr std::size_t kMaxTelemetryCapacity = std::size_t{1} << 24;

/// How a HapticLoop runs: its rate, scheduling, telemetry, and the
/// coupling, watchdog and interpolation it renders force with.
struct HapticLoopSettings {
  /// Tick rate [Hz], 1..1e6. At least 1 Hz: the period is an int64 count
  /// of nanoseconds (and twice it the missed-deadline threshold), which a
  /// rate of 1e-10 Hz would overflow; a loop slower than 1 Hz renders no force.
  double rate_hz = 1000.0;
  bool realtime = true;             ///< request SCHED_FIFO for the loop thread
  int realtime_priority = 80;       ///< SCHED_FIFO priority, 1..99
  int cpu = -1;                     ///< pin the loop thread to this CPU; -1: no pinning
  /// While the loop runs, hold a PM QoS request of 0 us CPU wake-up latency
  /// (/dev/cpu_dma_latency, as cyclictest does): idle CPUs poll instead of
  /// entering sleep states, so a timer wakes the loop without leaving a
  /// sleep state first. Off by default: it makes every idle CPU spin
  /// (power, heat), and in a VM whose host caps its CPU time the spinning
  /// vCPUs use up the cap and the host pauses the whole VM (measured here:
  /// 35 ms pauses every 100 ms; docs/benchmarks.md). Turn it on for a
  /// dedicated machine. Needs write access to the device (root); what was
  /// obtained is reported in SchedulingReport::cpu_latency.
  bool zero_cpu_latency = false;
  std::size_t telemetry_capacity = 1u << 16;  ///< ticks kept in the telemetry ring (the newest), 1..kMaxTelemetryCapacity
  unsigned snapshot_read_attempts = 4;        ///< bounded seqlock retries per tick, >= 1
  CouplingParams coupling;            ///< the virtual coupling and force limits
  WatchdogParams watchdog;            ///< when stale state fades the force out
  InterpolationParams interpolation;  ///< how the tool's state is interpolated between snapshots
  /// Render the newest snapshot's local contact model (local_contacts.h):
  /// each tick solves a proxy of the tool against the contact planes the
  /// physics published (HapticToolBridge::set_local_contacts) and commands
  /// the coupling to the proxy, so contact stiffness is felt at the tick
  /// rate; in free space the proxy is the device (nothing is rendered).
  /// The physics' tool is still driven by the coupling to the interpolated
  /// tool (CouplingFeedback::force). Off: the device gets that coupling.
  bool local_contacts = false;
  /// The device's degrees of freedom rendered: 6 (force and torque) or 3
  /// (force only, for a device without torque actuators, e.g. a Touch).
  /// With 3 the device is commanded exactly zero torque; the coupling's
  /// torque still goes to the simulated tool through the feedback, so the
  /// tool keeps following the device's measured rotation.
  int degrees_of_freedom = 6;
  PassivityParams passivity;  ///< the passivity observer's window and tolerance (passivity_observer.h)
  /// Called once on the loop thread before its first tick (outside the
  /// tick: it may allocate); e.g. to mark the thread for an allocation counter.
  std::function<void()> on_thread_start;
};
/// Errors name the bad parameter.
Status check(const HapticLoopSettings& settings);

/// What the loop thread asked for and what it got; never assumed.
struct SchedulingReport {
  std::string requested;   ///< "SCHED_FIFO priority 80" or "SCHED_OTHER (not requested)"
  std::string policy;      ///< obtained: "SCHED_FIFO", "SCHED_RR", "SCHED_OTHER", ...
  int priority = 0;        ///< obtained
  int cpu = -1;            ///< pinned CPU obtained (-1: none)
  std::string error;       ///< why the request failed ("" when it did not)
  std::string cpu_latency = "not requested";  ///< the PM QoS request: "0 us held", or why not
  /// Whether a real-time policy (SCHED_FIFO or SCHED_RR) was obtained.
  [[nodiscard]] bool realtime() const { return policy == "SCHED_FIFO" || policy == "SCHED_RR"; }
  /// One line saying what was requested and obtained.
  [[nodiscard]] std::string describe() const;
};

/// One tick, as kept in the telemetry ring.
struct TickRecord {
  std::uint64_t tick = 0;        ///< 1, 2, ...
  std::int64_t scheduled_ns = 0;  ///< the absolute deadline it was woken for [ns] (= start for manual ticks)
  std::int64_t start_ns = 0;     ///< when it started [ns]
  std::int64_t end_ns = 0;       ///< when it finished [ns]
  double snapshot_age = 0.0;     ///< age of the newest snapshot at start [s] (infinity: none)
  double render_age = 0.0;       ///< age of the state rendered [s]
  Vec3 device_position{};        ///< [m]
  Vec3 tool_position{};          ///< rendered [m] (the proxy, when local contacts are rendered)
  Vec3 raw_force{};              ///< coupling before the safety chain [N]
  Vec3 force{};                  ///< commanded to the device [N] (with the passivity controller's damper)
  Vec3 torque{};                 ///< commanded to the device [N m] (zero with degrees_of_freedom 3)
  /// Cumulative energy put into the environment since the start [J] (passivity_observer.h).
  double passivity_energy = 0.0;
  double window_energy = 0.0;     ///< of it, over the last passivity.window ticks [J]
  double gain = 0.0;             ///< watchdog gain
  /// Local contacts: the energy stored in the coupling and the contact
  /// planes at this tick, V(device) of local_contacts.h [J]; 0 otherwise.
  double contact_energy = 0.0;
  std::uint32_t local_contacts = 0;  ///< local contacts pushing the proxy this tick
  double contact_gap_offset = 0.0;   ///< the planes' passivity offset this tick [m] (LocalContactRenderer)
  std::uint32_t flags = 0;       ///< TickFlags
  std::uint32_t device_buttons = 0;  ///< the device's buttons, one bit each
};

/// Counters, readable from any thread while the loop runs.
struct HapticCounters {
  std::uint64_t ticks = 0;             ///< ticks run
  std::uint64_t missed_deadlines = 0;  ///< tick-to-tick intervals > 2 periods
  std::uint64_t skipped_slots = 0;     ///< periods skipped to catch up after a long stall
  std::uint64_t non_finite = 0;        ///< ticks whose raw force/torque had NaN/Inf
  std::uint64_t clamped = 0;           ///< ticks whose force or torque was clamped
  std::uint64_t slew_limited = 0;      ///< ticks whose force or torque change was limited
  std::uint64_t stale_ticks = 0;       ///< ticks with stale tool or device state
  std::uint64_t stalls = 0;            ///< fresh -> stale transitions
  std::uint64_t snapshot_read_failures = 0;  ///< ticks whose bounded seqlock read gave up
  std::uint64_t device_failures = 0;   ///< ticks without a device sample
  std::uint64_t snapshots_received = 0;  ///< new snapshots read from the channel
  std::uint64_t passivity_violations = 0;  ///< ticks whose cumulative energy was below -passivity.tolerance
  double passivity_energy = 0.0;   ///< the cumulative energy put into the environment [J]
  double min_window_energy = 0.0;  ///< the least energy of any passivity.window ticks so far [J]
};

/// The haptic servo loop: each tick samples the device, interpolates the
/// tool's published state, renders the coupling force through the safety
/// filters and commands it, on its own thread (start) or called from a
/// device SDK's scheduler (tick). A tick allocates nothing, takes no lock
/// and does no I/O.
class HapticLoop {
 public:
  /// Checks the settings and preallocates everything a tick uses. The
  /// device, channels and clock must outlive the loop. Never throws: a
  /// failed allocation is an Error too.
  static Result<std::unique_ptr<HapticLoop>> create(const HapticLoopSettings& settings, HapticDevice& device,
                                                   SnapshotChannel& snapshots, FeedbackChannel& feedback,
                                                   Clock& clock);
  ~HapticLoop();  ///< stops the thread if running
  HapticLoop(const HapticLoop&) = delete;
  HapticLoop& operator=(const HapticLoop&) = delete;

  /// Starts the device and the loop thread; returns once the thread has
  /// set its scheduling (see scheduling()). Errors: already running, the
  /// device failed to start, the thread could not be created.
  Status start();
  /// Stops the thread and the device (the device is commanded zero force;
  /// a later start() ramps the force up again through the watchdog). Idempotent.
  void stop() noexcept;
  /// Whether the loop thread runs.
  [[nodiscard]] bool running() const { return running_.load(std::memory_order_acquire); }
  /// What the loop thread obtained; filled by start().
  [[nodiscard]] const SchedulingReport& scheduling() const { return scheduling_; }

  /// One tick at clock.now_ns(), on the calling thread: for virtual-clock
  /// tests and for devices whose SDK runs its own servo scheduler (call it
  /// from that callback; the device must then be started by the caller).
  /// Not while the loop thread runs (returns a record with tick == 0).
  /// From one thread at a time. A tick() that would overlap a
  /// copy_telemetry() on another thread (or another tick()) is skipped: it
  /// returns a record with tick == 0 at once and commands nothing, so an
  /// SDK callback should stop calling tick() before the telemetry is copied.
  TickRecord tick() noexcept;

  /// The loop's counters so far (ticks, clamps, stale ticks, ...).
  [[nodiscard]] HapticCounters counters() const;
  /// [out] out: the telemetry ring, oldest first (at most telemetry_capacity
  /// ticks). Only while the loop thread is not running and no tick() is in
  /// progress on another thread (an error otherwise, out unchanged): the
  /// ring is written without locks; a lock-free guard keeps an externally
  /// driven tick() (SDK servo callback) and the copy apart.
  Status copy_telemetry(std::vector<TickRecord>& out) const;
  /// The settings it was created with.
  [[nodiscard]] const HapticLoopSettings& settings() const { return settings_; }
  /// The newest rendered tool state (loop thread / manual ticker only).
  [[nodiscard]] const RenderedTool& rendered_tool() const { return tool_; }

 private:
  HapticLoop(const HapticLoopSettings& settings, HapticDevice& device, SnapshotChannel& snapshots,
             FeedbackChannel& feedback, Clock& clock);
  TickRecord tick_at(std::int64_t scheduled_ns, bool use_scheduled) noexcept;
  // The passivity controller (when on) on [in,out] force and torque, then
  // the observer on the command; fills rec's energies and returns
  // kPassivityViolation and kPassivityDamping bits.
  std::uint32_t observe_passivity(Vec3& force, Vec3& torque, TickRecord& rec) noexcept;
  void run();
  struct AtomicCounters {
    std::atomic<std::uint64_t> ticks{0}, missed{0}, skipped{0}, non_finite{0}, clamped{0}, slewed{0}, stale{0},
        stalls{0}, read_failures{0}, device_failures{0}, snapshots{0}, passivity{0};
    std::atomic<double> energy{0.0}, min_window{0.0};
  };

  HapticLoopSettings settings_;
  HapticDevice& device_;
  SnapshotChannel& snapshots_;
  FeedbackChannel& feedback_;
  Clock& clock_;
  std::int64_t period_ns_ = 0;

  // Tick state (loop thread or manual ticker only).
  SnapshotHistory history_;
  HapticSnapshot scratch_{};
  std::uint64_t last_version_ = 0;
  DeviceSample sample_{};
  bool have_sample_ = false;
  RenderedTool tool_{};
  VirtualCoupling coupling_;        // to the device
  VirtualCoupling drive_coupling_;  // to the physics' tool, when local contacts are rendered
  Watchdog watchdog_;
  PassivityObserver passivity_;
  bool have_prev_tick_ = false;
  std::int64_t prev_start_ns_ = 0;
  Vec3 prev_force_{}, prev_torque_{};
  Vec3 prev_rendered_force_{};      // commanded to the device by the previous tick
  LocalContactRenderer local_;
  CouplingFeedback fb_{};
  std::vector<TickRecord> ring_;  // preallocated
  std::uint64_t recorded_ = 0;
  // tick() vs copy_telemetry() from different threads: kIdle, kTicking or kCopying.
  enum : int { kIdle, kTicking, kCopying };
  mutable std::atomic<int> access_{kIdle};

  AtomicCounters counters_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_{false};
  std::atomic<bool> ready_{false};
  SchedulingReport scheduling_;
  std::thread thread_;
  int qos_fd_ = -1;  // /dev/cpu_dma_latency while held
};

/// Sets the calling thread's scheduling: SCHED_FIFO at `priority` when
/// `realtime`, pinned to `cpu` when >= 0; reports what it obtained
/// (pthread_getschedparam after the request) and why a request failed.
SchedulingReport set_thread_scheduling(bool realtime, int priority, int cpu);

/// Opens /dev/cpu_dma_latency and requests `microseconds` of CPU wake-up
/// latency; the request holds while the returned descriptor is open.
/// [out] report: "<n> us held" or why it failed. Returns -1 on failure.
int hold_cpu_latency(int microseconds, std::string& report);
/// Releases a request made by hold_cpu_latency (closes the descriptor; -1 is ignored).
void release_cpu_latency(int fd);

}  // namespace sinew::haptics
