// bone_burr — a burr cuts a groove across the tibia's plateau. A scripted
// haptic device drives the burr, a rigid tool shaped by a level set,
// through the virtual coupling (Colgate et al. 1995); the bone is a
// level-set collider built from the tibia's surface with its inside stored;
// each tick the burr's penalty against the bone (voxmap-pointshell,
// ToolDesc) pushes it back and the bone it presses deeper than --cut-depth
// is removed (ToolDesc::cuts: the bone cut along the burr's motion after
// every frame), so the force the hand feels while cutting is the penalty
// at that depth. Physics and the haptic loop run in lockstep at 1 kHz on a
// virtual clock (haptics::ScriptedHands: deterministic, and what
// `sinew run scenes/bone_burr.json` gives); the wall time of each tick's
// work is measured and reported against the 1 ms a tick has.
//
// Writes into the output folder:
//   force_trace.csv   every tick: time, device and burr position, the force
//                     rendered to the device, the bone's push on the burr,
//                     its points in the bone, the removed volume so far, and
//                     the tick's wall time split into step, cut and haptics
//   force_trace.png   the force and the removed volume (when gnuplot exists)
//   bone_*.vtu        the bone's surface around the groove (triangles),
//   bone_burr.pvd     every --surface-every ticks, as a ParaView series
//   burr_*.vtu,       the burr's surface at the same ticks
//   burr.pvd
//   scene.pvd         the whole scene (the bone's whole surface and the burr,
//                     the runner's blocks) at the first and the last tick
//
//   bone_burr --help   (the options, their defaults and units)
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "command_line.h"
#include "sinew/haptics/clock.h"
#include "sinew/haptics/haptic_loop.h"
#include "sinew/haptics/keyframe_path.h"
#include "sinew/haptics/scripted_hands.h"
#include "sinew/level_set.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"
#include "tool_surface.h"

namespace {

using namespace sinew::haptics;
using Wall = std::chrono::steady_clock;

struct Options {
  std::string out;
  std::string backend = "cpu";
  double voxel = 2.5e-4;      // the bone's voxel [m]
  double cut_depth = 1e-4;    // the burr removes bone it presses deeper than this [m]
  int surface_every = 500;    // ticks between bone surfaces written
};

// The burr: a 4 mm ball (radius 2 mm) on a handpiece of 30 g, whose inertia
// (a 10 cm pen) keeps the coupling's rotational gains stable at 1 kHz.
constexpr double kRadius = 2e-3, kMass = 0.03;
// Its penalty: pressed 0.25 mm into a flat face it feels k pi d^2 (R - d/3)
// = 1 N; its contact stiffness there, 2 k pi R d ~ 8e3 N/m, keeps
// sqrt(k_contact / M) dt = 0.5 below 2 at 1 kHz (ToolDesc).
constexpr double kStiffness = 2.66e9, kDamping = 2e6;
constexpr double kTick = 1e-3;  // [s]: physics and haptics at 1 kHz
constexpr int kKeyEvery = 10;   // ticks between the hand path's keys

// The script, relative to the plateau's surface under the device: from 3
// mm above it down to 4 mm below over 1.5 s (the coupling's spring
// stretches a few mm while the burr cuts), a 10 mm groove along y over 4
// s, then out to 8 mm above over 1 s (clear of the slopes beside it).
constexpr double kAbove = 3e-3, kBelow = 4e-3, kLift = 8e-3, kGroove = 0.01;
constexpr double kDown = 1.5, kAlong = 4.0, kUp = 1.0, kDuration = 0.3 + kDown + kAlong + kUp + 0.2;

// Smooth 0 -> 1 over [a, b] (cosine ramp: zero velocity at both ends).
double ramp(double t, double a, double b) {
  if (t <= a) return 0.0;
  if (t >= b) return 1.0;
  return 0.5 - 0.5 * std::cos(M_PI * (t - a) / (b - a));
}

// The surface's height at (top x, y): the highest triangle over that point
// below top z + 5 mm (the same arithmetic as scenes/generators/bone_burr.py).
double plateau_height(const sinew::TriMesh& mesh, const std::array<double, 3>& top, double y0, double y) {
  double best = -std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.triangles) {
    const auto& a = mesh.vertices[t[0]];
    const auto& b = mesh.vertices[t[1]];
    const auto& c = mesh.vertices[t[2]];
    // Only triangles near the groove (the generator's prefilter).
    if (!(std::min({a[0], b[0], c[0]}) <= top[0] && top[0] <= std::max({a[0], b[0], c[0]}) &&
          std::max({a[1], b[1], c[1]}) >= y0 - 1e-3 && std::min({a[1], b[1], c[1]}) <= y0 + kGroove + 1e-3))
      continue;
    const double d = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1]);
    if (d == 0.0) continue;
    const double u = ((b[1] - c[1]) * (top[0] - c[0]) + (c[0] - b[0]) * (y - c[1])) / d;
    const double v = ((c[1] - a[1]) * (top[0] - c[0]) + (a[0] - c[0]) * (y - c[1])) / d;
    if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
    const double z = u * a[2] + v * b[2] + (1.0 - u - v) * c[2];
    if (z <= top[2] + 5e-3) best = std::max(best, z);
  }
  return best;
}

