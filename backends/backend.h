// backend.h — the backend interface (internal: users describe scenes, the
// library writes frame programs).
//
// A Device owns buffers and runs *frame programs*: the ordered commands of
// one frame — kernel dispatches, buffer fills and copies, barriers — built
// once per scene and run every frame, so a backend can prepare them (the
// Vulkan backend records a command buffer once). Virtual calls happen per
// command at preparation and per program at run time, never per item.
//
// Work whose size is known only on the device (pairs found, contacts made,
// particles emitted) is expressed with *counters*: a uint word in a device
// buffer, declared with a capacity, that kernels of the frame write; a
// dispatch may take its work-item count from a counter (an indirect
// dispatch), and after every run the device reads all declared counters
// back (a few words, copied at the end of the frame, no extra round trip)
// and reports any that exceeded its capacity as a capacity_exceeded error.
// A program's small results (the statistics, a residual check) travel the
// same way as *end reads*: ranges copied after its last command and brought
// back by the wait that ends it (FrameProgram::read_at_end).
//
// Backends: "cpu" (the reference; every dispatch runs in parallel with TBB),
// "opencl" and "vulkan" (when built).
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

#include "backends/kernel.h"
#include "sinew/device.h"
#include "sinew/result.h"

namespace sinew {

/// A device buffer; valid only with the device that made it. Ids are never
/// reused, so a handle to a destroyed buffer stays invalid.
struct BufferHandle {
  std::uint32_t id = UINT32_MAX;
  friend bool operator==(BufferHandle, BufferHandle) = default;
  [[nodiscard]] bool valid() const { return id != UINT32_MAX; }
};

/// One kernel launch over work items [0, count). A cooperative kernel
/// (group size G > 0 in the registry) runs ceil(count / G) groups.
/// Indirect (indirect.buffer valid): the item count is read from a counter
/// of the program when the dispatch runs, and `count` is its capacity
/// (see FrameProgram::dispatch_indirect).
struct Dispatch {
  static constexpr std::size_t max_bindings = 12;
  static constexpr std::size_t max_params_bytes = 64;
  Kernel kernel = Kernel::count_;
  std::uint32_t count = 0;                            ///< work items (the capacity when indirect)
  struct {
    BufferHandle buffer;                              ///< invalid: a direct dispatch
    std::uint32_t word = 0;                           ///< the count is buffer's uint at this word
  } indirect;
  std::uint32_t binding_count = 0;
  BufferHandle bindings[max_bindings] = {};           ///< in the kernel's binding order
  std::uint32_t params_bytes = 0;
  alignas(16) std::byte params[max_params_bytes] = {};  ///< the kernel's parameter struct
};

/// Sets words [word, word + words) of a buffer to `value`.
struct Fill {
  BufferHandle buffer;
  std::uint32_t word = 0;
  std::uint32_t words = 0;
  std::uint32_t value = 0;
};

/// Copies `words` 32-bit words from source (at source_word) to target (at
/// target_word); the two ranges must not overlap.
struct Copy {
  BufferHandle source;
  std::uint32_t source_word = 0;
  BufferHandle target;
  std::uint32_t target_word = 0;
  std::uint32_t words = 0;
};

/// Every command before a barrier completes (and its writes are visible)
/// before any command after it starts. Commands between two barriers may
/// run in any order or concurrently.
struct Barrier {};

/// A uint word of a device buffer that the frame's kernels count into, with
/// the most it may reach. The value at the end of the frame is read back
/// and checked, so a frame resets its counters (Fill) before it counts.
struct Counter {
  std::string label;      ///< names it in the capacity_exceeded error
  BufferHandle buffer;
  std::uint32_t word = 0;
  std::uint32_t capacity = 0;
};

/// Words of a device buffer read back when the program ends, with its
/// counters: the frame's small results (the statistics' reductions) reach
/// the host in the wait that ends the program, not in a round trip of their
/// own (FrameProgram::read_at_end, Device::end_reads).
struct EndRead {
  BufferHandle buffer;
  std::uint32_t word = 0;
  std::uint32_t words = 0;
};

/// The ordered commands of one frame.
class FrameProgram {
 public:
  using Command = std::variant<Dispatch, Barrier, Fill, Copy>;

