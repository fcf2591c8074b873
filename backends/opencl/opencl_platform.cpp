// opencl_platform.cpp — OpenCL platforms and devices, contexts and queues,
// and the kernel build.
//
// The embedded kernel program (every kernels/gpu/NAME.gpu, compiled to
// OpenCL C and SPIR-V; here the OpenCL C, headers inlined) is built once
// per device; the binary is cached under $XDG_CACHE_HOME/sinew (else
// ~/.cache/sinew) keyed by a hash of platform, device, driver version,
// build options and source.
#include "backends/opencl/opencl_platform.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "backends/kernel_table.h"

namespace sinew {
namespace opencl {
namespace {

// OpenCL 1.2 lets float division and sqrt be off by up to 2.5 and 3 ulp
// unless -cl-fp32-correctly-rounded-divide-sqrt is given, which a device
// offers through CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT. The kernels follow
// the CPU reference's operation order to agree with it bitwise; without
// the flag an H100 (NVIDIA's OpenCL) drifted by 1e-4 m on the mesh-contact
// scenes, and since contacts are found from the positions, a drift changes
// them and grows (1 cm on the folded membrane). CPU devices (PoCL) round
// correctly either way.
std::string build_options(cl_device_id device) {
  std::string options = "-cl-std=CL1.2";
  cl_device_fp_config fp = 0;
  if (clGetDeviceInfo(device, CL_DEVICE_SINGLE_FP_CONFIG, sizeof fp, &fp, nullptr) == CL_SUCCESS &&
      (fp & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT) != 0)
    options += " -cl-fp32-correctly-rounded-divide-sqrt";
  return options;
}

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

// The device named by `selector` (an index, or a substring of the name);
// empty: $SINEW_OPENCL_DEVICE, else the first GPU, else the first device.
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
  for (const std::string& part : {f.info.platform, f.info.name, f.info.driver_version, build_options(f.device), source})
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

}  // namespace

std::string cl_status(cl_int code) {
  const char* name = nullptr;
  switch (code) {
    case CL_DEVICE_NOT_FOUND: name = "CL_DEVICE_NOT_FOUND"; break;
    case CL_MEM_OBJECT_ALLOCATION_FAILURE: name = "CL_MEM_OBJECT_ALLOCATION_FAILURE"; break;
    case CL_OUT_OF_RESOURCES: name = "CL_OUT_OF_RESOURCES"; break;
    case CL_OUT_OF_HOST_MEMORY: name = "CL_OUT_OF_HOST_MEMORY"; break;
    case CL_BUILD_PROGRAM_FAILURE: name = "CL_BUILD_PROGRAM_FAILURE"; break;
    case CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST: name = "CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST"; break;
    case CL_INVALID_VALUE: name = "CL_INVALID_VALUE"; break;
    case CL_INVALID_MEM_OBJECT: name = "CL_INVALID_MEM_OBJECT"; break;
    case CL_INVALID_KERNEL_NAME: name = "CL_INVALID_KERNEL_NAME"; break;
    case CL_INVALID_KERNEL_ARGS: name = "CL_INVALID_KERNEL_ARGS"; break;
    case CL_INVALID_ARG_SIZE: name = "CL_INVALID_ARG_SIZE"; break;
    case CL_INVALID_WORK_GROUP_SIZE: name = "CL_INVALID_WORK_GROUP_SIZE"; break;
    case CL_INVALID_BUFFER_SIZE: name = "CL_INVALID_BUFFER_SIZE"; break;
    case CL_INVALID_GLOBAL_WORK_SIZE: name = "CL_INVALID_GLOBAL_WORK_SIZE"; break;
    default: break;
  }
  return "OpenCL error " + std::to_string(code) + (name ? std::string(" (") + name + ")" : std::string());
}

Error cl_error(cl_int code, const std::string& what, ErrorCode otherwise) {
  const bool memory =
      code == CL_MEM_OBJECT_ALLOCATION_FAILURE || code == CL_OUT_OF_RESOURCES || code == CL_OUT_OF_HOST_MEMORY;
  return Error(memory ? ErrorCode::out_of_memory : otherwise, what + ": " + cl_status(code));
}

Result<std::vector<Found>> find_devices() {
  cl_uint platform_count = 0;
  const cl_int err = clGetPlatformIDs(0, nullptr, &platform_count);
  if (err != CL_SUCCESS || platform_count == 0)
    return Error(ErrorCode::backend_unavailable,
                 "no OpenCL platform found (install an OpenCL driver, e.g. pocl-opencl-icd for the CPU; " +
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
  if (found.empty()) return Error(ErrorCode::backend_unavailable, "OpenCL platforms found, but no OpenCL device");
  return found;
}

Result<Opened> open_selected(const DeviceOptions& options) {
  auto found = find_devices();
  if (!found) return found.error();
  auto index = choose(*found, options.device);
  if (!index) return index.error();
  Opened o;
  o.found = (*found)[*index];
  const Found& f = o.found;
  cl_int err = CL_SUCCESS;
  const cl_context_properties props[] = {CL_CONTEXT_PLATFORM, reinterpret_cast<cl_context_properties>(f.platform), 0};
  o.ctx = clCreateContext(props, 1, &f.device, nullptr, nullptr, &err);
  if (err != CL_SUCCESS) return cl_error(err, "clCreateContext on " + f.info.name, ErrorCode::backend_unavailable);
  o.queue = clCreateCommandQueue(o.ctx, f.device, 0, &err);  // in order, no profiling
  if (err != CL_SUCCESS) {
    clReleaseContext(o.ctx);
    return cl_error(err, "clCreateCommandQueue on " + f.info.name, ErrorCode::backend_unavailable);
  }
  return o;
}

void close(const Opened& opened) {
  clReleaseCommandQueue(opened.queue);
  clReleaseContext(opened.ctx);
}

Result<cl_program> build_from_source(cl_context ctx, const Found& f, const std::string& source) {
  const char* text = source.c_str();
  cl_int err = CL_SUCCESS;
  cl_program program = clCreateProgramWithSource(ctx, 1, &text, nullptr, &err);
  if (err != CL_SUCCESS) return cl_error(err, "clCreateProgramWithSource");
  err = clBuildProgram(program, 1, &f.device, build_options(f.device).c_str(), nullptr, nullptr);
  if (err != CL_SUCCESS) {
    const std::string log = build_log(program, f.device);
    clReleaseProgram(program);
    return Error(ErrorCode::internal, "OpenCL kernel build failed on " + f.info.name + " (" + cl_status(err) + "):\n" + log);
  }
  return program;
}

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
          clBuildProgram(program, 1, &f.device, build_options(f.device).c_str(), nullptr, nullptr) == CL_SUCCESS)
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

}  // namespace opencl

Result<std::vector<OpenclDeviceInfo>> list_opencl_devices() {
  auto found = opencl::find_devices();
  if (!found) return found.error();
  std::vector<OpenclDeviceInfo> out;
  for (const opencl::Found& f : *found) out.push_back(f.info);
  return out;
}

Status try_build_opencl_source(const std::string& source, const DeviceOptions& options) {
  auto opened = opencl::open_selected(options);
  if (!opened) return opened.error();
  auto program = opencl::build_from_source(opened->ctx, opened->found, source);
  if (program) clReleaseProgram(*program);
  opencl::close(*opened);
  return program.status();
}

}  // namespace sinew
