// opencl_device.cpp — the OpenCL backend.
//
// One context and one in-order queue per device: dispatches run in the
// order they are enqueued and each sees the writes of the ones before, so a
// frame program is enqueued whole with no host wait between colours or
// stages, and the host waits once (clFinish) at the end of the frame.
// The embedded kernel program (all of kernels/opencl, headers inlined) is
// built once per device; the binary is cached under $XDG_CACHE_HOME/sinew
// (else ~/.cache/sinew) keyed by a hash of platform, device, driver version,
// build options and source. An unreadable or unwritable cache only costs the
// build time.
#define CL_TARGET_OPENCL_VERSION 120
#include "backends/opencl/opencl_device.h"

#include <CL/cl.h>

#include <array>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "backends/kernel_table.h"

namespace sinew {
namespace opencl {
extern const char* const kProgramSource;  // generated from kernels/opencl (EmbedKernelSources.cmake)
}

namespace {

constexpr const char* kBuildOptions = "-cl-std=CL1.2";
constexpr std::size_t kLocalSize = 64;

std::string cl_status(cl_int code) { return "OpenCL error " + std::to_string(code); }

// A string property through one of OpenCL's two-call getters
// (clGetDeviceInfo, clGetPlatformInfo): ask the size, then the bytes.
template <class Getter, class Object, class Param>
std::string info_string(Getter get, Object object, Param what) {
  std::size_t n = 0;
  if (get(object, what, 0, nullptr, &n) != CL_SUCCESS || n == 0) return "";
  std::string s(n, '\0');
  get(object, what, n, s.data(), nullptr);
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}
std::string device_string(cl_device_id d, cl_device_info what) { return info_string(clGetDeviceInfo, d, what); }
std::string platform_string(cl_platform_id p, cl_platform_info what) { return info_string(clGetPlatformInfo, p, what); }

struct Found {
  cl_platform_id platform;
  cl_device_id device;
  OpenclDeviceInfo info;
};

Result<std::vector<Found>> find_devices() {
  cl_uint platform_count = 0;
  const cl_int err = clGetPlatformIDs(0, nullptr, &platform_count);
  if (err != CL_SUCCESS || platform_count == 0)
    return Error("no OpenCL platform found (install an OpenCL driver, e.g. pocl-opencl-icd for the CPU; " +
                 (err == CL_SUCCESS ? std::string("0 platforms") : cl_status(err)) + ")");
  std::vector<cl_platform_id> platforms(platform_count);
  clGetPlatformIDs(platform_count, platforms.data(), nullptr);
  std::vector<Found> found;
  for (cl_platform_id p : platforms) {
    cl_uint n = 0;
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, nullptr, &n) != CL_SUCCESS || n == 0) continue;
    std::vector<cl_device_id> devices(n);
    clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, n, devices.data(), nullptr);
    for (cl_device_id d : devices) {
      cl_device_type type = 0;
      clGetDeviceInfo(d, CL_DEVICE_TYPE, sizeof type, &type, nullptr);
      found.push_back({p, d,
                       {platform_string(p, CL_PLATFORM_NAME), device_string(d, CL_DEVICE_NAME),
                        device_string(d, CL_DRIVER_VERSION), (type & CL_DEVICE_TYPE_GPU) != 0}});
    }
  }
  if (found.empty()) return Error("OpenCL platforms found, but no OpenCL device");
  return found;
}

// The device named by `selector` (an index, or a substring of the name);
// empty: the first GPU, else the first device.
Result<std::size_t> choose(const std::vector<Found>& found, std::string selector) {
  if (selector.empty())
    if (const char* env = std::getenv("SINEW_OPENCL_DEVICE")) selector = env;
  if (selector.empty()) {
    for (std::size_t i = 0; i < found.size(); ++i)
      if (found[i].info.gpu) return i;
    return std::size_t{0};
  }
  std::vector<std::string> names;
  for (const Found& f : found) names.push_back(f.info.name);
  return match_device_selector(names, names, selector, "OpenCL");
}

