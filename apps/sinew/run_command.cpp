// run_command.cpp — `sinew run`: a scene file run frame by frame with its
// script, a progress bar on a terminal or one flushed line per output
// frame when piped, the scene's binary VTK output (every body, tool and
// the fluid: sinew/vtk_output.h), and the per-stage profile at the end.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "sinew/mesh.h"
#include "sinew/scene_file.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"

namespace sinew::cli {
namespace {

int fail(const std::string& what) {
  std::fprintf(stderr, "sinew run: %s\n", what.c_str());
  return 1;
}

// Progress: a bar redrawn in place on a terminal; nothing when piped
// (the output lines say how far it is).
class Progress {
 public:
  Progress(int frames, bool terminal) : frames_(frames), terminal_(terminal) {}
  void update(int frame, double mean_ms) {
    if (!terminal_) return;
    // Redrawn at most ten times a second (a fast scene makes thousands of frames a second).
    const auto now = std::chrono::steady_clock::now();
    if (drawn_ && frame < frames_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(double(kWidth) * frame / frames_);
    std::fprintf(stdout, "\r[%s%s] %d/%d frames, %.2f ms/frame", std::string(filled, '#').c_str(),
                 std::string(kWidth - filled, ' ').c_str(), frame, frames_, mean_ms);
    std::fflush(stdout);
    drawn_ = true;
  }
  /// Clears the bar so a line can be printed in its place.
  void clear() {
    if (drawn_) std::fprintf(stdout, "\r%*s\r", 80, "");
    drawn_ = false;
  }

 private:
  int frames_;
  bool terminal_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point last_draw_{};
};

// The mean wall time per stage over the run, and each stage's counters
// in the last frame; what the host read and waited for per frame; and,
// where the backend records timestamps (Vulkan on a GPU, DeviceTimes), the
// program's device time and its costliest kernels.
struct Profile {
  std::vector<std::string> order;
  std::map<std::string, double> total_ms;
  std::map<std::string, std::vector<StageProfile::Counter>> last_counters;
  std::uint64_t read_bytes = 0, host_waits = 0, max_read_bytes = 0, max_host_waits = 0;
  int timed_frames = 0;
  double device_ms = 0.0;
  std::array<double, DeviceTimes::max_kernels> kernel_ms{};
  void add(const FrameStats& st) {
    for (const StageProfile& s : st.stages) {
      if (!total_ms.count(s.name)) order.push_back(s.name);
      total_ms[s.name] += s.ms;
      last_counters[s.name] = s.counters;
    }
    read_bytes += st.read_back_bytes;
    host_waits += st.host_waits;
    max_read_bytes = std::max<std::uint64_t>(max_read_bytes, st.read_back_bytes);
    max_host_waits = std::max<std::uint64_t>(max_host_waits, st.host_waits);
    if (st.device.timed) {
      ++timed_frames;
      device_ms += st.device.span_ms;
      for (std::size_t k = 0; k < kernel_ms.size(); ++k) kernel_ms[k] += st.device.kernel_ms[k];
    }
  }
  void print(int frames, double total_wall_ms) const {
    std::printf("profile: %.3f ms per frame on average over %d frames (%.1f ms in all); per stage, and its counters in the last frame:\n",
                total_wall_ms / frames, frames, total_wall_ms);
    for (const std::string& name : order) {
      std::printf("  %-16s %9.3f ms", name.c_str(), total_ms.at(name) / frames);
      for (const auto& c : last_counters.at(name)) std::printf("  %s %g", c.name.c_str(), c.value);
      std::printf("\n");
    }
    std::printf("host transfers per frame: %.0f bytes read back (most %llu), %.2f waits (most %llu)\n",
                double(read_bytes) / frames, static_cast<unsigned long long>(max_read_bytes),
                double(host_waits) / frames, static_cast<unsigned long long>(max_host_waits));
    if (timed_frames == 0) return;
    std::printf("device time: %.3f ms per frame (timestamps, %d frames); costliest kernels per frame:\n",
                device_ms / timed_frames, timed_frames);
    const auto names = kernel_names();
    std::vector<std::size_t> by_time;
    for (std::size_t k = 0; k < std::min(names.size(), kernel_ms.size()); ++k)
      if (kernel_ms[k] > 0.0) by_time.push_back(k);
    std::sort(by_time.begin(), by_time.end(), [&](std::size_t a, std::size_t b) { return kernel_ms[a] > kernel_ms[b]; });
    for (std::size_t i = 0; i < std::min<std::size_t>(by_time.size(), 10); ++i)
      std::printf("  %-32.*s %9.3f ms\n", static_cast<int>(names[by_time[i]].size()), names[by_time[i]].data(),
                  kernel_ms[by_time[i]] / timed_frames);
  }
};

void print_frame(int frame, const FrameStats& st) {
  std::printf("frame %d  t = %.4f s  %.3f ms  residual rms %.6e  volume change %+.6e  kinetic energy %.6e J  sweeps %llu\n",
              frame, st.time, st.wall_ms, st.residual_rms, st.volume_change, st.kinetic_energy,
              static_cast<unsigned long long>(st.sweeps));
  std::fflush(stdout);
}

// The particles' positions as raw float32 xyzw, for bitwise comparisons.
Status write_positions(const Simulation& sim, const std::string& path) {
  std::vector<float> xyzw;
  if (Status s = sim.read_positions(xyzw); !s) return s;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return Error{ErrorCode::bad_input_file, path + ": cannot be written"};
  const std::size_t written = std::fwrite(xyzw.data(), sizeof(float), xyzw.size(), f);
  const bool closed = std::fclose(f) == 0;
  if (written != xyzw.size() || !closed) return Error{ErrorCode::bad_input_file, path + ": write failed"};
  return {};
}

}  // namespace

int run_scene(const RunOptions& o) {
  auto file = load_scene_file(o.scene);
  if (!file) return fail(file.error().message());
  const int frames = o.frames > 0 ? o.frames : file->run.frames;
  const int every = o.every > 0 ? o.every : file->run.every;
  DeviceOptions device{.backend = o.backend.empty() ? file->run.backend : o.backend, .device = o.device,
                       .threads = o.threads};
  auto sim = Simulation::create(file->scene, device);
  if (!sim) return fail(sim.error().message());
  const SceneInfo& info = sim->info();
  std::printf("sinew run %s on %s (%s): %u particles, %u constraints, %u colours; %d frames of %g s, %d substeps x %d iterations\n",
              o.scene.c_str(), sim->device_name().c_str(), sim->backend_name().c_str(), info.particles,
              info.constraints(), info.colors, frames, file->scene.solver.time_step, file->scene.solver.substeps,
              file->scene.solver.iterations);
  std::fflush(stdout);

  std::optional<SceneOutput> vtk;
  if (!o.out.empty()) {
    auto made = SceneOutput::create(file->scene, o.out, {.bodies = file->bodies});
    if (!made) return fail(made.error().message());
    vtk.emplace(std::move(*made));
    // Frame 0: the scene as it starts.
    if (Status s = vtk->write(*sim, 0); !s) return fail(s.error().message());
  }
  ScriptPlayer player(file->script);
  // The file's scripted hands: their loops tick on a virtual clock between frames.
  std::unique_ptr<haptics::ScriptedHands> hands;
  if (!file->hands.empty()) {
    auto made = haptics::ScriptedHands::create(file->hands, *sim, file->scene.solver.time_step);
    if (!made) return fail(made.error().message());
    hands = std::move(*made);
    for (std::size_t i = 0; i < file->hands.size(); ++i)
      std::printf("hand %zu drives tool %u: a scripted device over %g s, its haptic loop at %g Hz on the frames' clock\n", i,
                  file->hands[i].tool, file->hands[i].path.duration(), file->hands[i].loop.rate_hz);
  }
  Progress progress(frames, isatty(fileno(stdout)) != 0);
  Profile profile;
  std::vector<std::string> events;
  double total_ms = 0.0;
  for (int f = 1; f <= frames; ++f) {
    events.clear();
    if (Status s = player.before_frame(*sim, f, &events); !s) return fail("frame " + std::to_string(f) + ": " + s.error().message());
    if (hands)
      if (Status s = hands->before_step(*sim); !s) return fail("frame " + std::to_string(f) + ": " + s.error().message());
    if (Status s = sim->step(); !s) return fail("frame " + std::to_string(f) + ": " + s.error().message());
    if (hands)
      if (Status s = hands->after_step(*sim); !s) return fail("frame " + std::to_string(f) + ": " + s.error().message());
    const FrameStats& st = sim->last_frame();
    total_ms += st.wall_ms;
    profile.add(st);
    const bool output = f % every == 0 || f == frames;
    if ((!events.empty() || output) && !o.quiet) {
      progress.clear();
      for (const std::string& e : events) std::printf("%s\n", e.c_str());
      if (output) print_frame(f, st);
      std::fflush(stdout);
    }
    if (output && vtk)
      if (Status s = vtk->write(*sim, f); !s) return fail(s.error().message());
    progress.update(f, total_ms / f);
  }
  progress.clear();
  if (vtk) std::printf("wrote %s/scene.pvd (every body, collider, tool and needle, one .vtm per frame)\n", o.out.c_str());
  if (!o.positions.empty()) {
    if (Status s = write_positions(*sim, o.positions); !s) return fail(s.error().message());
    std::printf("wrote %u particles' final positions to %s\n", info.particles, o.positions.c_str());
  }
  for (std::size_t i = 0; hands && i < hands->count(); ++i) {
    const haptics::HapticCounters c = hands->loop(i).counters();
    const haptics::Vec3& f = hands->device(i).last_force();
    std::printf("hand %zu: %llu ticks, %llu clamped, %llu slew-limited; last force on the device (%.4f, %.4f, %.4f) N\n", i,
                static_cast<unsigned long long>(c.ticks), static_cast<unsigned long long>(c.clamped),
                static_cast<unsigned long long>(c.slew_limited), f[0], f[1], f[2]);
  }
  profile.print(frames, total_ms);
  std::fflush(stdout);
  return 0;
}

}  // namespace sinew::cli
