// opencl_device.cpp — the OpenCL backend's device: buffers, frame programs,
// submit and wait. (Platforms, contexts and the kernel build with its
// binary cache: opencl_platform.cpp.)
//
// One context and one in-order queue per device: every command runs after
// the ones enqueued before it and sees their writes, so a frame program is
// enqueued whole, barriers cost nothing (the queue already orders
// everything) and the host does not wait between colours or stages.
//
// submit() enqueues the program's commands, then a non-blocking read of each
// declared counter word into host memory the program owns, flushes and
// returns. wait() is one clFinish: the counters arrived with the frame (no
// extra round trip) and are checked against their capacities. Calls that
// touch buffers, and the next submit, first finish a submission in flight.
//
// Work groups: independent kernels run in groups of kIndependentGroupSize
// (64), cooperative kernels in their registry group size G (their sources
// say reqd_work_group_size(G)). A dispatch of `count` items launches
// ceil(count / G) * G work items; kernels return for items past their count.
//
// Indirect dispatches: OpenCL 1.2 has no indirect dispatch (no launch whose
// size is read from a buffer), and reading the counter on the host in the
// middle of the frame would cost a round trip per dispatch and make submit
// wait. So an indirect dispatch is launched for its capacity rounded up to
// the group size, relying on the contract of FrameProgram::dispatch_indirect:
// the kernel reads the count itself and returns for items past it. The
// results are those of an exact launch; the cost is the groups between the
// count and the capacity, which start and return at once.
//
// A program keeps its FrameProgram. Resizing or destroying a buffer bumps
// a generation counter, and a program prepared at an older generation is
// checked and resolved again (new cl_mem handles, new sizes) at its next
// submit, as on the CPU backend.
#include "backends/opencl/opencl_device.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "backends/kernel_table.h"
#include "backends/opencl/opencl_platform.h"

namespace sinew {
namespace {

using opencl::cl_error;

struct ClBuffer {
  cl_mem mem = nullptr;  // nullptr: destroyed (ids are never reused)
  std::size_t bytes = 0;
  std::string label;
};

// Device memory is allocated in whole 64-byte blocks, so kernels may read a
// float4 at the end of any buffer.
std::size_t allocation_bytes(std::size_t bytes) { return (bytes + 63) / 64 * 64; }

// A command resolved to OpenCL objects, ready to enqueue.
struct ClStep {
  enum class Kind { dispatch, fill, copy } kind = Kind::dispatch;
  std::uint32_t command = 0;  // its position in the program (1-based), for errors
  Kernel kernel_id = Kernel::count_;
  cl_kernel kernel = nullptr;
  std::size_t global = 0, local = 0;
  std::uint32_t binding_count = 0;
  cl_mem bindings[Dispatch::max_bindings] = {};
  std::uint32_t params_bytes = 0;
  alignas(16) std::byte params[Dispatch::max_params_bytes] = {};
  cl_mem source = nullptr, target = nullptr;  // copy: both; fill: target
  std::size_t source_offset = 0, target_offset = 0, bytes = 0;
  cl_uint value = 0;  // fill pattern
};

struct CounterRead {
  cl_mem mem = nullptr;
  std::size_t offset = 0;
};

// Held through a unique_ptr: the non-blocking counter and end reads of a
// submission write into counter_values and end_values, which must not move
// while it is in flight.
struct ClProgram {
  FrameProgram source;            // kept to resolve again after a buffer is resized or destroyed
  std::uint64_t resolved_at = 0;  // the device's generation the steps are from
  std::vector<ClStep> steps;
  std::vector<CounterRead> counter_reads;
  std::vector<std::uint32_t> counter_values;  // written by the reads of a submission
  std::vector<CounterRead> end_reads;         // the first word of each end read
  std::vector<std::uint32_t> end_values;      // written by the end reads of a submission
};

std::string step_name(const ClStep& s) {
  const std::string where = "command " + std::to_string(s.command);
  switch (s.kind) {
    case ClStep::Kind::fill: return where + " (fill)";
    case ClStep::Kind::copy: return where + " (copy)";
    case ClStep::Kind::dispatch: break;
  }
  return where + " (" + std::string(kernel_name(s.kernel_id)) + ")";
}

class OpenclDevice final : public Device {
 public:
  OpenclDevice(opencl::Opened opened, cl_program program)
      : found_(std::move(opened.found)), ctx_(opened.ctx), queue_(opened.queue), program_(program) {
    for (std::size_t k = 0; k < kernel_count; ++k) {
      cl_int err = CL_SUCCESS;
      const std::string name(kernel_name(static_cast<Kernel>(k)));
      cl_kernel kernel = clCreateKernel(program_, name.c_str(), &err);
      kernels_[k] = err == CL_SUCCESS ? kernel : nullptr;  // a missing one is an error of create_program
      if (kernels_[k])
        clGetKernelWorkGroupInfo(kernel, found_.device, CL_KERNEL_WORK_GROUP_SIZE, sizeof(std::size_t),
                                 &max_group_[k], nullptr);
    }
  }
  ~OpenclDevice() override {
    clFinish(queue_);
    for (cl_kernel k : kernels_)
      if (k) clReleaseKernel(k);
    for (ClBuffer& b : buffers_)
      if (b.mem) clReleaseMemObject(b.mem);
    clReleaseProgram(program_);
    opencl::close({found_, ctx_, queue_});
  }
  OpenclDevice(const OpenclDevice&) = delete;
  OpenclDevice& operator=(const OpenclDevice&) = delete;

