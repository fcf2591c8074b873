// frame_profile.h — what the reference scenes' benchmarks (bench_retraction,
// bench_suture_scene) measure per frame: its wall and process CPU time and
// each stage's time (FrameStats::stages), reported as nearest-rank
// percentiles.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <string>
#include <vector>

#include "bench_support.h"  // percentile
#include "sinew/simulation.h"

namespace sinew::bench {

/// The 1-minute load average (-1 when unknown).
inline double load_average() {
  double load[1] = {0.0};
  return getloadavg(load, 1) == 1 ? load[0] : -1.0;
}

/// Frame times [ms]: call start() before a frame and stop() after it.
/// Wall time, and the process's CPU time (every thread's): on a shared
/// machine the latter is the frame's work without the time other jobs took.
class FrameProfile {
 public:
  void start() {
    cpu0_ = cpu_now_ms();
    wall0_ = std::chrono::steady_clock::now();
  }
  /// [in] stats: the frame's (Simulation::last_frame()), for its stages.
  void stop(const FrameStats& stats) {
    wall_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0_).count());
    cpu_.push_back(cpu_now_ms() - cpu0_);
    for (const auto& p : stats.stages) {
      if (!stages_.count(p.name)) order_.push_back(p.name);
      stages_[p.name].push_back(p.ms);
    }
  }
  [[nodiscard]] double wall(double q) const { return percentile(wall_, q); }  ///< [ms]
  [[nodiscard]] double cpu(double q) const { return percentile(cpu_, q); }    ///< [ms]
  /// Prints CSV: a header, then per stage its median, p95 and worst [ms].
  void print_stages() const {
    std::printf("stage,median_ms,p95_ms,worst_ms\n");
    for (const auto& name : order_) {
      const auto& v = stages_.at(name);
      std::printf("%s,%.3f,%.3f,%.3f\n", name.c_str(), percentile(v, 0.5), percentile(v, 0.95), percentile(v, 1.0));
    }
  }

 private:
  static double cpu_now_ms() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
  }
  std::vector<double> wall_, cpu_;
  std::map<std::string, std::vector<double>> stages_;
  std::vector<std::string> order_;
  double cpu0_ = 0.0;
  std::chrono::steady_clock::time_point wall0_;
};

}  // namespace sinew::bench
