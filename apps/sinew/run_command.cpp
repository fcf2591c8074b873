// run_command.cpp — `sinew run`: a scene file run frame by frame with its
// script, a progress bar on a terminal or one flushed line per output
// frame when piped, VTU series per body, and the per-stage profile at the end.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "commands.h"
#include "sinew/mesh.h"
#include "sinew/scene_file.h"
#include "sinew/simulation.h"

namespace sinew::cli {
namespace {

int fail(const std::string& what) {
  std::fprintf(stderr, "sinew run: %s\n", what.c_str());
  return 1;
}

// The VTU series of one body or of the fluid: its files and their times.
struct Series {
  std::vector<std::filesystem::path> files;
  std::vector<double> times;
};

// Writes every body (and the fluid) of the frame: <out>/<name>_<frame>.vtu.
class VtuOutput {
 public:
  VtuOutput(const SceneFile& file, std::filesystem::path out) : file_(file), out_(std::move(out)) {}

  Status write(Simulation& sim, int frame) {
    const double t = sim.last_frame().time;
    if (Status s = sim.read_positions(x_); !s) return s;
    if (Status s = sim.read_velocities(v_); !s) return s;
    const SceneInfo& info = sim.info();
    for (const SceneBodyName& b : file_.bodies) {
      const std::filesystem::path path = out_ / (b.name + "_" + std::to_string(frame) + ".vtu");
      if (Status s = write_body(sim, info, b, path); !s) return s;
      series_[b.name].files.push_back(path);
      series_[b.name].times.push_back(t);
    }
    if (file_.scene.fluid) {
      const std::filesystem::path path = out_ / ("fluid_" + std::to_string(frame) + ".vtu");
      if (Status s = write_fluid(sim, path); !s) return s;
      series_["fluid"].files.push_back(path);
      series_["fluid"].times.push_back(t);
    }
    return {};
  }

  Status finish() {
    for (const auto& [name, s] : series_)
      if (Status st = write_pvd(out_ / (name + ".pvd"), s.files, s.times); !st) return st;
    return {};
  }

 private:
  Status write_body(Simulation& sim, const SceneInfo& info, const SceneBodyName& b, const std::filesystem::path& path) {
    const SceneDesc& scene = file_.scene;
    std::size_t first = 0, count = 0;
    if (b.kind == BodyKind::tet) first = info.tet_body_first_particle[b.index], count = scene.tet_bodies[b.index].mesh.vertices.size();
    if (b.kind == BodyKind::tri) first = info.tri_body_first_particle[b.index], count = scene.tri_bodies[b.index].mesh.vertices.size();
    if (b.kind == BodyKind::line) first = info.line_body_first_particle[b.index], count = scene.line_bodies[b.index].vertices.size();
    const std::span<const float> x = std::span<const float>(x_).subspan(4 * first, 4 * count);
    if (b.kind == BodyKind::tet) {
      // Each vertex's speed [m/s], as a point field.
      speed_.resize(count);
      for (std::size_t p = 0; p < count; ++p) {
        const float* v = &v_[4 * (first + p)];
        speed_[p] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      }
      const VertexField fields[] = {{"speed", 1, speed_}};
      if (!scene.topology_changes) return write_vtu(path, x, 4, scene.tet_bodies[b.index].mesh.tets, fields);
      auto id = sim.topology().tet_body(b.index);
      if (!id) return id.error();
      auto tets = sim.topology().current_tets(*id);
      if (!tets) return tets.error();
      return write_vtu(path, x, 4, *tets, fields);
    }
    if (b.kind == BodyKind::tri) {
      if (!scene.topology_changes) return write_vtu_triangles(path, x, 4, scene.tri_bodies[b.index].mesh.triangles);
      auto id = sim.topology().tri_body(b.index);
      if (!id) return id.error();
      auto triangles = sim.topology().current_triangles(*id);
      if (!triangles) return triangles.error();
      return write_vtu_triangles(path, x, 4, *triangles);
    }
    return write_vtu_lines(path, x, 4, scene.line_bodies[b.index].segments);
  }

  Status write_fluid(Simulation& sim, const std::filesystem::path& path) {
    if (Status s = sim.fluid().read(particles_); !s) return s;
    xyz_.clear(), rho_.clear(), pressure_.clear(), velocity_.clear();
    for (const FluidParticle& p : particles_) {
      xyz_.insert(xyz_.end(), p.position.begin(), p.position.end());
      velocity_.insert(velocity_.end(), p.velocity.begin(), p.velocity.end());
      rho_.push_back(p.density);
      pressure_.push_back(p.pressure);
    }
    const VertexField fields[] = {{"density", 1, rho_}, {"pressure", 1, pressure_}, {"velocity", 3, velocity_}};
    return write_vtu_points(path, xyz_, 3, fields);
  }

  const SceneFile& file_;
  std::filesystem::path out_;
  std::map<std::string, Series> series_;
  std::vector<float> x_, v_, speed_, xyz_, rho_, pressure_, velocity_;
  std::vector<FluidParticle> particles_;
};

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
// in the last frame.
struct Profile {
  std::vector<std::string> order;
  std::map<std::string, double> total_ms;
  std::map<std::string, std::vector<StageProfile::Counter>> last_counters;
  void add(const FrameStats& st) {
    for (const StageProfile& s : st.stages) {
      if (!total_ms.count(s.name)) order.push_back(s.name);
      total_ms[s.name] += s.ms;
      last_counters[s.name] = s.counters;
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

  std::optional<VtuOutput> vtu;
  if (!o.out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.out, ec);
    if (ec) return fail(o.out + ": cannot be made (" + ec.message() + ")");
    vtu.emplace(*file, o.out);
  }
  ScriptPlayer player(file->script);
  Progress progress(frames, isatty(fileno(stdout)) != 0);
  Profile profile;
  std::vector<std::string> events;
  double total_ms = 0.0;
  for (int f = 1; f <= frames; ++f) {
    events.clear();
    if (Status s = player.before_frame(*sim, f, &events); !s) return fail("frame " + std::to_string(f) + ": " + s.error().message());
    if (Status s = sim->step(); !s) return fail("frame " + std::to_string(f) + ": " + s.error().message());
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
    if (output && vtu)
      if (Status s = vtu->write(*sim, f); !s) return fail(s.error().message());
    progress.update(f, total_ms / f);
  }
  progress.clear();
  if (vtu) {
    if (Status s = vtu->finish(); !s) return fail(s.error().message());
    std::printf("wrote VTU series (one .pvd per body) to %s\n", o.out.c_str());
  }
  if (!o.positions.empty()) {
    if (Status s = write_positions(*sim, o.positions); !s) return fail(s.error().message());
    std::printf("wrote %u particles' final positions to %s\n", info.particles, o.positions.c_str());
  }
  profile.print(frames, total_ms);
  std::fflush(stdout);
  return 0;
}

}  // namespace sinew::cli
