// cpu_device.cpp — the CPU reference backend.
//
// A program runs its commands in order. Each dispatch is split into chunks
// that TBB runs on the device's own task arena; a barrier is implicit, since
// a parallel_for returns only when all of its chunks are done. The kernels
// (kernels/cpu) are plain scalar code and the test oracle for the GPU ones.
#include "backends/cpu/cpu_device.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <string>
#include <thread>

#include "backends/kernel_table.h"
#include "cpu/contact_kernels.h"
#include "cpu/fem_kernels.h"
#include "cpu/thin_kernels.h"
#include "cpu/xpbd_kernels.h"

namespace sinew {
namespace {

// The AVX2 solves do whole groups of eight; the scalar kernel does the rest.
void solve_distance_simd(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  kernels::xpbd_solve_distance(params, bindings, kernels::xpbd_solve_distance_avx2(params, bindings, begin, end), end);
}
void solve_volume_simd(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  kernels::xpbd_solve_volume(params, bindings, kernels::xpbd_solve_volume_avx2(params, bindings, begin, end), end);
}

kernels::CpuKernelFn cpu_kernel(Kernel kernel, bool simd) {
  if (simd && kernel == Kernel::xpbd_solve_distance) return solve_distance_simd;
  if (simd && kernel == Kernel::xpbd_solve_volume) return solve_volume_simd;
  switch (kernel) {
    case Kernel::xpbd_predict: return kernels::xpbd_predict;
    case Kernel::xpbd_update_velocity: return kernels::xpbd_update_velocity;
    case Kernel::xpbd_solve_distance: return kernels::xpbd_solve_distance;
    case Kernel::xpbd_solve_volume: return kernels::xpbd_solve_volume;
    case Kernel::xpbd_solve_neo_hookean: return kernels::xpbd_solve_neo_hookean;
    case Kernel::xpbd_solve_stvk: return kernels::xpbd_solve_stvk;
    case Kernel::xpbd_solve_corotational: return kernels::xpbd_solve_corotational;
    case Kernel::xpbd_solve_area: return kernels::xpbd_solve_area;
    case Kernel::xpbd_solve_dihedral: return kernels::xpbd_solve_dihedral;
    case Kernel::xpbd_solve_line_bending: return kernels::xpbd_solve_line_bending;
    case Kernel::xpbd_solve_attachment: return kernels::xpbd_solve_attachment;
    case Kernel::xpbd_solve_contacts: return kernels::xpbd_solve_contacts;
    case Kernel::count_: break;
  }
  return nullptr;
}

// 64-byte aligned, zero-filled host memory.
struct HostBuffer {
  struct Free {
    void operator()(std::byte* p) const { ::operator delete[](p, std::align_val_t{64}); }
  };
  std::unique_ptr<std::byte[], Free> data;
  std::size_t bytes = 0;
  std::string label;
};

// A dispatch resolved to raw pointers, ready to run.
struct CpuDispatch {
  kernels::CpuKernelFn fn;
  std::uint32_t count;
  std::byte* bindings[Dispatch::max_bindings];
  alignas(16) std::byte params[Dispatch::max_params_bytes];
};

class CpuDevice final : public Device {
 public:
  CpuDevice(int threads, bool simd) : threads_(threads), simd_(simd), arena_(threads) {}

  std::string backend_name() const override { return "cpu"; }
  std::string device_name() const override {
    return "CPU reference (" + std::to_string(threads_) + (threads_ == 1 ? " thread" : " threads") +
           (simd_ ? ", AVX2)" : ", scalar)");
  }

  Result<BufferHandle> create_buffer(std::size_t bytes, std::string_view label) override {
    if (bytes == 0) return Error("create_buffer '" + std::string(label) + "': size must be > 0");
    HostBuffer b;
    // Round up so kernels may read whole float4s at the end of any buffer.
    const std::size_t rounded = (bytes + 63) / 64 * 64;
    b.data.reset(static_cast<std::byte*>(::operator new[](rounded, std::align_val_t{64})));
    std::fill_n(b.data.get(), rounded, std::byte{0});
    b.bytes = bytes;
    b.label = label;
    buffers_.push_back(std::move(b));
    return BufferHandle{static_cast<std::uint32_t>(buffers_.size() - 1)};
  }

  Status write_buffer(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) override {
    auto target = range(buffer, offset, bytes, "write_buffer");
    if (!target) return target.status();
    std::memcpy(*target, data, bytes);
    return {};
  }

  Status read_buffer(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) override {
    auto source = range(buffer, offset, bytes, "read_buffer");
    if (!source) return source.status();
    std::memcpy(data, *source, bytes);
    return {};
  }

  Result<ProgramHandle> create_program(const FrameProgram& program) override {
    if (Status s = check_program(program, static_cast<std::uint32_t>(buffers_.size())); !s) return s.error();
    std::vector<CpuDispatch> steps;
    for (const auto& command : program.commands()) {
      const auto* d = std::get_if<Dispatch>(&command);
      if (!d || d->count == 0) continue;  // barriers are implicit, see the top of this file
      CpuDispatch c{};
      c.fn = cpu_kernel(d->kernel, simd_);
      c.count = d->count;
      for (std::uint32_t b = 0; b < d->binding_count; ++b) c.bindings[b] = buffers_[d->bindings[b].id].data.get();
      std::memcpy(c.params, d->params, d->params_bytes);
      steps.push_back(c);
    }
    programs_.push_back(std::move(steps));
    return ProgramHandle{static_cast<std::uint32_t>(programs_.size() - 1)};
  }

  Status run_program(ProgramHandle program) override {
    if (program.id >= programs_.size()) return Error("run_program: not a program of this device");
    const auto& steps = programs_[program.id];
    arena_.execute([&] {
      for (const CpuDispatch& d : steps) run(d);
    });
    return {};
  }

 private:
  // Small dispatches run inline: below this many items the cost of waking
  // other threads exceeds the work.
  static constexpr std::uint32_t kSerialBelow = 1024;

  void run(const CpuDispatch& d) {
    if (d.count < kSerialBelow || threads_ == 1) {
      d.fn(d.params, d.bindings, 0, d.count);
      return;
    }
    // Static partition: one contiguous chunk per thread, no stealing. The
    // result does not depend on the split (a dispatch's items are independent).
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, d.count, 256),
                      [&](const tbb::blocked_range<std::uint32_t>& r) { d.fn(d.params, d.bindings, r.begin(), r.end()); },
                      tbb::static_partitioner());
  }

  Result<std::byte*> range(BufferHandle buffer, std::size_t offset, std::size_t bytes, const char* what) {
    if (buffer.id >= buffers_.size()) return Error(std::string(what) + ": not a buffer of this device");
    HostBuffer& b = buffers_[buffer.id];
    if (Status s = check_buffer_range(b.label, b.bytes, offset, bytes, what); !s) return s.error();
    return b.data.get() + offset;
  }

  int threads_;
  bool simd_;
  tbb::task_arena arena_;
  std::vector<HostBuffer> buffers_;
  std::vector<std::vector<CpuDispatch>> programs_;
};

}  // namespace

Result<std::unique_ptr<Device>> make_cpu_device(const DeviceOptions& options) {
  if (options.threads < 0) return Error("DeviceOptions.threads must be >= 0 (0 = all hardware threads), got " +
                                        std::to_string(options.threads));
  const int threads =
      options.threads > 0 ? options.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const bool simd = options.cpu_simd && kernels::cpu_has_avx2();
  return std::unique_ptr<Device>(std::make_unique<CpuDevice>(threads, simd));
}

}  // namespace sinew
