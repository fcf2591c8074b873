// cpu_device.cpp — the CPU reference backend.
//
// A program runs its commands in order on a team of threads (cpu_team.h)
// that share each dispatch and meet at a barrier between dependent ones
// (run_steps). Independent kernels get ranges of items; cooperative kernels (a group size in the
// registry) get ranges of groups and do each group's work in order, so the
// CPU reference of a scan or a sort is plain sequential code per group.
// Indirect dispatches read their count from the counter word when they run.
// Each member's share of a dispatch follows its measured speed (Shares); a
// program with nothing worth sharing, or that the team runs no faster than
// one thread (measured: WidthChoice), runs on the calling thread alone.
// The kernels (kernels/cpu) are plain scalar code and the test oracle for
// the GPU ones.
#include "backends/cpu/cpu_device.h"
#include "backends/cpu/cpu_sharing.h"
#include "backends/cpu/cpu_team.h"
#include "hooks/hooks_internal.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <memory>
#include <new>
#include <string>
#include <thread>

#include "backends/kernel_table.h"
#include "cpu/cpu_kernels.h"
#include "cpu/fem_kernels.h"   // the AVX2 FEM solves
#include "cpu/neighbour_kernels.h"  // the AVX2 neighbour query
#include "cpu/sph_kernels.h"        // the AVX2 fluid density and step
#include "cpu/xpbd_kernels.h"  // the AVX2 distance and volume solves

