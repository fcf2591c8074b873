// haptic_drag — a rigid probe pressed into a block of soft tissue and
// dragged across it by a scripted haptic device, through the real haptic
// loop: a 1 kHz thread (SCHED_FIFO when granted) renders the virtual
// coupling (Colgate et al. 1995) to the device while this thread steps the
// physics at 250 Hz, paced to the wall clock, and drives the probe with
// minus the coupling force averaged over each frame. With --clock virtual
// the same loop is ticked between the frames on a virtual clock
// (haptics::ScriptedHands): the run is the same every time, and it is what
// scenes/haptic_drag.json gives through `sinew run`.
//
// Writes into the output folder:
//   force_trace.csv   every haptic tick: time, device and rendered tool
//                     position, the force commanded to the device, gain, flags
//   frames.csv        every physics frame: tool position, contact force from
//                     the tissue, force applied to the tool
//   force_trace.png   the force trace and the positions (when gnuplot exists)
//   haptic_drag.pvd   every 25th frame (10 a second): the tissue
//                     (tissue_<frame>.vtu) and the probe (tool0_<frame>.vtu)
//
//   haptic_drag --help   (the options, their defaults and units)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "command_line.h"
#include "sinew/haptics/haptic_loop.h"
#include "sinew/haptics/keyframe_path.h"
#include "sinew/haptics/scripted_device.h"
#include "sinew/haptics/scripted_hands.h"
#include "sinew/haptics/tool_bridge.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"

namespace {

using namespace sinew::haptics;
using sinew::Result;

struct Options {
  std::string out;
  std::string backend = "cpu";
  double rate = 1000.0;
  bool realtime = true;
  std::string clock = "wall";  // or "virtual"
};

// The block: 6.4 x 2 x 6.4 cm, 4 mm cells, its top face at y = 2 cm, centred on x = z = 0.
constexpr double kCell = 0.004, kTop = 5 * kCell;
// The probe: a vertical capsule, radius 6 mm, 4.2 cm long, its tip 5 mm above the tissue.
constexpr double kRadius = 0.006, kHalfHeight = 0.015;
constexpr double kStartY = kTop + 0.005 + kRadius + kHalfHeight;
constexpr double kPress = 0.012;  // down 12 mm: the tip 7 mm below the surface (less the coupling's stretch)
constexpr double kDrag = 0.02;    // then 2 cm along x
constexpr double kDuration = 5.0;  // [s]

// The scripted hand: hold, press down (0.5-1.5 s), hold, drag sideways
// (2-3.5 s), hold, lift (4-4.6 s); cosine ramps between the keys, so the
// hand starts and stops at rest.
Result<KeyframePath> hand_path() {
  const double x0 = -0.01, x1 = x0 + kDrag, down = kStartY - kPress;
  return KeyframePath::create({{.time = 0.0, .position = {x0, kStartY, 0.0}},
                               {.time = 0.5, .position = {x0, kStartY, 0.0}},
                               {.time = 1.5, .position = {x0, down, 0.0}},
                               {.time = 2.0, .position = {x0, down, 0.0}},
                               {.time = 3.5, .position = {x1, down, 0.0}},
                               {.time = 4.0, .position = {x1, down, 0.0}},
                               {.time = 4.6, .position = {x1, kStartY, 0.0}}},
                              PathInterpolation::smooth);
}

int fail(const std::string& what) {
  std::fprintf(stderr, "haptic_drag: %s\n", what.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  sinew::examples::CommandLine cli(
      "haptic_drag",
      "A rigid probe pressed into a block of soft tissue and dragged across it by a scripted haptic device,\n"
      "through the real 1 kHz haptic loop (virtual coupling) while the physics steps at 250 Hz, for 5 s.\n"
      "Writes into --out: force_trace.csv (every haptic tick), frames.csv (every physics frame),\n"
      "force_trace.png (with gnuplot), haptic_drag.pvd (the tissue) and probe.pvd (the probe).");
  opt.out = cli.default_out();
  cli.add_backend(opt.backend);
  // The rate is checked with the loop's settings below (a clear error for 0, nan, ...).
  cli.app().add_option("--rate", opt.rate, "Haptic loop rate [Hz]");
  cli.app().add_flag_callback("--no-realtime", [&opt] { opt.realtime = false; }, "Run the haptic thread without asking for SCHED_FIFO");
  cli.app()
      .add_option("--clock", opt.clock,
                   "wall: the haptic loop on its own thread, the physics paced to the wall clock; virtual: the loop "
                   "ticked between the frames on a virtual clock (the same run every time, as `sinew run "
                   "scenes/haptic_drag.json`)")
      ->check(CLI::IsMember({"wall", "virtual"}));
  cli.add_out(opt.out);
  if (auto exit = cli.parse(argc, argv)) return *exit;

  // ------------------------------------------------------------ the scene
  auto mesh = sinew::make_tet_grid({.nx = 16, .ny = 5, .nz = 16, .origin = {-8 * kCell, 0.0, -8 * kCell},
                                    .cell_size = {kCell, kCell, kCell}});
  if (!mesh) return fail(mesh.error().message());
  sinew::TetBodyDesc body;
  body.mesh = std::move(*mesh);
  body.density = 1000.0;
  if (auto s = body.set_elastic(300e3, 0.4); !s) return fail(s.error().message());  // E = 300 kPa
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] < 1e-9) body.pinned.push_back(v);