std::uint64_t fnv1a(std::uint64_t h, const std::string& s) {
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::filesystem::path cache_file(const Found& f, const std::string& source) {
  std::uint64_t h = 14695981039346656037ull;
  for (const std::string& part : {f.info.platform, f.info.name, f.info.driver_version, std::string(kBuildOptions), source})
    h = fnv1a(h, part + '\n');
  std::filesystem::path dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) dir = xdg;
  else if (const char* home = std::getenv("HOME"); home && *home) dir = std::filesystem::path(home) / ".cache";
  else return {};
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.bin", static_cast<unsigned long long>(h));
  return dir / "sinew" / "opencl" / name;
}

std::string build_log(cl_program program, cl_device_id device) {
  std::size_t n = 0;
  clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &n);
  std::string log(n, '\0');
  if (n) clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, n, log.data(), nullptr);
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

Result<cl_program> build_from_source(cl_context ctx, const Found& f, const std::string& source) {
  const char* text = source.c_str();
  cl_int err = CL_SUCCESS;
  cl_program program = clCreateProgramWithSource(ctx, 1, &text, nullptr, &err);
  if (err != CL_SUCCESS) return Error("clCreateProgramWithSource: " + cl_status(err));
  err = clBuildProgram(program, 1, &f.device, kBuildOptions, nullptr, nullptr);
  if (err != CL_SUCCESS) {
    const std::string log = build_log(program, f.device);
    clReleaseProgram(program);
    return Error("OpenCL kernel build failed on " + f.info.name + " (" + cl_status(err) + "):\n" + log);
  }
  return program;
}

// Loads the cached binary, or builds from source and caches the binary.
Result<cl_program> build_cached(cl_context ctx, const Found& f, const std::string& source) {
  const std::filesystem::path file = cache_file(f, source);
  if (!file.empty()) {
    std::ifstream in(file, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!bytes.empty()) {
      const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
      const std::size_t size = bytes.size();
      cl_int status = CL_SUCCESS, err = CL_SUCCESS;
      cl_program program = clCreateProgramWithBinary(ctx, 1, &f.device, &size, &data, &status, &err);
      if (err == CL_SUCCESS && status == CL_SUCCESS &&
          clBuildProgram(program, 1, &f.device, kBuildOptions, nullptr, nullptr) == CL_SUCCESS)
        return program;
      if (program) clReleaseProgram(program);  // stale or foreign binary: rebuild below
    }
  }
  auto program = build_from_source(ctx, f, source);
  if (!program || file.empty()) return program;
  std::size_t size = 0;
  if (clGetProgramInfo(*program, CL_PROGRAM_BINARY_SIZES, sizeof size, &size, nullptr) == CL_SUCCESS && size > 0) {
    std::vector<unsigned char> binary(size);
    unsigned char* ptr = binary.data();
    if (clGetProgramInfo(*program, CL_PROGRAM_BINARIES, sizeof ptr, &ptr, nullptr) == CL_SUCCESS) {
      std::error_code ec;
      std::filesystem::create_directories(file.parent_path(), ec);
      const auto tmp = file.string() + ".tmp" + std::to_string(reinterpret_cast<std::uintptr_t>(&binary));
      if (std::ofstream out(tmp, std::ios::binary); out.write(reinterpret_cast<const char*>(ptr), std::streamsize(size)))
        std::filesystem::rename(tmp, file, ec);  // atomic: concurrent builds never see half a file
      std::filesystem::remove(tmp, ec);
    }
  }
  return program;
}

struct ClBuffer {
  cl_mem mem = nullptr;
  std::size_t bytes = 0;
  std::string label;
};

struct ClDispatch {
  cl_kernel kernel;
  std::size_t global;
  std::uint32_t binding_count;
  cl_mem bindings[Dispatch::max_bindings];
  std::uint32_t params_bytes;
  alignas(16) std::byte params[Dispatch::max_params_bytes];
};

class OpenclDevice final : public Device {
 public:
  OpenclDevice(Found found, cl_context ctx, cl_command_queue queue, cl_program program)
      : found_(std::move(found)), ctx_(ctx), queue_(queue), program_(program) {
    for (std::size_t k = 0; k < kernels_.size(); ++k) {
      cl_int err = CL_SUCCESS;
      const std::string name(kernel_name(static_cast<Kernel>(k)));
      cl_kernel kernel = clCreateKernel(program_, name.c_str(), &err);
      kernels_[k] = err == CL_SUCCESS ? kernel : nullptr;  // a missing one is an error of create_program
    }
  }
  ~OpenclDevice() override {
    clFinish(queue_);
    for (cl_kernel k : kernels_)
      if (k) clReleaseKernel(k);
    for (ClBuffer& b : buffers_) clReleaseMemObject(b.mem);
    clReleaseProgram(program_);
    clReleaseCommandQueue(queue_);
    clReleaseContext(ctx_);
  }
  OpenclDevice(const OpenclDevice&) = delete;
  OpenclDevice& operator=(const OpenclDevice&) = delete;

