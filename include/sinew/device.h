// sinew/device.h — choosing where a scene runs, and what its device time was.
//
// Backends: "cpu" (the reference; every dispatch runs in parallel with TBB),
// "opencl" and "vulkan" (GPU backends, when built), and "auto" (the best one
// available: a GPU backend with a device, else "cpu"). The backend interface
// itself (devices, buffers, frame programs) is internal to the library:
// users describe scenes (sinew/scene.h) and run them (sinew/simulation.h).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sinew/result.h"

namespace sinew {

/// Device time of one run of a frame program, from timestamps the device
/// writes around each dispatch. The Vulkan backend records them where its
/// queue has timestamps (on by default on GPUs; SINEW_VULKAN_TIMESTAMPS);
/// the CPU and OpenCL backends record none (timed stays false).
struct DeviceTimes {
  static constexpr std::size_t max_kernels = 128;  ///< kernels timed at most (the arrays' size)
  bool timed = false;  ///< whether the backend recorded timestamps for this run
  double span_ms = 0.0;  ///< first timestamp to last [ms]: the program's time on the device
  /// Per kernel (indexed like kernel_names()), summed over its dispatches [ms].
  /// Dispatches between two barriers may overlap, so the sum may exceed span_ms.
  std::array<double, max_kernels> kernel_ms{};
  std::array<std::uint32_t, max_kernels> dispatches{};  ///< timed dispatches per kernel
};

/// The names of the kernels sinew runs, in the order DeviceTimes indexes
/// them ("xpbd_predict", "xpbd_solve_distance", ...).
std::span<const std::string_view> kernel_names();

/// How to pick a backend and device.
struct DeviceOptions {
  std::string backend = "auto";  ///< "cpu", "opencl", "vulkan" or "auto"
  /// opencl/vulkan: a device index or a substring of its name; empty: the
  /// environment variable SINEW_OPENCL_DEVICE / SINEW_VULKAN_DEVICE, else the
  /// first GPU, else the first device.
  std::string device = "";
  int threads = 0;               ///< cpu: worker threads; 0 = all hardware threads
  /// cpu: true (default) times each program on all threads and on one, and
  /// runs it on one where the team is no faster (too little work, or the
  /// other cores busy with other processes), trying the team again now and
  /// then; false: every program worth sharing runs on all threads. Results
  /// are bitwise the same either way.
  bool cpu_adaptive_team = true;
  bool cpu_simd = true;          ///< cpu: use the AVX2 solves where the CPU has AVX2 (bitwise
                                 ///< equal to the scalar reference kernels, only faster)
  bool quiet = false;            ///< true: do not print the one-line fallback notice of "auto"
};

/// The backends built into this library ("cpu" always).
std::vector<std::string> built_backends();

}  // namespace sinew