  std::string backend_name() const override { return "opencl"; }
  std::string device_name() const override {
    return "OpenCL: " + found_.info.name + " (" + found_.info.platform + ", driver " + found_.info.driver_version + ")";
  }

  // ---------------------------------------------------------------- buffers

  Result<BufferHandle> create_buffer(std::size_t bytes, std::string_view label) override {
    const std::string name(label);
    if (bytes == 0) return Error(ErrorCode::internal, "create_buffer '" + name + "': size must be > 0");
    auto mem = allocate(bytes, "create_buffer '" + name + "'");
    if (!mem) return mem.error();
    buffers_.push_back({*mem, bytes, name});
    sizes_.push_back(bytes);
    return BufferHandle{static_cast<std::uint32_t>(buffers_.size() - 1)};
  }

  Status destroy_buffer(BufferHandle buffer) override {
    if (Status s = drain(); !s) return s;
    auto b = live_buffer(buffer, "destroy_buffer");
    if (!b) return b.status();
    clReleaseMemObject((*b)->mem);
    **b = ClBuffer{};
    sizes_[buffer.id] = 0;
    ++generation_;  // programs binding it fail at their next resolve
    return {};
  }

  Status resize_buffer(BufferHandle buffer, std::size_t bytes) override {
    if (Status s = drain(); !s) return s;
    auto b = live_buffer(buffer, "resize_buffer");
    if (!b) return b.status();
    ClBuffer& old = **b;
    const std::string what = "resize_buffer '" + old.label + "'";
    if (bytes == 0) return Error(ErrorCode::internal, what + ": size must be > 0");
    auto mem = allocate(bytes, what, std::min(bytes, old.bytes));
    if (!mem) return mem.error();
    if (const cl_int err = clEnqueueCopyBuffer(queue_, old.mem, *mem, 0, 0, std::min(bytes, old.bytes), 0, nullptr, nullptr);
        err != CL_SUCCESS) {
      clReleaseMemObject(*mem);
      return cl_error(err, what + ": copying the contents");
    }
    clReleaseMemObject(old.mem);  // freed once the copy is done
    old.mem = *mem;
    old.bytes = bytes;
    sizes_[buffer.id] = bytes;
    ++generation_;
    return {};
  }

  Status write_buffer_impl(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) override {
    if (Status s = drain(); !s) return s;
    auto b = range(buffer, offset, bytes, "write_buffer");
    if (!b) return b.status();
    if (bytes == 0) return {};
    const cl_int err = clEnqueueWriteBuffer(queue_, (*b)->mem, CL_TRUE, offset, bytes, data, 0, nullptr, nullptr);
    if (err != CL_SUCCESS) return cl_error(err, "write_buffer '" + (*b)->label + "'");
    return {};
  }

