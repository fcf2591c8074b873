// opencl_device.h — the OpenCL backend: any OpenCL 1.2+ device (PoCL on a
// CPU, NVIDIA, AMD, Intel GPUs). Kernels (kernels/gpu/NAME.gpu, compiled to
// OpenCL C and SPIR-V; here the OpenCL C) are embedded at build time, built
// at run time for the chosen device and cached on disk.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "backends/backend.h"

namespace sinew {

/// One OpenCL device found on this machine.
struct OpenclDeviceInfo {
  std::string platform;
  std::string name;
  std::string driver_version;
  bool gpu = false;
};

/// Every OpenCL device of every platform, in (platform, device) order; an
/// error when there is no OpenCL platform at all.
Result<std::vector<OpenclDeviceInfo>> list_opencl_devices();

/// [in] options.device: an index into list_opencl_devices() or a substring
/// of the device name; empty: $SINEW_OPENCL_DEVICE, else the first GPU, else
/// the first device. Errors: no platform, no matching device, a kernel build
/// failure (with the build log).
Result<std::unique_ptr<Device>> make_opencl_device(const DeviceOptions& options);

/// Builds `source` for the selected device without caching (for tests and
/// tools). Errors carry the compiler's build log.
Status try_build_opencl_source(const std::string& source, const DeviceOptions& options);

}  // namespace sinew
