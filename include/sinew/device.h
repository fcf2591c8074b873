// sinew/device.h — the backend interface.
//
// A Device owns buffers and runs *frame programs*: the ordered kernel
// dispatches of one frame, with barriers between dependent dispatches. A
// program is built once per scene and run every frame, so a backend can
// prepare it (the Vulkan backend records it into a command buffer once).
// Virtual calls happen per dispatch, never per particle or constraint.
//
// Backends: "cpu" (the reference; every dispatch runs in parallel with TBB),
// "opencl" and "vulkan" (GPU backends, when built), and "auto" (the best one
// available: a GPU backend with a device, else "cpu").
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "sinew/result.h"

namespace sinew {

/// The kernels every backend implements, by name (kernel_name). Their
/// parameters and buffer bindings are declared once in kernels/shared. The
/// solve kernels run in this order within an iteration (contacts last).
enum class Kernel : std::uint32_t {
  xpbd_predict,
  xpbd_update_velocity,
  xpbd_solve_distance,
  xpbd_solve_volume,
  xpbd_solve_neo_hookean,
  xpbd_solve_stvk,
  xpbd_solve_corotational,
  xpbd_solve_area,
  xpbd_solve_dihedral,
  xpbd_solve_line_bending,
  xpbd_solve_attachment,
  xpbd_solve_contacts,
  count_  ///< number of kernels, not a kernel
};

inline constexpr std::size_t kernel_count = static_cast<std::size_t>(Kernel::count_);

/// Device time of one run of a frame program, from timestamps the device
/// writes around each dispatch. The Vulkan backend records them where its
/// queue has timestamps (on by default on GPUs; SINEW_VULKAN_TIMESTAMPS);
/// the CPU and OpenCL backends record none (timed stays false).
struct DeviceTimes {
  bool timed = false;
  double span_ms = 0.0;  ///< first timestamp to last [ms]: the program's time on the device
  /// Per kernel (indexed by Kernel), summed over its dispatches [ms].
  /// Dispatches between two barriers may overlap, so the sum may exceed span_ms.
  std::array<double, kernel_count> kernel_ms{};
  std::array<std::uint32_t, kernel_count> dispatches{};  ///< timed dispatches per kernel
};

/// The kernel's name, the same in every kernel language ("xpbd_predict").
std::string_view kernel_name(Kernel kernel);

/// A device buffer; valid only with the device that made it.
struct BufferHandle {
  std::uint32_t id = UINT32_MAX;
  friend bool operator==(BufferHandle, BufferHandle) = default;
};

/// One kernel launch over work items [0, count).
struct Dispatch {
  static constexpr std::size_t max_bindings = 8;
  static constexpr std::size_t max_params_bytes = 64;
  Kernel kernel = Kernel::count_;
  std::uint32_t count = 0;                            ///< work items
  std::uint32_t binding_count = 0;
  BufferHandle bindings[max_bindings] = {};           ///< in the kernel's binding order
  std::uint32_t params_bytes = 0;
  alignas(16) std::byte params[max_params_bytes] = {};  ///< the kernel's parameter struct
};

/// Every dispatch before a barrier completes (and its writes are visible)
/// before any dispatch after it starts. Dispatches between two barriers may
/// run in any order or concurrently.
struct Barrier {};

/// The ordered dispatches of one frame.
class FrameProgram {
 public:
  using Command = std::variant<Dispatch, Barrier>;