namespace sinew {
namespace {

// The AVX2 solves do whole groups of eight; the scalar kernel does the rest.
void solve_distance_simd(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  kernels::xpbd_solve_distance(params, bindings, kernels::xpbd_solve_distance_avx2(params, bindings, begin, end), end);
}
void solve_volume_simd(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  kernels::xpbd_solve_volume(params, bindings, kernels::xpbd_solve_volume_avx2(params, bindings, begin, end), end);
}
void solve_neo_hookean_simd(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  kernels::xpbd_solve_neo_hookean(params, bindings, kernels::xpbd_solve_neo_hookean_avx2(params, bindings, begin, end),
                                  end);
}
void solve_stvk_simd(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  kernels::xpbd_solve_stvk(params, bindings, kernels::xpbd_solve_stvk_avx2(params, bindings, begin, end), end);
}
void solve_corotational_simd(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  kernels::xpbd_solve_corotational(params, bindings,
                                   kernels::xpbd_solve_corotational_avx2(params, bindings, begin, end), end);
}

// The CPU reference of every registered kernel: kernels::NAME.
constexpr kernels::CpuKernelFn kReference[] = {
#define SINEW_CPU_KERNEL(name, bindings, params, group) kernels::name,
    SINEW_KERNELS(SINEW_CPU_KERNEL)
#undef SINEW_CPU_KERNEL
};
static_assert(std::size(kReference) == kernel_count);

kernels::CpuKernelFn cpu_kernel(Kernel kernel, bool simd) {
  if (simd && kernel == Kernel::xpbd_solve_distance) return solve_distance_simd;
  if (simd && kernel == Kernel::xpbd_solve_volume) return solve_volume_simd;
  if (simd && kernel == Kernel::xpbd_solve_neo_hookean) return solve_neo_hookean_simd;
  if (simd && kernel == Kernel::xpbd_solve_stvk) return solve_stvk_simd;
  if (simd && kernel == Kernel::xpbd_solve_corotational) return solve_corotational_simd;
  if (simd && kernel == Kernel::nbr_query) return kernels::nbr_query_avx2;
  if (simd && kernel == Kernel::sph_density) return kernels::sph_density_avx2;
  if (simd && kernel == Kernel::sph_step) return kernels::sph_step_avx2;
  if (simd && kernel == Kernel::sph_boundary_force) return kernels::sph_boundary_force_avx2;
  return kReference[static_cast<std::size_t>(kernel)];
}

// Rough cost of one item of a kernel on one core [ns], so that the split of
// a dispatch follows its work, not only its item count: an FEM tet costs
// as much as ~25 distance constraints, and 800 of them (one colour of a
// 25,000-tet body) are worth two threads where 800 edges are not. Measured
// with organ_step --threads 1 on kidney_57k (10 substeps x 1 iteration):
// distance and volume ~6.5 ns per constraint (AVX2), neo_hookean ~110 ns
// per tet (scalar), stvk ~130, corotational ~150; the others estimated from
// their arithmetic. Only the order of magnitude matters. (Cube of 10,368
// Neo-Hookean tets at 5 iterations, 2 threads: 5.2 -> 2.7 ms per frame
// against deciding by item count alone, which ran its colours on one thread.)
std::uint32_t item_cost_ns(Kernel kernel) {
  switch (kernel) {
    case Kernel::xpbd_solve_distance: return 4;
    case Kernel::xpbd_solve_volume: return 8;
    case Kernel::xpbd_solve_neo_hookean: return 110;
    case Kernel::xpbd_solve_stvk: return 130;
    case Kernel::xpbd_solve_corotational: return 150;
    case Kernel::xpbd_solve_area: return 30;
    case Kernel::xpbd_solve_dihedral: return 80;
    case Kernel::xpbd_solve_line_bending: return 30;
    case Kernel::xpbd_solve_contacts: return 40;
    default: return 4;
  }
}

constexpr std::size_t kBufferAlignment = 64;

// 64-byte aligned, zero-filled host memory: from the engine's allocation
// hooks when it set them (sinew/hooks.h), given back through the same
// hooks, else from the C++ heap.
// (The deleter is declared outside HostBuffer: a nested class with member
// initialisers is not yet default-constructible inside its enclosing class.)
struct FreeHostMemory {
  std::shared_ptr<const AllocationHooks> hooks;  // null: the heap
  std::size_t bytes = 0;                         // as allocated (rounded)
  void operator()(std::byte* p) const {
    if (hooks)
      hooks->deallocate(p, bytes, kBufferAlignment);
    else
      ::operator delete[](p, std::align_val_t{kBufferAlignment});
  }
};

struct HostBuffer {
  using Free = FreeHostMemory;
  std::unique_ptr<std::byte[], Free> data;
  std::size_t bytes = 0;  // 0: destroyed
  std::string label;
};

// Round up so kernels may read whole float4s at the end of any buffer.
// out_of_memory, naming the buffer, when neither the hooks nor the heap has it.
Result<std::unique_ptr<std::byte[], HostBuffer::Free>> allocate(const std::shared_ptr<const AllocationHooks>& hooks,
                                                                std::size_t bytes, std::string_view label) {
  const std::size_t rounded = (bytes + kBufferAlignment - 1) / kBufferAlignment * kBufferAlignment;
  void* memory = nullptr;
  if (hooks) {
    try {
      memory = hooks->allocate(rounded, kBufferAlignment);
    } catch (...) {  // an engine's allocator that throws has no memory either
      memory = nullptr;
    }
  } else {
    memory = ::operator new[](rounded, std::align_val_t{kBufferAlignment}, std::nothrow);
  }
  if (!memory)
    return Error(ErrorCode::out_of_memory, "cpu buffer '" + std::string(label) + "': " + std::to_string(rounded) +
                                               " bytes could not be allocated" +
                                               (hooks ? " (the allocation hook returned none)" : ""));
  std::unique_ptr<std::byte[], HostBuffer::Free> p(static_cast<std::byte*>(memory), HostBuffer::Free{hooks, rounded});
  std::fill_n(p.get(), rounded, std::byte{0});
  return p;
}

// A command resolved to raw pointers, ready to run.
struct CpuStep {
  enum class Kind { dispatch, fill, copy } kind = Kind::dispatch;
  kernels::CpuKernelFn fn = nullptr;
  std::uint32_t count = 0;       // items (independent) or groups (cooperative), or the capacity when indirect
  std::uint32_t group_size = 0;  // 0: independent items
  std::uint32_t cost_ns = 4;     // item_cost_ns of the kernel (per item, or per group member)
  bool solo = false;             // known at resolve time to run on member 0 alone (see run_steps)
  const std::uint32_t* indirect = nullptr;  // the counter word of an indirect dispatch
  std::uint32_t indirect_buffer = UINT32_MAX;  // the buffer id holding it
  // An indirect dispatch of the same kernel on the same buffers as the step
  // before, its counter in the same buffer (mesh contacts' colours): after
  // an empty one no barrier is needed before it (run_steps).
  bool chains_previous = false;
  std::byte* bindings[Dispatch::max_bindings] = {};
  alignas(16) std::byte params[Dispatch::max_params_bytes] = {};
  std::uint32_t* target = nullptr;  // fill, copy
  const std::uint32_t* source = nullptr;
  std::uint32_t words = 0, value = 0;
};

struct CpuProgram {
  bool live = false;
  FrameProgram source;            // kept to resolve again after a buffer is resized
  std::uint64_t resolved_at = 0;  // the device's resize generation the pointers are from
  std::vector<CpuStep> steps;
  bool alone = false;  // nothing in it worth sharing: never wakes the team
  WidthChoice width;
  std::vector<const std::uint32_t*> counter_words;
  std::vector<const std::uint32_t*> end_read_words;  // the first word of each end read
};

class CpuDevice final : public Device {
 public:
  CpuDevice(int threads, bool simd, bool adaptive)
      : simd_(simd),
        adaptive_(adaptive),
        team_(static_cast<unsigned>(threads), hooks::tasks()->start_thread),
        shares_(team_.members()),
        busy_(team_.members()) {}

