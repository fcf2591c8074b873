// device.cpp — backend-independent parts of the device interface: the kernel
// table, program checks and the choice of backend by name.
#include <cstdio>
#include <string>

#include <charconv>
#include <mutex>

#include "backends/cpu/cpu_device.h"
#if SINEW_HAS_OPENCL
#include "backends/opencl/opencl_device.h"
#endif
#if SINEW_HAS_VULKAN
#include "backends/vulkan/vulkan_device.h"
#endif
#include "backends/kernel_table.h"
#include "xpbd_params.h"

namespace sinew {
namespace {

using namespace kernels;

constexpr KernelSignature kSignatures[] = {
    {"xpbd_predict", 3, sizeof(PredictParams)},
    {"xpbd_update_velocity", 3, sizeof(UpdateVelocityParams)},
    {"xpbd_solve_distance", 5, sizeof(SolveParams)},
    {"xpbd_solve_volume", 5, sizeof(SolveParams)},
    {"xpbd_solve_neo_hookean", 5, sizeof(SolveParams)},
    {"xpbd_solve_stvk", 5, sizeof(SolveParams)},
    {"xpbd_solve_corotational", 5, sizeof(SolveParams)},
    {"xpbd_solve_area", 5, sizeof(SolveParams)},
    {"xpbd_solve_dihedral", 5, sizeof(SolveParams)},
    {"xpbd_solve_line_bending", 5, sizeof(SolveParams)},
    {"xpbd_solve_attachment", 6, sizeof(SolveParams)},  // + targets
    {"xpbd_solve_contacts", 8, sizeof(SolveParams)},    // + previous position, colliders, contact impulses
};
static_assert(std::size(kSignatures) == static_cast<std::size_t>(Kernel::count_),
              "every Kernel needs a signature");

}  // namespace

const KernelSignature& kernel_signature(Kernel kernel) { return kSignatures[static_cast<std::size_t>(kernel)]; }

std::string_view kernel_name(Kernel kernel) {
  if (kernel >= Kernel::count_) return "unknown";
  return kernel_signature(kernel).name;
}

std::size_t FrameProgram::dispatch_count() const {
  std::size_t n = 0;
  for (const auto& c : commands_) n += std::holds_alternative<Dispatch>(c) ? 1 : 0;
  return n;
}

std::size_t FrameProgram::barrier_count() const { return commands_.size() - dispatch_count(); }

std::size_t FrameProgram::dispatch_count(Kernel kernel) const {
  std::size_t n = 0;
  for (const auto& c : commands_)
    if (const auto* d = std::get_if<Dispatch>(&c); d && d->kernel == kernel) ++n;
  return n;
}

Status check_program(const FrameProgram& program, std::uint32_t buffer_count) {
  std::size_t position = 0;
  for (const auto& command : program.commands()) {
    ++position;
    const auto* d = std::get_if<Dispatch>(&command);
    if (!d) continue;
    const std::string where = "frame program command " + std::to_string(position);
    if (d->kernel >= Kernel::count_)
      return Error(where + ": unknown kernel id " + std::to_string(static_cast<std::uint32_t>(d->kernel)));
    const KernelSignature& sig = kernel_signature(d->kernel);
    const std::string who = where + " (" + std::string(sig.name) + ")";
    if (d->binding_count != sig.bindings)
      return Error(who + ": binds " + std::to_string(d->binding_count) + " buffers, the kernel takes " +
                   std::to_string(sig.bindings));
    if (d->params_bytes != sig.params_bytes)
      return Error(who + ": parameter block of " + std::to_string(d->params_bytes) +
                   " bytes, the kernel takes " + std::to_string(sig.params_bytes));
    for (std::uint32_t b = 0; b < d->binding_count; ++b)
      if (d->bindings[b].id >= buffer_count)
        return Error(who + ": binding " + std::to_string(b) + " is not a buffer of this device");
  }
  return {};
}

Status check_buffer_range(const std::string& label, std::size_t size, std::size_t offset, std::size_t bytes,
                          const char* what) {
  if (offset > size || bytes > size - offset)
    return Error(std::string(what) + " '" + label + "': bytes [" + std::to_string(offset) + ", " +
                 std::to_string(offset + bytes) + ") outside the buffer's " + std::to_string(size) + " bytes");
  return {};
}

Result<std::size_t> match_device_selector(const std::vector<std::string>& names,
                                          const std::vector<std::string>& labels, const std::string& selector,
                                          const char* api) {
  std::size_t index = 0;
  const auto [end, ec] = std::from_chars(selector.data(), selector.data() + selector.size(), index);
  if (ec == std::errc() && end == selector.data() + selector.size() && index < names.size()) return index;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i].find(selector) != std::string::npos) return i;
  std::string list;
  for (std::size_t i = 0; i < labels.size(); ++i) list += "\n  " + std::to_string(i) + ": " + labels[i];
  return Error(std::string("no ") + api + " device matches '" + selector + "'; devices:" + list);
}

