// device.cpp — backend-independent parts of the device interface: the kernel
// table, program checks and the choice of backend by name.
#include <cstdio>
#include <string>

#include "backends/cpu/cpu_device.h"
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

std::vector<std::string> built_backends() {
  std::vector<std::string> names{"cpu"};
  return names;
}

Result<std::unique_ptr<Device>> create_device(const DeviceOptions& options) {
  const std::string& name = options.backend;
  if (name == "cpu") return make_cpu_device(options);
  if (name == "opencl" || name == "vulkan") {
    // The GPU backends land with their own issues; until then a request for
    // one is an error, never a silent substitute.
    return Error("backend '" + name + "' is not built into this version of sinew (built: cpu)");
  }
  if (name == "auto") {
    // No GPU backend is built yet, so "auto" means the CPU reference.
    if (!options.quiet) std::fprintf(stderr, "sinew: backend auto -> cpu (no GPU backend is built)\n");
    return make_cpu_device(options);
  }
  return Error("unknown backend '" + name + "' (choose cpu, opencl, vulkan or auto)");
}

}  // namespace sinew