  /// Appends a dispatch. [in] params: the kernel's struct from kernels/shared.
  template <class Params>
  void dispatch(Kernel kernel, std::uint32_t count, std::initializer_list<BufferHandle> bindings,
                const Params& params) {
    dispatch(kernel, count, std::span<const BufferHandle>(bindings.begin(), bindings.size()), params);
  }
  template <class Params>
  void dispatch(Kernel kernel, std::uint32_t count, std::span<const BufferHandle> bindings, const Params& params) {
    commands_.emplace_back(make_dispatch(kernel, count, bindings, params));
  }
  /// Appends a dispatch over as many items as counter `counter` (an index
  /// returned by counter()) holds when it runs, at most its capacity. The
  /// kernel reads the count itself (its parameters name the word) and
  /// returns for items past it: GPU backends may launch up to the capacity.
  template <class Params>
  void dispatch_indirect(Kernel kernel, std::uint32_t counter, std::initializer_list<BufferHandle> bindings,
                         const Params& params) {
    const Counter& c = counters_.at(counter);
    Dispatch d = make_dispatch(kernel, c.capacity,
                               std::span<const BufferHandle>(bindings.begin(), bindings.size()), params);
    d.indirect.buffer = c.buffer;
    d.indirect.word = c.word;
    commands_.emplace_back(d);
  }
  /// Appends a dispatch built by hand (tests, tools).
  void dispatch_raw(const Dispatch& d) { commands_.emplace_back(d); }
  void fill(BufferHandle buffer, std::uint32_t word, std::uint32_t words, std::uint32_t value) {
    commands_.emplace_back(Fill{buffer, word, words, value});
  }
  void copy(BufferHandle source, std::uint32_t source_word, BufferHandle target, std::uint32_t target_word,
            std::uint32_t words) {
    commands_.emplace_back(Copy{source, source_word, target, target_word, words});
  }
  /// Appends a barrier (two barriers in a row collapse into one).
  void barrier() {
    if (!commands_.empty() && !std::holds_alternative<Barrier>(commands_.back())) commands_.emplace_back(Barrier{});
  }
  /// Declares a counter; returns its index (the order of Device::counters()).
  std::uint32_t counter(std::string label, BufferHandle buffer, std::uint32_t word, std::uint32_t capacity) {
    counters_.push_back({std::move(label), buffer, word, capacity});
    return static_cast<std::uint32_t>(counters_.size() - 1);
  }

  /// Declares words [word, word + words) of `buffer` to be read back when
  /// the program has run, after its last command (the device copies them
  /// with the counters). Returns where they start in Device::end_reads().
  std::uint32_t read_at_end(BufferHandle buffer, std::uint32_t word, std::uint32_t words) {
    const std::uint32_t at = end_read_words_;
    end_reads_.push_back({buffer, word, words});
    end_read_words_ += words;
    return at;
  }

  [[nodiscard]] const std::vector<Command>& commands() const { return commands_; }
  [[nodiscard]] const std::vector<Counter>& counters() const { return counters_; }
  [[nodiscard]] const std::vector<EndRead>& end_reads() const { return end_reads_; }
  /// The end reads' words in all (the size of Device::end_reads()).
  [[nodiscard]] std::uint32_t end_read_words() const { return end_read_words_; }
  [[nodiscard]] std::size_t dispatch_count() const;
  [[nodiscard]] std::size_t barrier_count() const;
  /// Dispatches of one kernel.
  [[nodiscard]] std::size_t dispatch_count(Kernel kernel) const;

 private:
  template <class Params>
  static Dispatch make_dispatch(Kernel kernel, std::uint32_t count, std::span<const BufferHandle> bindings,
                                const Params& params) {
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
    return d;
  }

  std::vector<Command> commands_;
  std::vector<Counter> counters_;
  std::vector<EndRead> end_reads_;
  std::uint32_t end_read_words_ = 0;
};

/// A program prepared by a device.
struct ProgramHandle {
  std::uint32_t id = UINT32_MAX;
};

/// What the host exchanged with a device, counted by the Device itself
/// (every backend alike), from its creation on.
struct HostTransfers {
  std::uint64_t read_bytes = 0;   ///< bytes copied device -> host (read_buffer)
  std::uint64_t reads = 0;        ///< read_buffer calls
  std::uint64_t write_bytes = 0;  ///< bytes copied host -> device (write_buffer)
  std::uint64_t submits = 0;      ///< programs submitted
  /// Times the host blocked on the device: every read_buffer (a round trip),
  /// and every wait(), write_buffer or submit that found a submission in
  /// flight. (Creating, resizing or destroying a buffer while one is in
  /// flight also waits and is not counted; the runtime does that only on
  /// topology changes, between frames' programs.)
  std::uint64_t waits = 0;
};

/// What a device holds now (tests check that destroying gives it back).
struct DeviceObjects {
  std::uint32_t buffers = 0;       ///< live buffers
  std::uint64_t buffer_bytes = 0;  ///< their sizes as asked for
  std::uint32_t programs = 0;      ///< live programs
  /// Backend objects behind them (Vulkan: buffers, memory allocations,
  /// descriptor pools, command buffers, query pools; OpenCL: cl_mem; CPU:
  /// host allocations), not counting the device's own fixed set.
  std::uint32_t native = 0;
};

class Device {
 public:
  virtual ~Device() = default;
  /// "cpu", "opencl" or "vulkan".
  [[nodiscard]] virtual std::string backend_name() const = 0;
  /// A human-readable description of the device, e.g. "CPU reference (2 threads)".
  [[nodiscard]] virtual std::string device_name() const = 0;