  Status read_buffer_impl(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) override {
    if (Status s = drain(); !s) return s;
    auto b = range(buffer, offset, bytes, "read_buffer");
    if (!b) return b.status();
    if (bytes == 0) return {};
    const cl_int err = clEnqueueReadBuffer(queue_, (*b)->mem, CL_TRUE, offset, bytes, data, 0, nullptr, nullptr);
    if (err != CL_SUCCESS) return cl_error(err, "read_buffer '" + (*b)->label + "'");
    return {};
  }

  // ---------------------------------------------------------------- programs

  Result<ProgramHandle> create_program(const FrameProgram& program) override {
    auto p = std::make_unique<ClProgram>();
    p->source = program;
    if (Status s = resolve(*p); !s) return s.error();
    programs_.push_back(std::move(p));
    return ProgramHandle{static_cast<std::uint32_t>(programs_.size() - 1)};
  }

  Status destroy_program(ProgramHandle program) override {
    if (!live_program(program)) return Error(ErrorCode::internal, "destroy_program: not a live program of this device");
    if (Status s = drain(); !s) return s;  // its counter reads may be in flight
    programs_[program.id].reset();
    return {};
  }

  Status submit_impl(ProgramHandle program) override {
    if (!live_program(program)) return Error(ErrorCode::internal, "submit: not a live program of this device");
    if (Status s = drain(); !s) return s;
    pending_ = false;  // one submission at a time: the previous one's counters are not checked
    ClProgram& p = *programs_[program.id];
    if (p.resolved_at != generation_)
      if (Status s = resolve(p); !s) return s;
    for (const ClStep& step : p.steps) {
      if (const cl_int err = enqueue(step); err != CL_SUCCESS) {
        clFinish(queue_);  // what was enqueued before it runs out; no counters to check
        return cl_error(err, "submit: frame program " + step_name(step));
      }
    }
    for (std::size_t c = 0; c < p.counter_reads.size(); ++c) {
      const CounterRead& r = p.counter_reads[c];
      if (const cl_int err = clEnqueueReadBuffer(queue_, r.mem, CL_FALSE, r.offset, sizeof(std::uint32_t),
                                                 &p.counter_values[c], 0, nullptr, nullptr);
          err != CL_SUCCESS) {
        clFinish(queue_);
        return cl_error(err, "submit: reading counter '" + p.source.counters()[c].label + "'");
      }
    }
    std::uint32_t* to = p.end_values.data();
    for (std::size_t e = 0; e < p.end_reads.size(); ++e) {
      const CounterRead& r = p.end_reads[e];
      const std::uint32_t words = p.source.end_reads()[e].words;
      if (const cl_int err = clEnqueueReadBuffer(queue_, r.mem, CL_FALSE, r.offset, std::size_t{words} * 4, to, 0,
                                                 nullptr, nullptr);
          err != CL_SUCCESS) {
        clFinish(queue_);
        return cl_error(err, "submit: end read " + std::to_string(e));
      }
      to += words;
    }
    if (const cl_int err = clFlush(queue_); err != CL_SUCCESS) {
      clFinish(queue_);
      return cl_error(err, "submit: clFlush", ErrorCode::device_lost);
    }
    in_flight_ = program.id;
    return {};
  }

  Status wait_impl() override {
    if (Status s = drain(); !s) return s;
    if (!pending_) return {};
    pending_ = false;
    return pending_status_;
  }

  std::span<const std::uint32_t> counters() const override { return counters_; }
  std::span<const std::uint32_t> end_reads() const override { return end_reads_; }

  DeviceObjects objects() const override {
    DeviceObjects o;
    for (const ClBuffer& b : buffers_)
      if (b.mem) {
        ++o.buffers;
        o.buffer_bytes += b.bytes;
      }
    o.native = o.buffers;  // one cl_mem per buffer; programs hold no OpenCL objects of their own
    for (const auto& p : programs_) o.programs += p ? 1 : 0;
    return o;
  }