  std::string backend_name() const override { return "cpu"; }
  std::string device_name() const override {
    const unsigned threads = team_.members();
    return "CPU reference (" + std::to_string(threads) + (threads == 1 ? " thread" : " threads") +
           (simd_ ? ", AVX2)" : ", scalar)");
  }

  Result<BufferHandle> create_buffer(std::size_t bytes, std::string_view label) override {
    if (bytes == 0) return Error(ErrorCode::internal, "create_buffer '" + std::string(label) + "': size must be > 0");
    auto data = allocate(allocation_hooks_, bytes, label);
    if (!data) return data.error();
    HostBuffer b;
    b.data = std::move(*data);
    b.bytes = bytes;
    b.label = label;
    buffers_.push_back(std::move(b));
    sizes_.push_back(bytes);
    return BufferHandle{static_cast<std::uint32_t>(buffers_.size() - 1)};
  }

  Status destroy_buffer(BufferHandle buffer) override {
    auto b = live_buffer(buffer, "destroy_buffer");
    if (!b) return b.status();
    (*b)->data.reset();
    (*b)->bytes = 0;
    sizes_[buffer.id] = 0;
    ++generation_;  // programs binding it fail at their next resolve
    return {};
  }

  Status resize_buffer(BufferHandle buffer, std::size_t bytes) override {
    auto b = live_buffer(buffer, "resize_buffer");
    if (!b) return b.status();
    if (bytes == 0) return Error(ErrorCode::internal, "resize_buffer '" + (*b)->label + "': size must be > 0");
    auto data = allocate(allocation_hooks_, bytes, (*b)->label);
    if (!data) return data.error();
    std::memcpy(data->get(), (*b)->data.get(), std::min(bytes, (*b)->bytes));
    (*b)->data = std::move(*data);
    (*b)->bytes = bytes;
    sizes_[buffer.id] = bytes;
    ++generation_;
    return {};
  }

  Status write_buffer_impl(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) override {
    auto target = range(buffer, offset, bytes, "write_buffer");
    if (!target) return target.status();
    std::memcpy(*target, data, bytes);
    return {};
  }

  Status read_buffer_impl(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) override {
    auto source = range(buffer, offset, bytes, "read_buffer");
    if (!source) return source.status();
    std::memcpy(data, *source, bytes);
    return {};
  }

  Result<ProgramHandle> create_program(const FrameProgram& program) override {
    CpuProgram p;
    p.live = true;
    p.source = program;
    if (Status s = resolve(p); !s) return s.error();
    programs_.push_back(std::move(p));
    return ProgramHandle{static_cast<std::uint32_t>(programs_.size() - 1)};
  }

  Status destroy_program(ProgramHandle program) override {
    if (program.id >= programs_.size() || !programs_[program.id].live)
      return Error(ErrorCode::internal, "destroy_program: not a live program of this device");
    programs_[program.id] = CpuProgram{};
    return {};
  }