  sinew::SceneDesc scene;
  scene.gravity = {0.0, -9.81, 0.0};
  // 250 Hz frames: the coupled probe sees the physics one frame late
  // (interpolation), so frames must be short against its coupled period
  // 2 pi sqrt(M / K) = 0.2 s (README, haptics).
  scene.solver = {.time_step = 1.0 / 250.0, .substeps = 5, .iterations = 2, .measure_errors = false};
  scene.tet_bodies.push_back(std::move(body));
  sinew::ToolDesc probe;
  probe.radius = kRadius;
  probe.half_height = kHalfHeight;
  probe.mass = 0.5;  // [kg], heavy against the tissue's 0.1 g particles
  const double r2 = kRadius * kRadius, l2 = 4 * kHalfHeight * kHalfHeight;
  probe.inertia = {probe.mass * (3 * r2 + l2) / 12, probe.mass * r2 / 2, probe.mass * (3 * r2 + l2) / 12};
  probe.position = {-0.01, kStartY, 0.0};
  probe.gravity = false;  // the hand carries the instrument
  probe.static_friction = 0.4;
  probe.dynamic_friction = 0.3;
  scene.tools.push_back(probe);

  auto sim = sinew::Simulation::create(scene, {.backend = opt.backend, .quiet = true});
  if (!sim) return fail(sim.error().message());
  const auto probe_id = sim->tools().tool(0);
  if (!probe_id) return fail(probe_id.error().message());

  // ------------------------------------------------------------ the haptic side
  auto path = hand_path();
  if (!path) return fail(path.error().message());
  HapticLoopSettings settings;
  settings.rate_hz = opt.rate;
  settings.realtime = opt.realtime;
  settings.coupling.damping = 3.0;  // [N s/m]: damps the probe's free swing, still passive (> K T / 2)
  // The rate sizes the telemetry below: the loop's own check first (a clear error for --rate nan, 0, ...).
  if (auto s = check(settings); !s) return fail(s.error().message());
  settings.telemetry_capacity = static_cast<std::size_t>((kDuration + 1.0) * opt.rate);
  // Damps the probe's swing on the coupling spring (not felt; tool_bridge.h).
  constexpr double kToolDamping = 5.0, kToolAngularDamping = 2e-3;
  const bool virtual_clock = opt.clock == "virtual";