 private:
  // A zero-filled cl_mem of allocation_bytes(bytes), whose first `keep`
  // bytes the caller fills (a resize copies the old contents there).
  Result<cl_mem> allocate(std::size_t bytes, const std::string& what, std::size_t keep = 0) {
    const std::size_t rounded = allocation_bytes(bytes);
    cl_int err = CL_SUCCESS;
    cl_mem mem = clCreateBuffer(ctx_, CL_MEM_READ_WRITE, rounded, nullptr, &err);
    if (err != CL_SUCCESS) {
      // Past the device's largest allocation is out of memory too.
      const ErrorCode code = err == CL_INVALID_BUFFER_SIZE ? ErrorCode::out_of_memory : ErrorCode::internal;
      return cl_error(err, what + " (" + std::to_string(bytes) + " bytes)", code);
    }
    if (keep < rounded) {
      const cl_uchar zero = 0;
      err = clEnqueueFillBuffer(queue_, mem, &zero, 1, keep, rounded - keep, 0, nullptr, nullptr);
      if (err != CL_SUCCESS) {
        clReleaseMemObject(mem);
        return cl_error(err, what + ": zero fill");
      }
    }
    return mem;
  }

  // Finishes the submission in flight, if any: its counters are then on the
  // host, copied to counters_ and checked (wait() reports the result).
  Status drain() {
    if (in_flight_ == UINT32_MAX) return {};
    const ClProgram& p = *programs_[in_flight_];
    in_flight_ = UINT32_MAX;
    if (const cl_int err = clFinish(queue_); err != CL_SUCCESS)
      return cl_error(err, "waiting for the frame program", ErrorCode::device_lost);
    counters_.assign(p.counter_values.begin(), p.counter_values.end());
    end_reads_.assign(p.end_values.begin(), p.end_values.end());
    count_end_reads(end_reads_.size());
    pending_status_ = check_counters(p.source.counters(), counters_);
    pending_ = true;
    return {};
  }

  // Checks a program against the device's buffers and resolves its
  // commands to OpenCL objects (at creation, and again after a buffer was
  // resized or destroyed).
  Status resolve(ClProgram& p) {
    if (Status s = check_program(p.source, sizes_); !s) return s;
    std::vector<ClStep> steps;
    std::uint32_t position = 0;
    for (const auto& command : p.source.commands()) {
      ClStep c;
      c.command = ++position;
      if (const auto* f = std::get_if<Fill>(&command)) {
        if (f->words == 0) continue;
        c.kind = ClStep::Kind::fill;
        c.target = buffers_[f->buffer.id].mem;
        c.target_offset = std::size_t{f->word} * 4;
        c.bytes = std::size_t{f->words} * 4;
        c.value = f->value;
      } else if (const auto* k = std::get_if<Copy>(&command)) {
        if (k->words == 0) continue;
        c.kind = ClStep::Kind::copy;
        c.source = buffers_[k->source.id].mem;
        c.source_offset = std::size_t{k->source_word} * 4;
        c.target = buffers_[k->target.id].mem;
        c.target_offset = std::size_t{k->target_word} * 4;
        c.bytes = std::size_t{k->words} * 4;
      } else if (const auto* d = std::get_if<Dispatch>(&command)) {
        if (d->count == 0) continue;
        const auto k_index = static_cast<std::size_t>(d->kernel);
        c.kernel_id = d->kernel;
        c.kernel = kernels_[k_index];
        // Only when the embedded program is out of step with the kernel
        // registry (a test dispatches every kernel): an error, not a skip.
        if (!c.kernel)
          return Error(ErrorCode::internal, "frame program " + step_name(c) + ": the embedded OpenCL program has no kernel " +
                                                std::string(kernel_name(d->kernel)));
        // Indirect: d->count is the capacity, see the top of this file.
        const std::size_t group = launch_group_size(d->kernel);
        if (group > max_group_[k_index])
          return Error(ErrorCode::backend_unavailable,
                       "frame program " + step_name(c) + ": the kernel runs in groups of " + std::to_string(group) +
                           ", " + found_.info.name + " allows at most " + std::to_string(max_group_[k_index]));
        c.local = group;
        c.global = (std::size_t{d->count} + group - 1) / group * group;
        c.binding_count = d->binding_count;
        for (std::uint32_t b = 0; b < d->binding_count; ++b) c.bindings[b] = buffers_[d->bindings[b].id].mem;
        c.params_bytes = d->params_bytes;
        std::memcpy(c.params, d->params, d->params_bytes);
      } else {
        continue;  // a barrier: the in-order queue already orders every command
      }
      steps.push_back(c);
    }
    p.steps = std::move(steps);
    p.counter_reads.clear();
    for (const Counter& c : p.source.counters())
      p.counter_reads.push_back({buffers_[c.buffer.id].mem, std::size_t{c.word} * 4});
    p.counter_values.assign(p.counter_reads.size(), 0);
    p.end_reads.clear();
    for (const EndRead& r : p.source.end_reads())
      p.end_reads.push_back({buffers_[r.buffer.id].mem, std::size_t{r.word} * 4});
    p.end_values.assign(p.source.end_read_words(), 0);
    p.resolved_at = generation_;
    return {};
  }