  // The CPU runs the program here; wait() only checks its counters.
  Status submit_impl(ProgramHandle program) override {
    if (program.id >= programs_.size() || !programs_[program.id].live)
      return Error(ErrorCode::internal, "submit: not a live program of this device");
    CpuProgram& p = programs_[program.id];
    if (p.resolved_at != generation_)
      if (Status s = resolve(p); !s) return s;
    struct Job {
      CpuDevice* device;
      const std::vector<CpuStep>* steps;
    } job{this, &p.steps};
    const bool on_team = !p.alone && (!adaptive_ || p.width.next_on_team());
    const auto start = std::chrono::steady_clock::now();
    if (on_team) {
      for (Busy& b : busy_) b.ns = 0.0;
      team_.run([](void* context, unsigned member) {
        const Job& j = *static_cast<const Job*>(context);
        j.device->run_steps(*j.steps, member);
      }, &job);
      double busy[Shares::kMaxMembers];
      for (unsigned m = 0; m < team_.members(); ++m) busy[m] = busy_[m].ns;
      shares_.update(busy);
    } else {
      run_alone(p.steps);
    }
    if (!p.alone && adaptive_)
      p.width.record(on_team, std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count());
    counters_.resize(p.counter_words.size());
    for (std::size_t c = 0; c < counters_.size(); ++c) counters_[c] = *p.counter_words[c];
    end_reads_.resize(p.source.end_read_words());
    std::uint32_t* to = end_reads_.data();
    for (std::size_t r = 0; r < p.end_read_words.size(); ++r)
      to = std::copy_n(p.end_read_words[r], p.source.end_reads()[r].words, to);
    submitted_ = program.id;
    return {};
  }

  Status wait_impl() override {
    if (submitted_ == UINT32_MAX) return {};
    const CpuProgram& p = programs_[submitted_];
    submitted_ = UINT32_MAX;
    count_end_reads(end_reads_.size());
    return check_counters(p.source.counters(), counters_);
  }

  std::span<const std::uint32_t> counters() const override { return counters_; }
  std::span<const std::uint32_t> end_reads() const override { return end_reads_; }

  DeviceObjects objects() const override {
    DeviceObjects o;
    for (const HostBuffer& b : buffers_)
      if (b.bytes) {
        ++o.buffers;
        o.buffer_bytes += b.bytes;
      }
    o.native = o.buffers;
    for (const CpuProgram& p : programs_) o.programs += p.live ? 1 : 0;
    return o;
  }

 private:
  // Small dispatches run on one member: below this much work [ns, by
  // item_cost_ns] sharing it costs more than it saves (about 500 distance
  // constraints, or 18 Neo-Hookean tets).
  static constexpr std::uint64_t kSerialBelowNs = 2048;