  // Wall clock: the loop on its own thread, a bridge on this one.
  MonotonicClock clock;
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  ScriptedDevice device(path->script());
  std::unique_ptr<HapticLoop> loop;
  std::optional<HapticToolBridge> bridge;
  // Virtual clock: the same loop, ticked between the frames.
  std::unique_ptr<ScriptedHands> hands;
  std::int64_t t0 = 0;
  if (virtual_clock) {
    auto made = ScriptedHands::create({{.tool = 0, .path = *path, .loop = settings, .tool_damping = kToolDamping,
                                        .tool_angular_damping = kToolAngularDamping}},
                                      *sim, scene.solver.time_step);
    if (!made) return fail(made.error().message());
    hands = std::move(*made);
    std::printf("haptic_drag on %s: %u particles; haptic loop at %.0f Hz on a virtual clock\n",
                sim->device_name().c_str(), sim->info().particles, opt.rate);
  } else {
    auto made = HapticLoop::create(settings, device, snapshots, feedback, clock);
    if (!made) return fail(made.error().message());
    loop = std::move(*made);
    bridge.emplace(0, snapshots, feedback, clock);
    if (auto s = bridge->set_damping(kToolDamping, kToolAngularDamping); !s) return fail(s.error().message());
    if (auto s = bridge->publish(*sim); !s) return fail(s.error().message());
    t0 = clock.now_ns() + seconds_to_ns(0.01);
    device.set_origin(t0);
    if (auto s = loop->start(); !s) return fail(s.error().message());
    std::printf("haptic_drag on %s: %u particles; haptic loop at %.0f Hz, %s\n", sim->device_name().c_str(),
                sim->info().particles, opt.rate, loop->scheduling().describe().c_str());
  }
  const HapticLoop& the_loop = virtual_clock ? hands->loop(0) : *loop;
  const HapticToolBridge& the_bridge = virtual_clock ? hands->bridge(0) : *bridge;

  // The tissue named as in scenes/haptic_drag.json: the runner's output of it is the same.
  auto output = sinew::SceneOutput::create(scene, opt.out, {.bodies = {{.name = "tissue"}}, .name = "haptic_drag"});
  if (!output) return fail(output.error().message());
  if (auto s = output->write(*sim, 0); !s) return fail(s.error().message());

  // ------------------------------------------------------------ physics, paced to the wall clock (or not)
  const double dt = scene.solver.time_step;
  const int frames = static_cast<int>(std::lround(kDuration / dt));
  std::FILE* frames_csv = std::fopen((opt.out + "/frames.csv").c_str(), "w");
  if (!frames_csv) return fail("cannot write " + opt.out + "/frames.csv");
  std::fprintf(frames_csv, "time,tool_x,tool_y,tool_z,contact_fx,contact_fy,contact_fz,tool_force_x,tool_force_y,"
                           "tool_force_z,step_ms\n");
  int late = 0;
  double step_ms_max = 0.0, step_ms_sum = 0.0;
  for (int f = 1; f <= frames; ++f) {
    if (auto s = virtual_clock ? hands->before_step(*sim) : bridge->apply_feedback(*sim); !s)
      return fail(s.error().message());
    if (auto s = sim->step(); !s) return fail(s.error().message());
    if (auto s = virtual_clock ? hands->after_step(*sim) : bridge->publish(*sim); !s) return fail(s.error().message());
    step_ms_max = std::max(step_ms_max, sim->last_frame().wall_ms);
    step_ms_sum += sim->last_frame().wall_ms;
    auto tool = sim->tools().state(*probe_id);
    if (!tool) return fail(tool.error().message());
    const Vec3& applied = the_bridge.last_tool_force();
    std::fprintf(frames_csv, "%.4f,%.6f,%.6f,%.6f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.3f\n", f * dt, tool->position[0],
                 tool->position[1], tool->position[2], tool->contact_force[0], tool->contact_force[1],
                 tool->contact_force[2], applied[0], applied[1], applied[2], sim->last_frame().wall_ms);
    if (f % 25 == 0 || f == frames)  // 10 VTU frames per second
      if (auto s = output->write(*sim, f); !s) return fail(s.error().message());
    if (virtual_clock) continue;
    const std::int64_t next = t0 + seconds_to_ns(f * dt);
    if (clock.now_ns() > next) ++late;
    clock.sleep_until(next);
  }
  if (loop) loop->stop();
  std::fclose(frames_csv);

