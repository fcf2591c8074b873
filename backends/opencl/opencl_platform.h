// opencl_platform.h — private to the OpenCL backend: finding OpenCL devices,
// opening a context and an in-order queue on one, building the embedded
// kernel program (with its on-disk binary cache), and OpenCL status codes
// turned into sinew errors. The device itself: opencl_device.cpp.
#pragma once

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include <string>
#include <vector>

#include "backends/opencl/opencl_device.h"

namespace sinew::opencl {

// Generated from kernels/gpu/NAME.gpu (compiled to OpenCL C and SPIR-V; this is
// the OpenCL C) by cmake/EmbedKernelSources.cmake.
extern const char* const kProgramSource;

/// "OpenCL error -5 (CL_OUT_OF_RESOURCES)".
std::string cl_status(cl_int code);

/// An error for a failed OpenCL call: out_of_memory when `code` says memory
/// ran out (CL_MEM_OBJECT_ALLOCATION_FAILURE, CL_OUT_OF_RESOURCES,
/// CL_OUT_OF_HOST_MEMORY), else `otherwise`. The message is "what: status".
Error cl_error(cl_int code, const std::string& what, ErrorCode otherwise = ErrorCode::internal);

/// An OpenCL device of some platform.
struct Found {
  cl_platform_id platform = nullptr;
  cl_device_id device = nullptr;
  OpenclDeviceInfo info;
};

/// Every device of every platform; backend_unavailable when there are none.
Result<std::vector<Found>> find_devices();

/// The device options.device selects, with a fresh context and in-order queue.
struct Opened {
  Found found;
  cl_context ctx = nullptr;
  cl_command_queue queue = nullptr;
};
Result<Opened> open_selected(const DeviceOptions& options);
/// Releases what open_selected made.
void close(const Opened& opened);

/// Builds `source` for the device; a failed build is an internal error
/// carrying the compiler's log.
Result<cl_program> build_from_source(cl_context ctx, const Found& f, const std::string& source);
/// Loads the cached binary of `source` for this device and driver, or builds
/// it from source and caches the binary ($XDG_CACHE_HOME/sinew, else
/// ~/.cache/sinew). An unreadable or unwritable cache only costs the build time.
Result<cl_program> build_cached(cl_context ctx, const Found& f, const std::string& source);

}  // namespace sinew::opencl
