// bench_haptic_loop — the haptic loop's timing while the solver runs a
// tissue scene at the same time: tick rate, period jitter (p50/p99/p99.9/max
// of |period - 1/rate|), wake-up latency, missed deadlines (tick-to-tick
// intervals > 2 periods), tick compute time, the age of the state rendered,
// allocations made in ticks after warm-up (a replaced operator new counting
// on the loop thread only), and the scheduling policy obtained.
//
// The physics thread steps a tissue block with a probe coupled to a scripted
// device that presses and strokes back and forth; by default it steps back
// to back (`--physics saturate`: with TBB on every core, the harshest load),
// or paced to the wall clock (`--physics paced`); `--physics none` only
// republishes the tool's state at 250 Hz (the platform's own timing, no solver).
//
// Writes <out>/<name>.json and <out>/<name>.csv (one summary row), and with
// --trace <out>/<name>_ticks.csv (every tick). Default out: ./bench_haptic_loop_out.
//
//   bench_haptic_loop --help   (the options, their defaults and units)
#include <sys/mman.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>
#include <vector>

#include "command_line.h"
#include "sinew/haptics/haptic_loop.h"
#include "sinew/haptics/scripted_device.h"
#include "sinew/haptics/tool_bridge.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "support/allocation_counter.h"

namespace {

using namespace sinew::haptics;

struct Options {
  double seconds = 20.0;
  double rate = 1000.0;
  bool realtime = true;
  bool zero_cpu_latency = false;
  int priority = 80;
  int cpu = -1;
  std::string physics = "saturate";
  int cells = 16;
  std::string out;
  std::string name = "haptic_loop";
  bool trace = false;
  bool mlock = false;
};

struct Stats {
  double p50 = 0, p99 = 0, p999 = 0, max = 0, mean = 0;
};

// Nearest-rank percentiles.
Stats stats(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const auto rank = [&](double q) {
    const std::size_t k = static_cast<std::size_t>(std::ceil(q * double(v.size())));
    return v[std::min(v.size() - 1, k == 0 ? 0 : k - 1)];
  };
  s.p50 = rank(0.50);
  s.p99 = rank(0.99);
  s.p999 = rank(0.999);
  s.max = v.back();
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / double(v.size());
  return s;
}

std::string json_stats(const Stats& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "{\"p50\": %.3f, \"p99\": %.3f, \"p99_9\": %.3f, \"max\": %.3f, \"mean\": %.3f}", s.p50,
                s.p99, s.p999, s.max, s.mean);
  return buf;
}

std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o;
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

// The 1-minute load average (other processes competing for the cores).
std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string one;
  in >> one;
  return one.empty() ? "unknown" : one;
}

int fail(const std::string& what) {
  std::fprintf(stderr, "bench_haptic_loop: %s\n", what.c_str());
  return 1;
}

constexpr double kCell = 0.004;