  // Resolves a program's commands to pointers (at creation, and again
  // after a buffer was resized or destroyed).
  Status resolve(CpuProgram& p) {
    if (Status s = check_program(p.source, sizes_); !s) return s;
    std::vector<CpuStep> steps;
    auto words = [&](BufferHandle b, std::uint32_t word) {
      return reinterpret_cast<std::uint32_t*>(buffers_[b.id].data.get()) + word;
    };
    for (const auto& command : p.source.commands()) {
      CpuStep c;
      if (const auto* f = std::get_if<Fill>(&command)) {
        c.kind = CpuStep::Kind::fill;
        c.target = words(f->buffer, f->word);
        c.words = f->words;
        c.value = f->value;
      } else if (const auto* k = std::get_if<Copy>(&command)) {
        c.kind = CpuStep::Kind::copy;
        c.source = words(k->source, k->source_word);
        c.target = words(k->target, k->target_word);
        c.words = k->words;
      } else if (const auto* d = std::get_if<Dispatch>(&command)) {
        if (d->count == 0) continue;  // barriers are implicit, see the top of this file
        c.fn = cpu_kernel(d->kernel, simd_);
        c.count = d->count;
        c.group_size = kernel_signature(d->kernel).group_size;
        c.cost_ns = item_cost_ns(d->kernel);
        if (d->indirect.buffer.valid()) {
          c.indirect = words(d->indirect.buffer, d->indirect.word);
          c.indirect_buffer = d->indirect.buffer.id;
        }
        for (std::uint32_t b = 0; b < d->binding_count; ++b) c.bindings[b] = buffers_[d->bindings[b].id].data.get();
        std::memcpy(c.params, d->params, d->params_bytes);
      } else {
        continue;
      }
      if (c.kind != CpuStep::Kind::dispatch) {
        c.solo = true;
      } else if (!c.indirect) {
        const std::uint64_t items = c.group_size > 0 ? (std::uint64_t{c.count} + c.group_size - 1) / c.group_size
                                                     : c.count;
        c.solo = items * c.cost_ns * (c.group_size > 0 ? c.group_size : 1) < kSerialBelowNs;
      }
      if (c.indirect && !steps.empty()) {
        const CpuStep& before = steps.back();
        c.chains_previous = before.kind == CpuStep::Kind::dispatch && before.indirect && before.fn == c.fn &&
                            before.indirect_buffer == c.indirect_buffer &&
                            std::equal(std::begin(before.bindings), std::end(before.bindings), std::begin(c.bindings));
      }
      steps.push_back(c);
    }
    // Indirect dispatches are never solo (their count is known only when
    // they run), so a program of solo steps alone has nothing to share.
    p.alone = team_.members() == 1 ||
              std::all_of(steps.begin(), steps.end(), [](const CpuStep& s) { return s.solo; });
    p.steps = std::move(steps);
    p.counter_words.clear();
    for (const Counter& c : p.source.counters()) p.counter_words.push_back(words(c.buffer, c.word));
    p.end_read_words.clear();
    for (const EndRead& r : p.source.end_reads()) p.end_read_words.push_back(words(r.buffer, r.word));
    p.resolved_at = generation_;
    return {};
  }

  // One member's walk through a program (cpu_team.h): every member visits
  // every step in order, runs its share of it, and meets the others at a
  // barrier before a step that may read what the previous one wrote.
  // Fills, copies and dispatches too small to share (below kSerialBelowNs)
  // are member 0's alone; consecutive ones need no barrier between them.
  // The result does not depend on the split: a dispatch's items (or
  // groups) are independent.
  // An indirect dispatch that found no items wrote nothing, so the barrier
  // after it can be skipped when the next step is another of its chain
  // (chains_previous: the same kernel on the same buffers, its count in the
  // same buffer, as the mesh contacts' colours are). Why only then: a
  // member may still be reading the empty dispatch's count while another
  // runs the next step, which must therefore not write that count; a
  // kernel writing the counters its own dispatches read (a fill of them, a
  // kernel consuming them) would race, and members that read different
  // counts would meet different barriers and hang. Kernels never write the
  // counter words their own chain is dispatched by.
  // Mesh contacts dispatch every colour their program has room for, most
  // of them empty in most frames (measured, medians of 2-3 runs alternating
  // with the previous build, 2 threads: bench_mesh_contacts' coloured
  // blocks 1.45 -> 1.12 ms per frame, fold 2.21 -> 1.90; the continuous
  // collision benchmark's probe scene, 32 colours per sweep, 3.6 -> 1.56).
  void run_steps(const std::vector<CpuStep>& steps, unsigned member) {
    const unsigned members = team_.members();
    bool after_empty = false;
    for (std::size_t i = 0; i < steps.size(); ++i) {
      const CpuStep& s = steps[i];
      if (i > 0 && !(steps[i - 1].solo && s.solo) && !(after_empty && s.chains_previous)) team_.barrier();
      after_empty = false;
      switch (s.kind) {
        case CpuStep::Kind::fill:
          if (member == 0) std::fill_n(s.target, s.words, s.value);
          continue;
        case CpuStep::Kind::copy:
          if (member == 0) std::copy_n(s.source, s.words, s.target);
          continue;
        case CpuStep::Kind::dispatch: break;
      }
      // An indirect dispatch reads its count after the barrier before it
      // (it is never solo), so every member sees the same count.
      std::uint32_t items = s.indirect ? std::min(*s.indirect, s.count) : s.count;
      if (s.group_size > 0)
        items = static_cast<std::uint32_t>((std::uint64_t{items} + s.group_size - 1) / s.group_size);
      if (items == 0) {
        after_empty = true;
        continue;
      }
      const std::uint64_t item_ns = std::uint64_t{s.cost_ns} * (s.group_size > 0 ? s.group_size : 1);
      if (members == 1 || items * item_ns < kSerialBelowNs) {
        if (member == 0) s.fn(s.params, s.bindings, 0, items);
        continue;
      }
      const auto [begin, end] = shares_.range(items, member);
      if (begin < end) {
        const auto t0 = std::chrono::steady_clock::now();
        s.fn(s.params, s.bindings, begin, end);
        busy_[member].ns += std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
      }
    }
  }