  // ------------------------------------------------------------ outputs
  std::vector<TickRecord> ticks;
  if (auto s = the_loop.copy_telemetry(ticks); !s) return fail(s.error().message());
  const std::string trace = opt.out + "/force_trace.csv";
  std::FILE* csv = std::fopen(trace.c_str(), "w");
  if (!csv) return fail("cannot write " + trace);
  std::fprintf(csv, "time,device_x,device_y,device_z,tool_x,tool_y,tool_z,force_x,force_y,force_z,force,gain,"
                    "snapshot_age_ms,flags\n");
  double peak = 0.0;
  for (const TickRecord& r : ticks) {
    const double mag = std::sqrt(r.force[0] * r.force[0] + r.force[1] * r.force[1] + r.force[2] * r.force[2]);
    peak = std::max(peak, mag);
    std::fprintf(csv, "%.4f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.5f,%.5f,%.5f,%.5f,%.3f,%.3f,%u\n",
                 ns_to_seconds(r.start_ns - t0), r.device_position[0], r.device_position[1], r.device_position[2],
                 r.tool_position[0], r.tool_position[1], r.tool_position[2], r.force[0], r.force[1], r.force[2], mag,
                 r.gain, 1e3 * r.snapshot_age, r.flags);
  }
  std::fclose(csv);

  const std::string plot = opt.out + "/force_trace.png";
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    const std::string gp = opt.out + "/force_trace.gp";
    if (std::FILE* g = std::fopen(gp.c_str(), "w")) {
      std::fprintf(g,
                   "set terminal pngcairo size 1000,700 font 'sans,10'\n"
                   "set output '%s'\n"
                   "set datafile separator ','\n"
                   "set multiplot layout 2,1\n"
                   "set grid; set key top left\n"
                   "set title 'haptic_drag: force commanded to the device (1 kHz haptic loop)' noenhanced\n"
                   "set ylabel 'force [N]'\n"
                   "plot '%s' using 1:8 with lines lw 1.5 title 'F_x (drag)', '' using 1:9 with lines lw 1.5 "
                   "title 'F_y (press)', '' using 1:11 with lines lc rgb '#444444' title '|F|'\n"
                   "set title 'device and rendered tool'\n"
                   "set xlabel 'time [s]'; set ylabel 'position [mm]'\n"
                   "plot '%s' using 1:($2*1e3) with lines title 'device x', '' using 1:($5*1e3) with lines dt 2 "
                   "title 'tool x', '' using 1:($3*1e3) with lines title 'device y', '' using 1:($6*1e3) with lines "
                   "dt 2 title 'tool y'\n"
                   "unset multiplot\n",
                   plot.c_str(), trace.c_str(), trace.c_str());
      std::fclose(g);
      const std::string cmd = "gnuplot '" + gp + "'";
      if (std::system(cmd.c_str()) != 0) std::printf("gnuplot failed: no plot\n");
      else std::printf("wrote %s\n", plot.c_str());
    }
  } else {
    std::printf("gnuplot not found (apt-get install gnuplot-nox): no plot, CSV only\n");
  }

  const HapticCounters c = the_loop.counters();
  std::printf("%llu ticks, %llu missed deadlines (> 2 periods), %llu stale ticks, %llu clamped, %llu slew-limited; "
              "peak device force %.2f N\n",
              static_cast<unsigned long long>(c.ticks), static_cast<unsigned long long>(c.missed_deadlines),
              static_cast<unsigned long long>(c.stale_ticks), static_cast<unsigned long long>(c.clamped),
              static_cast<unsigned long long>(c.slew_limited), peak);
  std::printf("%d physics frames of %.1f ms: step %.2f ms mean, %.2f ms max", frames, 1e3 * dt,
              step_ms_sum / frames, step_ms_max);
  if (virtual_clock) std::printf(" (on the virtual clock: not paced)\n");
  else std::printf(", %d started late\n", late);
  std::printf("wrote %s and %s/frames.csv; open %s/haptic_drag.pvd in ParaView\n", trace.c_str(), opt.out.c_str(),
              opt.out.c_str());
  return 0;
}