// Press 6 mm into the block, then stroke +-1.5 cm along x at 0.5 Hz.
ScriptedPose stroke(double t) {
  const double top = 5 * kCell, radius = 0.006, half = 0.015;
  const double down = std::min(1.0, t / 0.5);
  ScriptedPose p;
  p.position = {0.015 * std::sin(2 * M_PI * 0.5 * std::max(0.0, t - 0.5)),
                top + radius + half + 0.002 - 0.008 * (0.5 - 0.5 * std::cos(M_PI * down)), 0.0};
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  sinew::examples::CommandLine cli(
      "bench_haptic_loop",
      "The 1 kHz haptic loop's timing while the solver runs a tissue scene with a probe on the other thread:\n"
      "tick rate, period jitter, wake-up latency, missed deadlines, tick compute time, the state's age,\n"
      "allocations in ticks and the scheduling obtained. Writes <out>/<name>.json and .csv (and with --trace\n"
      "<name>_ticks.csv, every tick).");
  using sinew::examples::at_least;
  auto& app = cli.app();
  opt.out = cli.default_out();
  app.add_option("--seconds", opt.seconds, "Length of the run [s]")->check(at_least(2));
  // The rate is checked with the loop's settings (a clear error for 0, nan, ...).
  app.add_option("--rate", opt.rate, "Haptic loop rate [Hz]");
  app.add_flag_callback("--no-realtime", [&opt] { opt.realtime = false; }, "Do not ask for SCHED_FIFO for the haptic thread");
  app.add_flag("--zero-cpu-latency", opt.zero_cpu_latency, "Hold /dev/cpu_dma_latency at 0 during the run");
  app.add_option("--priority", opt.priority, "SCHED_FIFO priority, 1..99")->check(CLI::Range(1, 99));
  app.add_option("--cpu", opt.cpu, "Pin the haptic thread to this CPU (-1: not pinned)")->check(at_least(-1));
  app.add_option("--physics", opt.physics, "saturate (back to back), paced (250 Hz of wall time) or none")
      ->check(CLI::IsMember({"saturate", "paced", "none"}));
  app.add_option("--cells", opt.cells, "The block's cells along x and z (4 mm each)")->check(at_least(2));
  app.add_option("--name", opt.name, "Base name of the files written");
  app.add_flag("--trace", opt.trace, "Also write every tick to <name>_ticks.csv");
  app.add_flag("--mlock", opt.mlock, "Lock the process's memory (mlockall) before the run");
  cli.add_out(opt.out);
  if (auto exit = cli.parse(argc, argv)) return *exit;
  const std::string load_at_start = load_average();
  std::string mlock_report = "not requested";
  if (opt.mlock)
    mlock_report = mlockall(MCL_CURRENT | MCL_FUTURE) == 0 ? "locked" : std::string("failed: ") + std::strerror(errno);

  // The tissue scene (as examples/haptic_drag): a block pinned at its bottom, a probe.
  const int n = opt.cells;
  auto mesh = sinew::make_tet_grid({.nx = n, .ny = 5, .nz = n, .origin = {-n * kCell / 2, 0.0, -n * kCell / 2},
                                    .cell_size = {kCell, kCell, kCell}});
  if (!mesh) return fail(mesh.error().message());
  sinew::TetBodyDesc body;
  body.mesh = std::move(*mesh);
  if (auto s = body.set_elastic(300e3, 0.4); !s) return fail(s.error().message());
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] < 1e-9) body.pinned.push_back(v);
  sinew::SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 250.0, .substeps = 5, .iterations = 2, .measure_errors = false};
  scene.tet_bodies.push_back(std::move(body));
  sinew::ToolDesc probe;
  probe.radius = 0.006;
  probe.half_height = 0.015;
  probe.mass = 0.5;
  probe.inertia = {4e-5, 9e-6, 4e-5};
  probe.position = stroke(0.0).position;
  probe.gravity = false;
  scene.tools.push_back(probe);
  auto sim = sinew::Simulation::create(scene, {.backend = "cpu", .quiet = true});
  if (!sim) return fail(sim.error().message());

  MonotonicClock clock;
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  ScriptedDevice device(stroke);
  HapticLoopSettings settings;
  settings.rate_hz = opt.rate;
  settings.realtime = opt.realtime;
  settings.realtime_priority = opt.priority;
  settings.zero_cpu_latency = opt.zero_cpu_latency;
  settings.cpu = opt.cpu;
  settings.coupling.damping = 3.0;
  // The rate sizes the telemetry below: the loop's own check first (a clear error for --rate nan, 0, ...).
  if (auto s = check(settings); !s) return fail(s.error().message());
  settings.telemetry_capacity = static_cast<std::size_t>((opt.seconds + 2.0) * opt.rate);
  settings.on_thread_start = [] { sinew::support::track_this_thread(); };  // counts the ticks' allocations
  auto loop = HapticLoop::create(settings, device, snapshots, feedback, clock);
  if (!loop) return fail(loop.error().message());
  HapticToolBridge bridge(0, snapshots, feedback, clock);
  if (auto s = bridge.set_damping(5.0, 2e-3); !s) return fail(s.error().message());
  if (auto s = bridge.publish(*sim); !s) return fail(s.error().message());

  const std::int64_t t0 = clock.now_ns();
  device.set_origin(t0);
  if (auto s = (*loop)->start(); !s) return fail(s.error().message());
  const SchedulingReport sched = (*loop)->scheduling();
  std::printf("bench_haptic_loop: %.0f Hz for %.0f s, %u particles, physics %s; haptic thread %s\n", opt.rate,
              opt.seconds, sim->info().particles, opt.physics.c_str(), sched.describe().c_str());

  // Physics on this thread until the end; counting starts after 1 s of warm-up.
  const double warmup = 1.0;
  const std::int64_t count_from = t0 + seconds_to_ns(warmup);
  const std::int64_t end = t0 + seconds_to_ns(opt.seconds);
  std::uint64_t frames = 0;
  double step_ms = 0.0;
  while (clock.now_ns() < end) {
    if (clock.now_ns() >= count_from) sinew::support::set_tracking(true);
    if (opt.physics != "none") {
      if (auto s = bridge.apply_feedback(*sim); !s) return fail(s.error().message());
      if (auto s = sim->step(); !s) return fail(s.error().message());
      step_ms += sim->last_frame().wall_ms;
    }
    if (auto s = bridge.publish(*sim); !s) return fail(s.error().message());
    ++frames;
    if (opt.physics != "saturate") clock.sleep_until(t0 + seconds_to_ns(double(frames) * scene.solver.time_step));
  }
  (*loop)->stop();
  sinew::support::set_tracking(false);
  const std::uint64_t tick_allocations = sinew::support::tracked_allocation_count();

  // ------------------------------------------------------------ statistics (after warm-up)
  std::vector<TickRecord> ticks;
  if (auto s = (*loop)->copy_telemetry(ticks); !s) return fail(s.error().message());
  ticks.erase(ticks.begin(), std::find_if(ticks.begin(), ticks.end(),
                                          [&](const TickRecord& r) { return r.start_ns >= count_from; }));
  if (ticks.size() < 100) return fail("too few ticks after warm-up");
  const double period_us = 1e6 / opt.rate;
  std::vector<double> jitter, latency, compute, snap_age, render_age;
  std::uint64_t missed = 0;
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    const TickRecord& r = ticks[i];
    latency.push_back(1e-3 * double(r.start_ns - r.scheduled_ns));
    compute.push_back(1e-3 * double(r.end_ns - r.start_ns));
    snap_age.push_back(1e3 * r.snapshot_age);
    render_age.push_back(1e3 * r.render_age);
    if (i == 0) continue;
    const double p = 1e-3 * double(r.start_ns - ticks[i - 1].start_ns);
    jitter.push_back(std::abs(p - period_us));
    if (p > 2 * period_us) ++missed;
  }
  const double span = ns_to_seconds(ticks.back().start_ns - ticks.front().start_ns);
  const double rate = double(ticks.size() - 1) / span;
  const Stats j = stats(jitter), l = stats(latency), c = stats(compute), sa = stats(snap_age), ra = stats(render_age);
  const HapticCounters counters = (*loop)->counters();
  const bool rate_ok = std::abs(rate - opt.rate) <= 0.005 * opt.rate;
  const bool goals = rate_ok && j.p99 <= 100.0 && j.p999 <= 250.0 && tick_allocations == 0;

  utsname u{};
  uname(&u);
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  const std::string base = opt.out + "/" + opt.name;
  {
    std::FILE* f = std::fopen((base + ".json").c_str(), "w");
    if (!f) return fail("cannot write " + base + ".json");
    std::fprintf(f, "{\n");
    std::fprintf(f, "  \"benchmark\": \"bench_haptic_loop\",\n");
    std::fprintf(f, "  \"machine\": {\"cpu\": \"%s\", \"cores\": %ld, \"kernel\": \"%s %s\", "
                    "\"load_average_1min_at_start\": \"%s\"},\n",
                 escape(cpu_model()).c_str(), cores, u.sysname, u.release, load_at_start.c_str());
    std::fprintf(f, "  \"scheduling\": {\"requested\": \"%s\", \"policy\": \"%s\", \"priority\": %d, \"cpu\": %d, "
                    "\"error\": \"%s\", \"cpu_wakeup_latency_pm_qos\": \"%s\"},\n",
                 escape(sched.requested).c_str(), sched.policy.c_str(), sched.priority, sched.cpu,
                 escape(sched.error).c_str(), escape(sched.cpu_latency).c_str());
    std::fprintf(f, "  \"mlockall\": \"%s\",\n", escape(mlock_report).c_str());
    std::fprintf(f, "  \"physics\": {\"mode\": \"%s\", \"particles\": %u, \"frames\": %llu, \"step_ms_mean\": %.3f, "
                    "\"frame_s\": %.4f},\n",
                 opt.physics.c_str(), sim->info().particles, static_cast<unsigned long long>(frames),
                 step_ms / double(frames), scene.solver.time_step);
    std::fprintf(f, "  \"rate_hz_target\": %.1f,\n  \"seconds_measured\": %.3f,\n  \"ticks\": %zu,\n", opt.rate, span,
                 ticks.size());
    std::fprintf(f, "  \"rate_hz\": %.3f,\n", rate);
    std::fprintf(f, "  \"period_jitter_us\": %s,\n", json_stats(j).c_str());
    std::fprintf(f, "  \"wake_latency_us\": %s,\n", json_stats(l).c_str());
    std::fprintf(f, "  \"missed_deadlines\": %llu,\n", static_cast<unsigned long long>(missed));
    std::fprintf(f, "  \"tick_compute_us\": %s,\n", json_stats(c).c_str());
    std::fprintf(f, "  \"snapshot_age_ms\": %s,\n", json_stats(sa).c_str());
    std::fprintf(f, "  \"render_age_ms\": %s,\n", json_stats(ra).c_str());
    std::fprintf(f, "  \"tick_allocations_after_warmup\": %llu,\n", static_cast<unsigned long long>(tick_allocations));
    std::fprintf(f, "  \"stale_ticks\": %llu,\n  \"skipped_slots\": %llu,\n",
                 static_cast<unsigned long long>(counters.stale_ticks),
                 static_cast<unsigned long long>(counters.skipped_slots));
    std::fprintf(f, "  \"goals\": {\"rate_within_0.5pct\": %s, \"jitter_p99_le_100us\": %s, "
                    "\"jitter_p99_9_le_250us\": %s, \"zero_tick_allocations\": %s, \"all\": %s}\n",
                 rate_ok ? "true" : "false", j.p99 <= 100.0 ? "true" : "false", j.p999 <= 250.0 ? "true" : "false",
                 tick_allocations == 0 ? "true" : "false", goals ? "true" : "false");
    std::fprintf(f, "}\n");
    std::fclose(f);
  }
  {
    std::FILE* f = std::fopen((base + ".csv").c_str(), "w");
    if (!f) return fail("cannot write " + base + ".csv");
    std::fprintf(f, "policy,priority,pm_qos,physics,particles,rate_target_hz,rate_hz,ticks,jitter_p50_us,jitter_p99_us,"
                    "jitter_p99_9_us,jitter_max_us,latency_p50_us,latency_p99_us,latency_max_us,missed_deadlines,"
                    "compute_p50_us,compute_p99_us,compute_max_us,snapshot_age_p50_ms,snapshot_age_max_ms,"
                    "render_age_p50_ms,render_age_max_ms,tick_allocations,physics_step_ms\n");
    std::fprintf(f, "%s,%d,%s,%s,%u,%.1f,%.3f,%zu,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%llu,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,"
                    "%.3f,%llu,%.3f\n",
                 sched.policy.c_str(), sched.priority, sched.cpu_latency == "0 us held" ? "0us" : "none",
                 opt.physics.c_str(), sim->info().particles, opt.rate, rate,
                 ticks.size(), j.p50, j.p99, j.p999, j.max, l.p50, l.p99, l.max, static_cast<unsigned long long>(missed),
                 c.p50, c.p99, c.max, sa.p50, sa.max, ra.p50, ra.max, static_cast<unsigned long long>(tick_allocations),
                 step_ms / double(frames));
    std::fclose(f);
  }
  if (opt.trace) {
    std::FILE* f = std::fopen((base + "_ticks.csv").c_str(), "w");
    if (!f) return fail("cannot write " + base + "_ticks.csv");
    std::fprintf(f, "tick,scheduled_ns,start_ns,end_ns,snapshot_age_ms,render_age_ms,force_x,force_y,force_z,flags\n");
    for (const TickRecord& r : ticks)
      std::fprintf(f, "%llu,%lld,%lld,%lld,%.4f,%.4f,%.5f,%.5f,%.5f,%u\n", static_cast<unsigned long long>(r.tick),
                   static_cast<long long>(r.scheduled_ns - t0), static_cast<long long>(r.start_ns - t0),
                   static_cast<long long>(r.end_ns - t0), 1e3 * r.snapshot_age, 1e3 * r.render_age, r.force[0],
                   r.force[1], r.force[2], r.flags);
    std::fclose(f);
  }

  std::printf("rate %.3f Hz (target %.0f), period jitter p50 %.1f / p99 %.1f / p99.9 %.1f / max %.1f us, "
              "wake latency p99 %.1f us, %llu missed deadlines (> 2 periods)\n",
              rate, opt.rate, j.p50, j.p99, j.p999, j.max, l.p99, static_cast<unsigned long long>(missed));
  std::printf("tick compute p50 %.2f / p99 %.2f / max %.1f us; state age (newest snapshot) p50 %.2f / max %.2f ms, "
              "rendered p50 %.2f / max %.2f ms; %llu allocations in ticks after warm-up\n",
              c.p50, c.p99, c.max, sa.p50, sa.max, ra.p50, ra.max, static_cast<unsigned long long>(tick_allocations));
  std::printf("physics: %llu frames, %.3f ms per step; goals (rate +-0.5%%, p99 <= 100 us, p99.9 <= 250 us, "
              "0 allocations): %s\nwrote %s.json and %s.csv\n",
              static_cast<unsigned long long>(frames), step_ms / double(frames), goals ? "met" : "NOT met",
              base.c_str(), base.c_str());
  return 0;
}
