// device.cpp — backend-independent parts of the device interface: the kernel
// table, program checks and the choice of backend by name.
#include <algorithm>
#include <array>
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
#include "sinew/log.h"
#include "accelerator_params.h"
#include "bvh_params.h"
#include "ccd_params.h"
#include "contact_coloring_params.h"
#include "fluid_coupling_params.h"
#include "level_set_params.h"
#include "narrow_phase_params.h"
#include "mesh_contact_params.h"
#include "neighbour_params.h"
#include "primitive_params.h"
#include "sph_params.h"
#include "sph_flow_params.h"
#include "pbf_params.h"
#include "sph_tension_params.h"
#include "stats_params.h"
#include "suture_params.h"
#include "vbd_params.h"
#include "xpbd_params.h"

namespace sinew {
namespace {

using namespace kernels;

// The kernel registry (kernels/kernel_list.h) as a table.
constexpr KernelSignature kSignatures[] = {
#define SINEW_KERNEL_SIGNATURE(name, bindings, params, group) {#name, bindings, sizeof(params), group},
    SINEW_KERNELS(SINEW_KERNEL_SIGNATURE)
#undef SINEW_KERNEL_SIGNATURE
};
static_assert(std::size(kSignatures) == kernel_count);

constexpr std::array<std::string_view, kernel_count> kNames = [] {
  std::array<std::string_view, kernel_count> names{};
  for (std::size_t k = 0; k < kernel_count; ++k) names[k] = kSignatures[k].name;
  return names;
}();

std::string range_text(std::uint32_t word, std::uint32_t words) {
  return "words [" + std::to_string(word) + ", " + std::to_string(std::uint64_t{word} + words) + ")";
}

// Whether buffer `b` is live and holds words [word, word + words).
Status check_words(const std::string& who, const char* role, BufferHandle b, std::uint64_t word, std::uint64_t words,
                   std::span<const std::size_t> bytes) {
  if (b.id >= bytes.size() || bytes[b.id] == 0)
    return Error(ErrorCode::internal, who + ": " + role + " is not a buffer of this device");
  if ((word + words) * 4 > bytes[b.id])
    return Error(ErrorCode::internal, who + ": " + role + " " + range_text(std::uint32_t(word), std::uint32_t(words)) +
                                          " past the buffer's " + std::to_string(bytes[b.id]) + " bytes");
  return {};
}

}  // namespace

const KernelSignature& kernel_signature(Kernel kernel) { return kSignatures[static_cast<std::size_t>(kernel)]; }

std::uint32_t launch_group_size(Kernel kernel) {
  const std::uint32_t g = kernel_signature(kernel).group_size;
  return g ? g : kIndependentGroupSize;
}

std::string_view kernel_name(Kernel kernel) {
  if (kernel >= Kernel::count_) return "unknown";
  return kernel_signature(kernel).name;
}

std::span<const std::string_view> kernel_names() { return kNames; }

std::size_t FrameProgram::dispatch_count() const {
  std::size_t n = 0;
  for (const auto& c : commands_) n += std::holds_alternative<Dispatch>(c) ? 1 : 0;
  return n;
}

std::size_t FrameProgram::barrier_count() const {
  std::size_t n = 0;
  for (const auto& c : commands_) n += std::holds_alternative<Barrier>(c) ? 1 : 0;
  return n;
}

std::size_t FrameProgram::dispatch_count(Kernel kernel) const {
  std::size_t n = 0;
  for (const auto& c : commands_)
    if (const auto* d = std::get_if<Dispatch>(&c); d && d->kernel == kernel) ++n;
  return n;
}

Status check_program(const FrameProgram& program, std::span<const std::size_t> bytes) {
  std::size_t index = 0;
  for (const Counter& c : program.counters()) {
    const std::string who = "frame program counter " + std::to_string(index++) + " ('" + c.label + "')";
    if (Status s = check_words(who, "its buffer", c.buffer, c.word, 1, bytes); !s) return s;
  }
  index = 0;
  for (const EndRead& r : program.end_reads()) {
    const std::string who = "frame program end read " + std::to_string(index++);
    if (r.words == 0) return Error(ErrorCode::internal, who + ": reads no words");
    if (Status s = check_words(who, "its buffer", r.buffer, r.word, r.words, bytes); !s) return s;
  }
  std::size_t position = 0;
  for (const auto& command : program.commands()) {
    ++position;
    const std::string where = "frame program command " + std::to_string(position);
    if (const auto* f = std::get_if<Fill>(&command)) {
      if (Status s = check_words(where + " (fill)", "the buffer", f->buffer, f->word, f->words, bytes); !s) return s;
      continue;
    }
    if (const auto* c = std::get_if<Copy>(&command)) {
      const std::string who = where + " (copy)";
      if (Status s = check_words(who, "the source", c->source, c->source_word, c->words, bytes); !s) return s;
      if (Status s = check_words(who, "the target", c->target, c->target_word, c->words, bytes); !s) return s;
      if (c->source == c->target && c->source_word < std::uint64_t{c->target_word} + c->words &&
          c->target_word < std::uint64_t{c->source_word} + c->words)
        return Error(ErrorCode::internal, who + ": source and target ranges overlap");
      continue;
    }
    const auto* d = std::get_if<Dispatch>(&command);
    if (!d) continue;
    if (d->kernel >= Kernel::count_)
      return Error(ErrorCode::internal,
                   where + ": unknown kernel id " + std::to_string(static_cast<std::uint32_t>(d->kernel)));
    const KernelSignature& sig = kernel_signature(d->kernel);
    const std::string who = where + " (" + std::string(sig.name) + ")";
    if (d->binding_count > Dispatch::max_bindings)
      return Error(ErrorCode::internal, who + ": binds " + std::to_string(d->binding_count) + " buffers, at most " +
                                            std::to_string(Dispatch::max_bindings));
    if (d->binding_count != sig.bindings)
      return Error(ErrorCode::internal, who + ": binds " + std::to_string(d->binding_count) +
                                            " buffers, the kernel takes " + std::to_string(sig.bindings));
    if (d->params_bytes != sig.params_bytes)
      return Error(ErrorCode::internal, who + ": parameter block of " + std::to_string(d->params_bytes) +
                                            " bytes, the kernel takes " + std::to_string(sig.params_bytes));
    for (std::uint32_t b = 0; b < d->binding_count; ++b)
      if (d->bindings[b].id >= bytes.size() || bytes[d->bindings[b].id] == 0)
        return Error(ErrorCode::internal, who + ": binding " + std::to_string(b) + " is not a buffer of this device");
    if (d->indirect.buffer.valid()) {
      const auto& counters = program.counters();
      const bool declared = std::any_of(counters.begin(), counters.end(), [&](const Counter& c) {
        return c.buffer == d->indirect.buffer && c.word == d->indirect.word && c.capacity == d->count;
      });
      if (!declared)
        return Error(ErrorCode::internal, who + ": an indirect dispatch whose count (word " +
                                              std::to_string(d->indirect.word) +
                                              ") is not a declared counter of capacity " + std::to_string(d->count));
    }
  }
  return {};
}

Status check_counters(const std::vector<Counter>& counters, std::span<const std::uint32_t> values) {
  std::string over;
  for (std::size_t i = 0; i < counters.size() && i < values.size(); ++i)
    if (values[i] > counters[i].capacity)
      over += (over.empty() ? "" : "; ") + ("'" + counters[i].label + "' reached " + std::to_string(values[i]) +
                                           " of capacity " + std::to_string(counters[i].capacity));
  if (over.empty()) return {};
  return Error(ErrorCode::capacity_exceeded,
               "capacity exceeded (work past it was dropped, the rest of the frame stands): " + over);
}


Status check_buffer_range(const std::string& label, std::size_t size, std::size_t offset, std::size_t bytes,
                          const char* what) {
  if (offset > size || bytes > size - offset)
    return Error(ErrorCode::internal, std::string(what) + " '" + label + "': bytes [" + std::to_string(offset) + ", " +
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
  return Error(ErrorCode::backend_unavailable, std::string("no ") + api + " device matches '" + selector + "'; devices:" + list);
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
  if (!options.quiet) std::call_once(said, [&] { log_message(LogLevel::warning, "backend auto -> cpu (" + why + ")"); });
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
    return Error(ErrorCode::backend_unavailable, "backend '" + name + "' is not built into this sinew (built: " + joined(built_backends()) +
                 "); configure with -DSINEW_" + (name == "opencl" ? "OPENCL" : "VULKAN") +
                 "=ON and its dependencies installed");
  if (name == "auto") return create_auto_device(options);
  return Error(ErrorCode::bad_parameter, "unknown backend '" + name + "' (choose cpu, opencl, vulkan or auto)");
}

}  // namespace sinew
