// kernel_table.h — what every backend needs to know about each kernel: its
// name (the same in every kernel language), how many buffers it binds and
// the size of its parameter struct. create_program checks dispatches against it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "backends/backend.h"

namespace sinew {

/// A kernel's registry entry (kernels/kernel_list.h).
struct KernelSignature {
  std::string_view name;
  std::uint32_t bindings;
  std::uint32_t params_bytes;
  std::uint32_t group_size;  ///< 0: independent items; N: cooperative groups of N items
};

/// Work items of independent kernels are launched in groups of this many
/// on GPU backends (their GPU sources say local_size 64).
inline constexpr std::uint32_t kIndependentGroupSize = 64;

/// The size of the groups a dispatch of `kernel` is launched in.
std::uint32_t launch_group_size(Kernel kernel);

/// [pre] kernel < Kernel::count_
const KernelSignature& kernel_signature(Kernel kernel);

/// Checks a program's commands and counters against the kernel table and
/// the device's buffers: buffer_bytes[id] is the size of buffer `id`, 0 for
/// one destroyed. Errors name the command by position and kernel.
Status check_program(const FrameProgram& program, std::span<const std::size_t> buffer_bytes);

/// The capacity_exceeded error for the counters whose value (values[i],
/// read after a run) exceeds their capacity, naming each; success when none does.
Status check_counters(const std::vector<Counter>& counters, std::span<const std::uint32_t> values);

/// The device a GPU backend's selector names: an index into `names`, or the
/// first name containing it as a substring. Errors list every device as
/// "index: label" (`labels[i]`), naming the API ("OpenCL", "Vulkan").
/// [pre] selector is not empty (callers apply their default choice first).
Result<std::size_t> match_device_selector(const std::vector<std::string>& names,
                                          const std::vector<std::string>& labels, const std::string& selector,
                                          const char* api);

/// Checks that bytes [offset, offset + bytes) lie in a buffer of `size`
/// bytes named `label`; `what` names the call in the error.
Status check_buffer_range(const std::string& label, std::size_t size, std::size_t offset, std::size_t bytes,
                          const char* what);

}  // namespace sinew