  std::string backend_name() const override { return "opencl"; }
  std::string device_name() const override {
    return "OpenCL: " + found_.info.name + " (" + found_.info.platform + ", driver " + found_.info.driver_version + ")";
  }

  Result<BufferHandle> create_buffer(std::size_t bytes, std::string_view label) override {
    if (bytes == 0) return Error("create_buffer '" + std::string(label) + "': size must be > 0");
    const std::size_t rounded = (bytes + 63) / 64 * 64;
    cl_int err = CL_SUCCESS;
    cl_mem mem = clCreateBuffer(ctx_, CL_MEM_READ_WRITE, rounded, nullptr, &err);
    if (err != CL_SUCCESS)
      return Error("create_buffer '" + std::string(label) + "' (" + std::to_string(bytes) + " bytes): " + cl_status(err));
    const cl_uchar zero = 0;
    err = clEnqueueFillBuffer(queue_, mem, &zero, 1, 0, rounded, 0, nullptr, nullptr);
    if (err != CL_SUCCESS) {
      clReleaseMemObject(mem);
      return Error("create_buffer '" + std::string(label) + "': zero fill: " + cl_status(err));
    }
    buffers_.push_back({mem, bytes, std::string(label)});
    return BufferHandle{static_cast<std::uint32_t>(buffers_.size() - 1)};
  }

  Status write_buffer(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) override {
    if (Status s = check_range(buffer, offset, bytes, "write_buffer"); !s) return s;
    if (bytes == 0) return {};
    const cl_int err = clEnqueueWriteBuffer(queue_, buffers_[buffer.id].mem, CL_TRUE, offset, bytes, data, 0, nullptr, nullptr);
    if (err != CL_SUCCESS) return Error("write_buffer '" + buffers_[buffer.id].label + "': " + cl_status(err));
    return {};
  }

  Status read_buffer(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) override {
    if (Status s = check_range(buffer, offset, bytes, "read_buffer"); !s) return s;
    if (bytes == 0) return {};
    const cl_int err = clEnqueueReadBuffer(queue_, buffers_[buffer.id].mem, CL_TRUE, offset, bytes, data, 0, nullptr, nullptr);
    if (err != CL_SUCCESS) return Error("read_buffer '" + buffers_[buffer.id].label + "': " + cl_status(err));
    return {};
  }

  Result<ProgramHandle> create_program(const FrameProgram& program) override {
    if (Status s = check_program(program, static_cast<std::uint32_t>(buffers_.size())); !s) return s.error();
    std::vector<ClDispatch> steps;
    for (const auto& command : program.commands()) {
      const auto* d = std::get_if<Dispatch>(&command);
      if (!d || d->count == 0) continue;  // barriers: the in-order queue already orders every dispatch
      cl_kernel kernel = kernels_[static_cast<std::size_t>(d->kernel)];
      // Only when kernels/opencl is out of step with the kernel table (a test
      // dispatches every kernel): an error, not a skipped test.
      if (!kernel)
        return Error("internal: the embedded OpenCL program has no kernel " + std::string(kernel_name(d->kernel)));
      ClDispatch c{};
      c.kernel = kernel;
      c.global = (d->count + kLocalSize - 1) / kLocalSize * kLocalSize;
      c.binding_count = d->binding_count;
      for (std::uint32_t b = 0; b < d->binding_count; ++b) c.bindings[b] = buffers_[d->bindings[b].id].mem;
      c.params_bytes = d->params_bytes;
      std::memcpy(c.params, d->params, d->params_bytes);
      steps.push_back(c);
    }
    programs_.push_back(std::move(steps));
    return ProgramHandle{static_cast<std::uint32_t>(programs_.size() - 1)};
  }