  // ---------------------------------------------------------------- buffers
  // Calls that touch buffers first wait for a submission in flight.

  /// A buffer of `bytes` bytes (> 0), zero-filled. `label` names it in errors.
  virtual Result<BufferHandle> create_buffer(std::size_t bytes, std::string_view label) = 0;
  /// Frees a buffer and its device memory. A program that binds it can no
  /// longer be submitted (an error names the buffer); destroy or rebuild it.
  virtual Status destroy_buffer(BufferHandle buffer) = 0;
  /// Gives a buffer a new size (> 0), keeping its handle and its first
  /// min(old, new) bytes; the rest is zero. Programs that use it are
  /// prepared again at their next submission (Vulkan records them again).
  virtual Status resize_buffer(BufferHandle buffer, std::size_t bytes) = 0;
  /// Copies host memory into a buffer. Errors: unknown buffer, range past its end.
  Status write_buffer(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) {
    settle();
    transfers_.write_bytes += bytes;
    return write_buffer_impl(buffer, offset, data, bytes);
  }
  /// Copies a buffer into host memory: a round trip, the host waits for
  /// the device (HostTransfers::waits).
  Status read_buffer(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) {
    in_flight_ = false;
    ++transfers_.waits;
    ++transfers_.reads;
    transfers_.read_bytes += bytes;
    return read_buffer_impl(buffer, offset, data, bytes);
  }

  // ---------------------------------------------------------------- programs

  /// Checks and prepares a frame program: unknown kernels, buffers or
  /// counters, wrong binding or parameter counts, ranges past a buffer's
  /// end are errors naming the command.
  virtual Result<ProgramHandle> create_program(const FrameProgram& program) = 0;
  /// Frees a program and everything the device made for it.
  virtual Status destroy_program(ProgramHandle program) = 0;
  /// Starts a program and returns without waiting (on the CPU backend it
  /// has finished when this returns). One submission is in flight at a
  /// time: submitting again first waits for the previous one.
  Status submit(ProgramHandle program) {
    settle();
    ++transfers_.submits;
    Status s = submit_impl(program);
    in_flight_ = static_cast<bool>(s);
    return s;
  }
  /// Waits for the submission in flight (none: returns at once), then
  /// checks its counters: a counter above its capacity is a
  /// capacity_exceeded error naming it (the frame's other results stand).
  Status wait() {
    settle();
    return wait_impl();
  }
  /// submit() then wait().
  Status run_program(ProgramHandle program) {
    if (Status s = submit(program); !s) return s;
    return wait();
  }
  /// The counters of the last program waited for, in declaration order, as
  /// they were at the end of its run. Allocates nothing.
  [[nodiscard]] virtual std::span<const std::uint32_t> counters() const = 0;
  /// The words the last program waited for declared with
  /// FrameProgram::read_at_end, as they were at the end of its run, its
  /// ranges one after another in declaration order; empty before a wait.
  /// Their bytes count as read back (HostTransfers::read_bytes) in the wait
  /// that brought them, with no wait or read of their own. Allocates nothing.
  [[nodiscard]] virtual std::span<const std::uint32_t> end_reads() const = 0;
  /// [out] times: device time of the last program waited for; timed =
  /// false (and no error) where the device records no timestamps.
  /// Allocates nothing.
  virtual Status last_run_times(DeviceTimes& times) const {
    times = {};
    return {};
  }
  /// What the device holds now.
  [[nodiscard]] virtual DeviceObjects objects() const = 0;
  /// What the host has exchanged with the device since it was made (the
  /// runtime takes per-frame differences: FrameStats::host_waits, ...).
  [[nodiscard]] const HostTransfers& transfers() const { return transfers_; }

 protected:
  // What each backend implements; the public calls above count them.
  virtual Status write_buffer_impl(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) = 0;
  virtual Status read_buffer_impl(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) = 0;
  virtual Status submit_impl(ProgramHandle program) = 0;
  virtual Status wait_impl() = 0;
  /// A backend's wait_impl, for the end reads of the program it finished.
  void count_end_reads(std::size_t words) { transfers_.read_bytes += 4 * words; }

 private:
  // A call that waits for the submission in flight (wait(), a write, the
  // next submit) counts one wait if there is one; a backend's own calls
  // inside an _impl then find none in flight and count nothing more.
  void settle() {
    if (in_flight_) ++transfers_.waits;
    in_flight_ = false;
  }
  HostTransfers transfers_;
  bool in_flight_ = false;
};

/// Makes a device. Asking for a backend that is not built, or that has no
/// device, returns an error that says so (ErrorCode::backend_unavailable).
/// "auto" takes the first GPU found by a built GPU backend (OpenCL, then
/// Vulkan); without one it falls back to "cpu" and prints one line saying
/// why, once per process (unless options.quiet).
Result<std::unique_ptr<Device>> create_device(const DeviceOptions& options = {});

}  // namespace sinew
