// commands.h — the sinew command-line program's commands (apps/sinew;
// docs/runner.md): run a scene file, check one, list backends and devices.
#pragma once

#include <string>

namespace sinew::cli {

/// `sinew run` options; zero or empty: the scene file's "run" section.
struct RunOptions {
  std::string scene;     ///< the scene file
  std::string backend;   ///< "auto", "cpu", "opencl", "vulkan"; empty: the file's
  std::string device;    ///< a device index or name substring (DeviceOptions::device)
  int frames = 0;        ///< frames to run; 0: the file's
  int every = 0;         ///< output every N frames; 0: the file's
  std::string out;       ///< VTU folder; empty: no VTU output
  int threads = 0;       ///< cpu backend's worker threads; 0: all
  bool quiet = false;    ///< no per-output lines (the summary and profile only)
  /// After the last frame, every particle's position and inverse mass as
  /// raw float32 x, y, z, w (little-endian, in read_positions' order) to
  /// this file; empty: none. For bitwise comparisons with other front ends
  /// (the C API, Python).
  std::string positions;
};

/// Runs the scene; returns the process's exit status (0, or 1 on an error).
int run_scene(const RunOptions& options);
/// Reads and checks the scene file without running it; prints what it holds.
int check_scene_file(const std::string& scene);
/// Prints the version, the backends built in and the devices each finds.
int print_info();

}  // namespace sinew::cli