  Status run_program(ProgramHandle program) override {
    if (program.id >= programs_.size()) return Error("run_program: not a program of this device");
    const std::size_t local = kLocalSize;
    for (const ClDispatch& d : programs_[program.id]) {
      cl_int err = CL_SUCCESS;
      for (std::uint32_t b = 0; b < d.binding_count && err == CL_SUCCESS; ++b)
        err = clSetKernelArg(d.kernel, b, sizeof(cl_mem), &d.bindings[b]);
      if (err == CL_SUCCESS) err = clSetKernelArg(d.kernel, d.binding_count, d.params_bytes, d.params);
      if (err == CL_SUCCESS) err = clEnqueueNDRangeKernel(queue_, d.kernel, 1, nullptr, &d.global, &local, 0, nullptr, nullptr);
      if (err != CL_SUCCESS) return Error("run_program: enqueue failed: " + cl_status(err));
    }
    const cl_int err = clFinish(queue_);
    if (err != CL_SUCCESS) return Error("run_program: " + cl_status(err));
    return {};
  }

 private:
  Status check_range(BufferHandle buffer, std::size_t offset, std::size_t bytes, const char* what) const {
    if (buffer.id >= buffers_.size()) return Error(std::string(what) + ": not a buffer of this device");
    const ClBuffer& b = buffers_[buffer.id];
    return check_buffer_range(b.label, b.bytes, offset, bytes, what);
  }

  Found found_;
  cl_context ctx_;
  cl_command_queue queue_;
  cl_program program_;
  std::array<cl_kernel, static_cast<std::size_t>(Kernel::count_)> kernels_{};
  std::vector<ClBuffer> buffers_;
  std::vector<std::vector<ClDispatch>> programs_;
};

struct ContextAndQueue {
  cl_context ctx = nullptr;
  cl_command_queue queue = nullptr;
};

Result<ContextAndQueue> make_context(const Found& f) {
  cl_int err = CL_SUCCESS;
  const cl_context_properties props[] = {CL_CONTEXT_PLATFORM, reinterpret_cast<cl_context_properties>(f.platform), 0};
  cl_context ctx = clCreateContext(props, 1, &f.device, nullptr, nullptr, &err);
  if (err != CL_SUCCESS) return Error("clCreateContext on " + f.info.name + ": " + cl_status(err));
  cl_command_queue queue = clCreateCommandQueue(ctx, f.device, 0, &err);
  if (err != CL_SUCCESS) {
    clReleaseContext(ctx);
    return Error("clCreateCommandQueue on " + f.info.name + ": " + cl_status(err));
  }
  return ContextAndQueue{ctx, queue};
}

// The selected device with a fresh context and queue.
struct Opened {
  Found found;
  ContextAndQueue cq;
};

Result<Opened> open_selected(const DeviceOptions& options) {
  auto found = find_devices();
  if (!found) return found.error();
  auto index = choose(*found, options.device);
  if (!index) return index.error();
  const Found& f = (*found)[*index];
  auto cq = make_context(f);
  if (!cq) return cq.error();
  return Opened{f, *cq};
}

}  // namespace

Result<std::vector<OpenclDeviceInfo>> list_opencl_devices() {
  auto found = find_devices();
  if (!found) return found.error();
  std::vector<OpenclDeviceInfo> out;
  for (const Found& f : *found) out.push_back(f.info);
  return out;
}

Result<std::unique_ptr<Device>> make_opencl_device(const DeviceOptions& options) {
  auto opened = open_selected(options);
  if (!opened) return opened.error();
  auto& [f, cq] = *opened;
  auto program = build_cached(cq.ctx, f, opencl::kProgramSource);
  if (!program) {
    clReleaseCommandQueue(cq.queue);
    clReleaseContext(cq.ctx);
    return program.error();
  }
  return std::unique_ptr<Device>(std::make_unique<OpenclDevice>(f, cq.ctx, cq.queue, *program));
}

Status try_build_opencl_source(const std::string& source, const DeviceOptions& options) {
  auto opened = open_selected(options);
  if (!opened) return opened.error();
  auto& [f, cq] = *opened;
  auto program = build_from_source(cq.ctx, f, source);
  if (program) clReleaseProgram(*program);
  clReleaseCommandQueue(cq.queue);
  clReleaseContext(cq.ctx);
  return program.status();
}

}  // namespace sinew