  /// Appends a dispatch. [in] params: the kernel's struct from kernels/shared.
  template <class Params>
  void dispatch(Kernel kernel, std::uint32_t count, std::initializer_list<BufferHandle> bindings,
                const Params& params) {
    dispatch(kernel, count, std::span<const BufferHandle>(bindings.begin(), bindings.size()), params);
  }
  template <class Params>
  void dispatch(Kernel kernel, std::uint32_t count, std::span<const BufferHandle> bindings, const Params& params) {
    static_assert(std::is_trivially_copyable_v<Params> && sizeof(Params) <= Dispatch::max_params_bytes);
    Dispatch d;
    d.kernel = kernel;
    d.count = count;
    for (BufferHandle b : bindings) {
      if (d.binding_count < Dispatch::max_bindings) d.bindings[d.binding_count] = b;
      ++d.binding_count;  // a count above max_bindings is rejected by create_program
    }
    d.params_bytes = sizeof(Params);
    std::memcpy(d.params, &params, sizeof(Params));
    commands_.emplace_back(d);
  }
  /// Appends a dispatch built by hand (tests, tools).
  void dispatch_raw(const Dispatch& d) { commands_.emplace_back(d); }
  /// Appends a barrier (two barriers in a row collapse into one).
  void barrier() {
    if (!commands_.empty() && !std::holds_alternative<Barrier>(commands_.back())) commands_.emplace_back(Barrier{});
  }
  [[nodiscard]] const std::vector<Command>& commands() const { return commands_; }
  [[nodiscard]] std::size_t dispatch_count() const;
  [[nodiscard]] std::size_t barrier_count() const;
  /// Dispatches of one kernel.
  [[nodiscard]] std::size_t dispatch_count(Kernel kernel) const;

 private:
  std::vector<Command> commands_;
};

/// A program prepared by a device.
struct ProgramHandle {
  std::uint32_t id = UINT32_MAX;
};

/// How to pick a backend and device.
struct DeviceOptions {
  std::string backend = "auto";  ///< "cpu", "opencl", "vulkan" or "auto"
  /// opencl/vulkan: a device index or a substring of its name; empty: the
  /// environment variable SINEW_OPENCL_DEVICE / SINEW_VULKAN_DEVICE, else the
  /// first GPU, else the first device.
  std::string device = "";
  int threads = 0;               ///< cpu: worker threads; 0 = all hardware threads
  bool cpu_simd = true;          ///< cpu: use the AVX2 solves where the CPU has AVX2 (bitwise
                                 ///< equal to the scalar reference kernels, only faster)
  bool quiet = false;            ///< true: do not print the one-line fallback notice of "auto"
};

class Device {
 public:
  virtual ~Device() = default;
  /// "cpu", "opencl" or "vulkan".
  [[nodiscard]] virtual std::string backend_name() const = 0;
  /// A human-readable description of the device, e.g. "CPU reference (2 threads)".
  [[nodiscard]] virtual std::string device_name() const = 0;

  /// A buffer of `bytes` bytes (> 0), zero-filled. `label` names it in errors.
  virtual Result<BufferHandle> create_buffer(std::size_t bytes, std::string_view label) = 0;
  /// Copies host memory into a buffer. Errors: unknown buffer, range past its end.
  virtual Status write_buffer(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) = 0;
  /// Copies a buffer into host memory, after all submitted work has finished.
  virtual Status read_buffer(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) = 0;

  /// Checks and prepares a frame program: unknown kernels, unknown buffers,
  /// wrong binding or parameter counts are errors naming the dispatch.
  virtual Result<ProgramHandle> create_program(const FrameProgram& program) = 0;
  /// Runs a prepared program once and waits for it to finish.
  virtual Status run_program(ProgramHandle program) = 0;
  /// [out] times: device time of the last run_program; timed = false (and
  /// no error) where the device records no timestamps. Allocates nothing.
  virtual Status last_run_times(DeviceTimes& times) const {
    times = {};
    return {};
  }
};

/// Makes a device. Asking for a backend that is not built, or that has no
/// device, returns an error that says so. "auto" takes the first GPU found
/// by a built GPU backend (OpenCL, then Vulkan); without one it falls back
/// to "cpu" and prints one line saying why, once per process (unless
/// options.quiet).
Result<std::unique_ptr<Device>> create_device(const DeviceOptions& options = {});

/// The backends built into this library ("cpu" always).
std::vector<std::string> built_backends();

}  // namespace sinew