std::vector<std::string> built_backends() {
  std::vector<std::string> names{"cpu"};
#if SINEW_HAS_OPENCL
  names.push_back("opencl");
#endif
#if SINEW_HAS_VULKAN
  names.push_back("vulkan");
#endif
  return names;
}

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// "auto": the first GPU of a built GPU backend, else the CPU backend.
Result<std::unique_ptr<Device>> create_auto_device(const DeviceOptions& options) {
  std::string why = "no GPU backend is built";
#if SINEW_HAS_OPENCL
  if (auto devices = list_opencl_devices(); devices) {
    for (std::size_t i = 0; i < devices->size(); ++i) {
      if (!(*devices)[i].gpu) continue;
      DeviceOptions gpu = options;
      gpu.backend = "opencl";
      if (gpu.device.empty()) gpu.device = std::to_string(i);
      return make_opencl_device(gpu);
    }
    why = "OpenCL found no GPU";
  } else {
    why = devices.error().message();
  }
#endif
#if SINEW_HAS_VULKAN
  // A Vulkan GPU (discrete or integrated), never a CPU device such as lavapipe.
  std::string vulkan_why = "Vulkan found no GPU";
  if (auto devices = list_vulkan_devices(); devices) {
    for (std::size_t i = 0; i < devices->size(); ++i) {
      if (!(*devices)[i].gpu) continue;
      DeviceOptions gpu = options;
      gpu.backend = "vulkan";
      if (gpu.device.empty()) gpu.device = std::to_string(i);
      return make_vulkan_device(gpu);
    }
  } else {
    vulkan_why = devices.error().message();
  }
  why = (SINEW_HAS_OPENCL ? why + "; " : std::string()) + vulkan_why;
#endif
  static std::once_flag said;  // "saying so once"
  if (!options.quiet) std::call_once(said, [&] { std::fprintf(stderr, "sinew: backend auto -> cpu (%s)\n", why.c_str()); });
  return make_cpu_device(options);
}

}  // namespace

Result<std::unique_ptr<Device>> create_device(const DeviceOptions& options) {
  const std::string& name = options.backend;
  if (name == "cpu") return make_cpu_device(options);
  if (name == "opencl") {
#if SINEW_HAS_OPENCL
    return make_opencl_device(options);
#endif
  }
  if (name == "vulkan") {
#if SINEW_HAS_VULKAN
    return make_vulkan_device(options);
#endif
  }
  if (name == "opencl" || name == "vulkan")
    return Error("backend '" + name + "' is not built into this sinew (built: " + joined(built_backends()) +
                 "); configure with -DSINEW_" + (name == "opencl" ? "OPENCL" : "VULKAN") +
                 "=ON and its dependencies installed");
  if (name == "auto") return create_auto_device(options);
  return Error("unknown backend '" + name + "' (choose cpu, opencl, vulkan or auto)");
}

}  // namespace sinew