  cl_int enqueue(const ClStep& s) {
    switch (s.kind) {
      case ClStep::Kind::fill:
        return clEnqueueFillBuffer(queue_, s.target, &s.value, sizeof s.value, s.target_offset, s.bytes, 0, nullptr,
                                   nullptr);
      case ClStep::Kind::copy:
        return clEnqueueCopyBuffer(queue_, s.source, s.target, s.source_offset, s.target_offset, s.bytes, 0, nullptr,
                                   nullptr);
      case ClStep::Kind::dispatch: break;
    }
    // Arguments are captured at enqueue, so the shared cl_kernel of each
    // kernel serves every dispatch of it.
    cl_int err = CL_SUCCESS;
    for (std::uint32_t b = 0; b < s.binding_count && err == CL_SUCCESS; ++b)
      err = clSetKernelArg(s.kernel, b, sizeof(cl_mem), &s.bindings[b]);
    if (err == CL_SUCCESS) err = clSetKernelArg(s.kernel, s.binding_count, s.params_bytes, s.params);
    if (err == CL_SUCCESS) err = clEnqueueNDRangeKernel(queue_, s.kernel, 1, nullptr, &s.global, &s.local, 0, nullptr, nullptr);
    return err;
  }

  bool live_program(ProgramHandle program) const { return program.id < programs_.size() && programs_[program.id]; }

  Result<ClBuffer*> live_buffer(BufferHandle buffer, const char* what) {
    if (buffer.id >= buffers_.size() || !buffers_[buffer.id].mem)
      return Error(ErrorCode::internal, std::string(what) + ": not a live buffer of this device");
    return &buffers_[buffer.id];
  }

  Result<ClBuffer*> range(BufferHandle buffer, std::size_t offset, std::size_t bytes, const char* what) {
    auto b = live_buffer(buffer, what);
    if (!b) return b.error();
    if (Status s = check_buffer_range((*b)->label, (*b)->bytes, offset, bytes, what); !s) return s.error();
    return b;
  }

  opencl::Found found_;
  cl_context ctx_;
  cl_command_queue queue_;
  cl_program program_;
  std::array<cl_kernel, kernel_count> kernels_{};
  std::array<std::size_t, kernel_count> max_group_{};  // CL_KERNEL_WORK_GROUP_SIZE of each kernel
  std::vector<ClBuffer> buffers_;
  std::vector<std::size_t> sizes_;  // bytes per buffer id, 0 when destroyed (check_program)
  std::uint64_t generation_ = 0;     // bumped by every resize and destroy
  std::vector<std::unique_ptr<ClProgram>> programs_;  // nullptr: destroyed
  std::uint32_t in_flight_ = UINT32_MAX;  // the program submitted and not yet finished
  bool pending_ = false;                  // a finished submission whose counter check wait() has not returned
  Status pending_status_;
  std::vector<std::uint32_t> counters_;
  std::vector<std::uint32_t> end_reads_;  // of the last program finished
};

}  // namespace

Result<std::unique_ptr<Device>> make_opencl_device(const DeviceOptions& options) {
  auto opened = opencl::open_selected(options);
  if (!opened) return opened.error();
  auto program = opencl::build_cached(opened->ctx, opened->found, opencl::kProgramSource);
  if (!program) {
    opencl::close(*opened);
    return program.error();
  }
  return std::unique_ptr<Device>(std::make_unique<OpenclDevice>(std::move(*opened), *program));
}

}  // namespace sinew
