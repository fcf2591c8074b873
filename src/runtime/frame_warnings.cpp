// frame_warnings.cpp — sinew/warnings.h. The Courant number follows the
// analysis in kernels/cpu/fem_kernels.cpp: xPBD's linearisation drops the
// curvature term that is a prestressed Neo-Hookean pair's whole shear
// stiffness at rest, so its shear is integrated explicitly and, like an
// explicit elastic step (Courant, Friedrichs and Lewy 1928), grows without
// bound once a shear wave crosses more than ~0.75 of an element per substep.
#include "runtime/frame_warnings.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sinew/log.h"
#include "runtime/simulation_impl.h"
#include "sinew/simulation.h"

namespace sinew {
namespace {

constexpr double kStableCourant = 0.75;    // a body at rest blows up above it
constexpr double kAccurateCourant = 0.2;   // docs/tissue.md: statics within ~1% below it
constexpr double kEdgePercentile = 0.1;    // the "cell": short edges without a sliver's extremes

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char text[512];
  std::snprintf(text, sizeof text, pattern, a, b, c, d);
  return text;
}

// The body's 10th-percentile edge length [m] (each tet's six edges; shared ones counted per tet).
double short_edge(const TetMesh& mesh) {
  std::vector<double> lengths;
  lengths.reserve(mesh.tets.size() * 6);
  for (const auto& t : mesh.tets)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        const Vec3d& p = mesh.vertices[t[a]];
        const Vec3d& q = mesh.vertices[t[b]];
        lengths.push_back(std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                    (p[2] - q[2]) * (p[2] - q[2])));
      }
  if (lengths.empty()) return 0.0;
  const auto nth = lengths.begin() + static_cast<std::ptrdiff_t>(kEdgePercentile * double(lengths.size() - 1));
  std::nth_element(lengths.begin(), nth, lengths.end());
  return *nth;
}

}  // namespace

double shear_courant_number(const SceneDesc& scene, std::size_t body) {
  const TetBodyDesc& b = scene.tet_bodies.at(body);
  if (b.material == TetMaterial::none || b.youngs_modulus <= 0.0 || b.density <= 0.0) return 0.0;
  const double edge = short_edge(b.mesh);
  if (edge <= 0.0) return 0.0;
  const double mu = b.youngs_modulus / (2.0 * (1.0 + b.poisson_ratio));
  const double substep = scene.solver.time_step / std::max(1, scene.solver.substeps);
  return substep * std::sqrt(mu / b.density) / edge;
}

void warn_about_scene(const SceneDesc& scene) {
  // The bound is xPBD's (its Gauss-Newton step drops the curvature term);
  // Vertex Block Descent's vertex steps keep it (kernels/math/vbd_math.h):
  // measured, a neo_hookean block at a Courant number of 1e4 released from
  // a stretch settles without gaining energy (tests/vbd_test.cpp).
  if (scene.solver.method == SolverMethod::vbd) return;
  for (std::size_t i = 0; i < scene.tet_bodies.size(); ++i) {
    if (scene.tet_bodies[i].material != TetMaterial::neo_hookean) continue;
    const double k = shear_courant_number(scene, i);
    if (!(k > kStableCourant)) continue;
    const double needed = std::ceil(double(std::max(1, scene.solver.substeps)) * k / kAccurateCourant);
    log_message(LogLevel::warning,
                "tet body " + std::to_string(i) +
                    format(" (stable Neo-Hookean): its shear-wave Courant number per substep is %.3g, above the "
                           "%.2g where a body at rest blows up (h sqrt(mu / rho) / L with L its 10th-percentile "
                           "edge, %.3g mm); %.0f substeps per frame bring it to 0.2, or use the corotational model",
                           k, kStableCourant, 1e3 * short_edge(scene.tet_bodies[i].mesh), needed));
  }
}

Status FrameWarnings::set(const WarningSettings& s) {
  const auto bad = [](const std::string& what) { return Error(ErrorCode::bad_parameter, "WarningSettings." + what); };
  if (!std::isfinite(s.frame_budget_ms) || s.frame_budget_ms < 0.0)
    return bad("frame_budget_ms must be finite and >= 0 (0: no budget)");
  if (!std::isfinite(s.repeat_seconds) || !(s.repeat_seconds > 0.0))
    return bad("repeat_seconds must be finite and > 0");
  if (!std::isfinite(s.capacity_fraction) || !(s.capacity_fraction > 0.0) || s.capacity_fraction > 1.0)
    return bad("capacity_fraction must be in (0, 1]");
  settings_ = s;
  return {};
}

void FrameWarnings::after_frame(const FrameStats& stats) {
  if (settings_.frame_budget_ms > 0.0) {
    ++frames_since_warning_;
    if (stats.wall_ms > settings_.frame_budget_ms) {
      ++overruns_;
      if (stats.wall_ms > worst_ms_) worst_ms_ = stats.wall_ms, worst_frame_ = stats.frame;
    }
    const auto now = Clock::now();
    const bool due = !warned_overrun_ ||
                     std::chrono::duration<double>(now - last_warning_).count() >= settings_.repeat_seconds;
    if (overruns_ > 0 && due) {
      log_message(LogLevel::warning,
                  std::to_string(overruns_) + " of the last " + std::to_string(frames_since_warning_) +
                      format(" frames overran their budget of %.3g ms (the worst: %.3g ms, ", settings_.frame_budget_ms,
                             worst_ms_) +
                      "frame " + std::to_string(worst_frame_) + ")");
      warned_overrun_ = true;
      last_warning_ = now;
      overruns_ = frames_since_warning_ = 0;
      worst_ms_ = 0.0;
    }
  }
  // Counts near their capacity: a counter "X" beside "X_capacity".
  constexpr std::string_view kSuffix = "_capacity";
  for (const StageProfile& stage : stats.stages)
    for (const StageProfile::Counter& cap : stage.counters) {
      if (cap.name.size() <= kSuffix.size() || !cap.name.ends_with(kSuffix) || !(cap.value > 0.0)) continue;
      const std::string name = cap.name.substr(0, cap.name.size() - kSuffix.size());
      const double value = stats.counter(stage.name, name);
      const std::string key = stage.name + "/" + name;
      const auto it = std::find(full_.begin(), full_.end(), key);
      if (value >= settings_.capacity_fraction * cap.value) {
        if (it != full_.end()) continue;
        full_.push_back(key);
        log_message(LogLevel::warning, stage.name + ": " + name + format(" reached %.0f of its capacity %.0f (%.0f%%)",
                                                                         value, cap.value, 100.0 * value / cap.value) +
                                           " at frame " + std::to_string(stats.frame) +
                                           "; past the capacity step() returns capacity_exceeded");
      } else if (it != full_.end() && value < 0.9 * settings_.capacity_fraction * cap.value) {
        full_.erase(it);
      }
    }
}

Status Simulation::set_warning_settings(const WarningSettings& settings) { return impl_->warnings.set(settings); }

const WarningSettings& Simulation::warning_settings() const { return impl_->warnings.settings(); }

}  // namespace sinew