  // A program on the calling thread alone: every step whole, in order.
  static void run_alone(const std::vector<CpuStep>& steps) {
    for (const CpuStep& s : steps) {
      switch (s.kind) {
        case CpuStep::Kind::fill: std::fill_n(s.target, s.words, s.value); break;
        case CpuStep::Kind::copy: std::copy_n(s.source, s.words, s.target); break;
        case CpuStep::Kind::dispatch: {
          std::uint32_t items = s.indirect ? std::min(*s.indirect, s.count) : s.count;
          if (s.group_size > 0)
            items = static_cast<std::uint32_t>((std::uint64_t{items} + s.group_size - 1) / s.group_size);
          if (items > 0) s.fn(s.params, s.bindings, 0, items);
          break;
        }
      }
    }
  }

  Result<HostBuffer*> live_buffer(BufferHandle buffer, const char* what) {
    if (buffer.id >= buffers_.size() || buffers_[buffer.id].bytes == 0)
      return Error(ErrorCode::internal, std::string(what) + ": not a live buffer of this device");
    return &buffers_[buffer.id];
  }

  Result<std::byte*> range(BufferHandle buffer, std::size_t offset, std::size_t bytes, const char* what) {
    auto b = live_buffer(buffer, what);
    if (!b) return b.error();
    if (Status s = check_buffer_range((*b)->label, (*b)->bytes, offset, bytes, what); !s) return s.error();
    return (*b)->data.get() + offset;
  }

  bool simd_;
  bool adaptive_;  // DeviceOptions::cpu_adaptive_team
  // The engine's allocation hooks when the device was made (sinew/hooks.h);
  // each buffer holds them too, to be freed through them.
  std::shared_ptr<const AllocationHooks> allocation_hooks_ = hooks::allocation();
  CpuTeam team_;   // runs every program worth sharing
  Shares shares_;  // each member's part of a shared dispatch
  struct alignas(64) Busy {
    double ns = 0.0;  // a member's time in its shares during the run [ns]
  };
  std::vector<Busy> busy_;
  std::vector<HostBuffer> buffers_;
  std::vector<std::size_t> sizes_;  // bytes per buffer id, 0 when destroyed (check_program)
  std::uint64_t generation_ = 0;     // bumped by every resize and destroy
  std::vector<CpuProgram> programs_;
  std::vector<std::uint32_t> counters_;
  std::vector<std::uint32_t> end_reads_;  // of the last program run
  std::uint32_t submitted_ = UINT32_MAX;
};

}  // namespace

Result<std::unique_ptr<Device>> make_cpu_device(const DeviceOptions& options) {
  if (options.threads < 0)
    return Error(ErrorCode::bad_parameter, "DeviceOptions.threads must be >= 0 (0 = all hardware threads), got " +
                                               std::to_string(options.threads));
  if (options.threads > int(Shares::kMaxMembers))
    return Error(ErrorCode::bad_parameter, "DeviceOptions.threads must be <= " + std::to_string(Shares::kMaxMembers) +
                                               ", got " + std::to_string(options.threads));
  const int threads =
      options.threads > 0 ? options.threads : std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, int(Shares::kMaxMembers));
  const bool simd = options.cpu_simd && kernels::cpu_has_avx2();
  return std::unique_ptr<Device>(std::make_unique<CpuDevice>(threads, simd, options.cpu_adaptive_team));
}

}  // namespace sinew