int fail(const std::string& what) {
  std::fprintf(stderr, "bone_burr: %s\n", what.c_str());
  return 1;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * double(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}
double ms_since(Wall::time_point t) { return std::chrono::duration<double, std::milli>(Wall::now() - t).count(); }

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  sinew::examples::CommandLine cli(
      "bone_burr",
      "A burr cuts a groove across the tibia's plateau: a scripted haptic device drives the burr (a level-set\n"
      "tool) through the virtual coupling, physics and haptics in lockstep at 1 kHz on a virtual clock; the\n"
      "bone it presses deeper than --cut-depth is removed. Writes into --out: force_trace.csv (every tick),\n"
      "force_trace.png (with gnuplot), bone_burr.pvd (the bone's surface around the groove), burr.pvd and\n"
      "scene.pvd (the whole scene at the first and last tick, as `sinew run scenes/bone_burr.json` writes it).");
  opt.out = cli.default_out();
  cli.add_backend(opt.backend);
  cli.app().add_option("--voxel", opt.voxel, "The bone's voxel size [m]")->check(sinew::examples::greater_than(0));
  cli.app().add_option("--cut-depth", opt.cut_depth, "Bone pressed deeper than this is removed [m], below the burr's "
                                                     "2 mm radius")
      ->check([](const std::string& v) {
        double d = 0.0;
        if (CLI::detail::lexical_cast(v, d) && d >= 0.0 && d < kRadius) return std::string();
        return "must be in [0, 0.002) m (got " + v + ")";
      });
  cli.app().add_option("--surface-every", opt.surface_every, "Ticks (of 1 ms) between the surfaces written")
      ->check(sinew::examples::at_least(1));
  cli.add_out(opt.out);
  if (auto exit = cli.parse(argc, argv)) return *exit;

  // ------------------------------------------------------------ the bone
  const std::string stl = std::string(SINEW_DATA_DIR) + "/meshes/surface/VHF_Left_Bone_Tibia_smooth.stl";
  auto mesh = sinew::read_stl(stl);
  if (!mesh) return fail(mesh.error().message());
  sinew::scale_mesh(*mesh, 1e-3);  // the data is in millimetres
  const auto built = Wall::now();
  auto bone = sinew::LevelSet::from_mesh(*mesh, {.voxel_size = opt.voxel, .exterior_band = 3.0 * opt.voxel,
                                                 .interior_band = std::numeric_limits<double>::infinity()});
  if (!bone) return fail(bone.error().message());
  const double build_ms = ms_since(built);

  // Where to cut: the plateau (z is the bone's long axis), the highest
  // vertex moved 5 mm towards the bone's middle; the groove runs along y
  // from there, the path following the surface's height along it (the
  // STL's triangles, every 0.1 mm; scenes/generators/bone_burr.py does the
  // same arithmetic for the scene file).
  std::array<double, 3> top = mesh->vertices[mesh->triangles[0][0]];
  std::array<double, 3> lo = top, hi = top;
  for (const auto& t : mesh->triangles)
    for (std::uint32_t v : t) {
      const auto& p = mesh->vertices[v];
      if (p[2] > top[2]) top = p;
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
    }
  for (int k = 0; k < 2; ++k) top[k] += top[k] < 0.5 * (lo[k] + hi[k]) ? 5e-3 : -5e-3;
  const double y0 = top[1] - 0.5 * kGroove;
  std::vector<double> height;  // the surface's z at y0 + i * 0.1 mm
  for (int i = 0; i <= 100; ++i) height.push_back(plateau_height(*mesh, top, y0, y0 + i * kGroove / 100));
  const auto surface_z = [height, y0](double y) {
    const double u = std::clamp((y - y0) / kGroove * 100, 0.0, 100.0);
    const auto i = std::min<std::size_t>(static_cast<std::size_t>(u), 99);
    return height[i] + (u - double(i)) * (height[i + 1] - height[i]);
  };
  const std::array<double, 3> surface{top[0], top[1], surface_z(top[1])};
  // The hand: down into the plateau, along the groove, out; keys every 10
  // ms of that motion, straight lines between them.
  const auto hand_at = [x = top[0], y0, surface_z](double t) {
    const double y = y0 + kGroove * ramp(t, 0.3 + kDown, 0.3 + kDown + kAlong);
    const double depth = kAbove - (kAbove + kBelow) * ramp(t, 0.3, 0.3 + kDown) +
                         (kBelow + kLift) * ramp(t, 0.3 + kDown + kAlong, kDuration - 0.2);
    return std::array<double, 3>{x, y, surface_z(y) + depth};
  };
  const int ticks = static_cast<int>(std::lround(kDuration / kTick));
  std::vector<PathKey> keys;
  for (int tick = 0; tick <= ticks; tick += kKeyEvery) keys.push_back({.time = tick * kTick, .position = hand_at(tick * kTick)});
  auto path = KeyframePath::create(std::move(keys), PathInterpolation::linear);
  if (!path) return fail(path.error().message());
  const ScriptedPose start = path->at(0.0);

  // ------------------------------------------------------------ the scene
  sinew::SceneDesc scene;
  scene.gravity = {0.0, 0.0, -9.81};
  scene.solver = {.time_step = kTick, .substeps = 1, .iterations = 1, .measure_errors = false};
  sinew::ColliderDesc collider;
  collider.shape = sinew::ColliderShape::level_set;
  collider.level_set = *bone;  // shared: cut_collider cuts this grid
  scene.colliders.push_back(collider);
  auto ball = sinew::LevelSet::sphere({0, 0, 0}, kRadius, {.voxel_size = kRadius / 8, .exterior_band = kRadius / 2,
                                                          .interior_band = kRadius});
  if (!ball) return fail(ball.error().message());
  sinew::ToolDesc burr;
  burr.shape = sinew::ToolShape::level_set;
  burr.level_set = *ball;
  burr.penalty_stiffness = kStiffness;
  burr.penalty_damping = kDamping;
  burr.mass = kMass;
  burr.inertia = {2.5e-5, 2.5e-5, 2e-6};
  burr.position = start.position;
  burr.gravity = false;  // the hand carries the instrument
  // It removes the bone its motion sweeps deeper than cut_depth, after every frame.
  burr.cuts = sinew::ToolCutDesc{.collider = 0,
                                 .cutter = {.kind = sinew::CutterShape::Kind::sphere, .radius = kRadius - opt.cut_depth}};
  scene.tools.push_back(burr);
  auto sim = sinew::Simulation::create(scene, {.backend = opt.backend, .quiet = true});
  if (!sim) return fail(sim.error().message());
  sinew::Tools tools = sim->tools();
  const auto burr_id = tools.tool(0);
  const auto bone_id = tools.collider(0);
  if (!burr_id || !bone_id) return fail("the scene lacks its burr or bone");

  // ------------------------------------------------------------ the haptic side
  // Ticked here, in lockstep with the physics (a tick before each frame).
  ScriptedHandDesc hand;
  hand.path = *path;  // tool 0
  // Damps the burr's own motion (not felt; tool_bridge.h): 2 N s/m x 1 ms / 30 g = 0.07.
  hand.tool_damping = 2.0;
  hand.tool_angular_damping = 1e-4;
  auto hands = ScriptedHands::create({hand}, *sim, kTick);
  if (!hands) return fail(hands.error().message());
  const HapticLoop& loop = (*hands)->loop(0);
  std::printf("bone_burr on %s: the tibia at %.2f mm voxels (%.2f M voxels, built in %.0f ms); a %.0f mm burr, %zu "
              "ticks at 1 kHz\n",
              sim->device_name().c_str(), opt.voxel * 1e3, double(bone->voxels()) * 1e-6, build_ms, 2e3 * kRadius,
              static_cast<std::size_t>(ticks));
  auto output = sinew::SceneOutput::create(scene, opt.out);
  if (!output) return fail(output.error().message());
  if (auto s = output->write(*sim, 0); !s) return fail(s.error().message());

  // ------------------------------------------------------------ the run
  const std::string trace = opt.out + "/force_trace.csv";
  std::FILE* csv = std::fopen(trace.c_str(), "w");
  if (!csv) return fail("cannot write " + trace);
  std::fprintf(csv, "time,device_x,device_y,device_z,burr_x,burr_y,burr_z,force_x,force_y,force_z,force,"
                    "bone_push_x,bone_push_y,bone_push_z,points_in_bone,removed_mm3,step_ms,cut_ms,haptic_ms,surface_z\n");
  // The region the burr works in, for the surfaces written (the whole bone
  // would be about a million triangles): the groove and 8 mm around it.
  const std::array<double, 6> region{surface[0] - 8e-3, surface[1] - 0.5 * kGroove - 8e-3, surface[2] - 8e-3,
                                     surface[0] + 8e-3, surface[1] + 0.5 * kGroove + 8e-3, surface[2] + 4e-3};
  std::vector<std::filesystem::path> files, burr_files;
  std::vector<double> times, tick_ms, step_ms, cut_ms, cutting_force;
  double removed = 0.0, peak = 0.0, surface_ms = 0.0;
  std::uint64_t changed_bytes = 0;
  std::vector<TickRecord> record;
  for (int tick = 1; tick <= ticks; ++tick) {
    const auto t0 = Wall::now();
    if (auto s = (*hands)->before_step(*sim); !s) return fail(s.error().message());  // the tick, the coupling's force
    const double before = ms_since(t0);
    const auto t1 = Wall::now();
    if (auto s = sim->step(); !s) return fail(s.error().message());  // the burr moves, then cuts
    const double step = ms_since(t1);
    const auto t2 = Wall::now();
    if (auto s = (*hands)->after_step(*sim); !s) return fail(s.error().message());
    const double haptic = before + ms_since(t2);
    auto state = tools.state(*burr_id);
    if (!state) return fail(state.error().message());
    const double cutting = sim->last_frame().stage_ms("tool cuts");
    removed += state->cut_volume;
    changed_bytes += static_cast<std::uint64_t>(sim->last_frame().counter("tool cuts", "changed_bytes"));
    if (auto s = loop.copy_telemetry(record); !s) return fail(s.error().message());
    const TickRecord& r = record.back();
    tick_ms.push_back(step + haptic);
    step_ms.push_back(step - cutting);
    cut_ms.push_back(cutting);
    const double force = std::sqrt(r.force[0] * r.force[0] + r.force[1] * r.force[1] + r.force[2] * r.force[2]);
    peak = std::max(peak, force);
    if (state->cut_volume > 0.0) cutting_force.push_back(force);
    std::fprintf(csv, "%.3f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%u,%.5f,%.4f,%.4f,%.4f,%.6f\n",
                 tick * kTick, r.device_position[0], r.device_position[1], r.device_position[2], state->position[0],
                 state->position[1], state->position[2], r.force[0], r.force[1], r.force[2], force,
                 state->penalty_force[0], state->penalty_force[1], state->penalty_force[2], state->penalty_points,
                 removed * 1e9, step - cutting, cutting, haptic, surface_z(r.device_position[1]));
    const sinew::Pose to{.position = state->position, .rotation = state->rotation};
    if (tick % opt.surface_every == 0 || tick == ticks) {  // the display's rate, not the haptic one
      const auto t3 = Wall::now();
      auto part = bone->surface_in(region);
      if (!part) return fail(part.error().message());
      std::vector<float> xyz;
      for (const auto& v : part->vertices) xyz.insert(xyz.end(), {float(v[0]), float(v[1]), float(v[2])});
      files.push_back(opt.out + "/bone_" + std::to_string(files.size()) + ".vtu");
      if (auto s = sinew::write_vtu_triangles(files.back(), xyz, 3, part->triangles); !s) return fail(s.error().message());
      burr_files.push_back(opt.out + "/burr_" + std::to_string(burr_files.size()) + ".vtu");
      if (auto s = sinew::examples::write_capsule_vtu(burr_files.back(), kRadius, 0.0, to); !s)
        return fail(s.error().message());
      times.push_back(tick * kTick);
      surface_ms = std::max(surface_ms, ms_since(t3));
    }
  }
  std::fclose(csv);
  if (auto s = output->write(*sim, ticks); !s) return fail(s.error().message());
  if (auto s = sinew::write_pvd(opt.out + "/bone_burr.pvd", files, times); !s) return fail(s.error().message());
  if (auto s = sinew::write_pvd(opt.out + "/burr.pvd", burr_files, times); !s) return fail(s.error().message());

  // ------------------------------------------------------------ the plot
  const std::string plot = opt.out + "/force_trace.png";
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    const std::string gp = opt.out + "/force_trace.gp";
    if (std::FILE* g = std::fopen(gp.c_str(), "w")) {
      std::fprintf(g,
                   "set terminal pngcairo size 1000,900 font 'sans,10'\n"
                   "set output '%s'\n"
                   "set datafile separator ','\n"
                   "set multiplot layout 3,1\n"
                   "set grid; set key top left\n"
                   "set title 'bone_burr: force rendered to the device (1 kHz)' noenhanced\n"
                   "set ylabel 'force [N]'\n"
                   "plot '%s' using 1:11 with lines lw 1.5 title '|F| device', '' using 1:10 with lines title "
                   "'F_z device', '' using 1:14 with lines dt 2 title 'bone push on the burr, z'\n"
                   "set title 'bone removed'\n"
                   "set ylabel 'volume [mm^3]'\n"
                   "plot '%s' using 1:16 with lines lw 1.5 title 'removed'\n"
                   "set title 'device and burr: along the groove, and height over the plateau (the burr''s centre)'\n"
                   "set xlabel 'time [s]'; set ylabel 'position [mm]'\n"
                   "plot '%s' using 1:(($3-%.9f)*1e3) with lines title 'device, along', '' using 1:(($6-%.9f)*1e3) "
                   "with lines dt 2 title 'burr, along', '' using 1:(($4-$20)*1e3) with lines title 'device, height', "
                   "'' using 1:(($7-$20)*1e3) with lines dt 2 title 'burr, height'\n"
                   "unset multiplot\n",
                   plot.c_str(), trace.c_str(), trace.c_str(), trace.c_str(), y0, y0);
      std::fclose(g);
      const std::string cmd = "gnuplot '" + gp + "'";
      if (std::system(cmd.c_str()) != 0) std::printf("gnuplot failed: no plot\n");
      else std::printf("wrote %s\n", plot.c_str());
    }
  } else {
    std::printf("gnuplot not found (apt-get install gnuplot-nox): no plot, CSV only\n");
  }

  const HapticCounters c = loop.counters();
  std::printf("removed %.2f mm^3 of bone (%llu bytes re-uploaded in all); force while cutting %.3f N median over %zu "
              "ticks, peak %.3f N; %llu clamped, %llu slew-limited ticks\n",
              removed * 1e9, static_cast<unsigned long long>(changed_bytes), median(cutting_force),
              cutting_force.size(), peak, static_cast<unsigned long long>(c.clamped),
              static_cast<unsigned long long>(c.slew_limited));
  std::printf("per tick: %.3f ms median, %.3f ms p99 (step %.3f, cut %.3f ms median) of the 1 ms a tick has; "
              "surface of the region %.0f ms at most\n",
              median(tick_ms), quantile(tick_ms, 0.99), median(step_ms), median(cut_ms), surface_ms);
  std::printf("wrote %s and %zu surfaces; open %s/bone_burr.pvd and burr.pvd (or scene.pvd: the whole bone at the "
              "start and the end) in ParaView\n",
              trace.c_str(), files.size(), opt.out.c_str());
  return 0;
}
