// kernel_table.h — what every backend needs to know about each kernel: its
// name (the same in every kernel language), how many buffers it binds and
// the size of its parameter struct. create_program checks dispatches against it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "sinew/device.h"

namespace sinew {

struct KernelSignature {
  std::string_view name;
  std::uint32_t bindings;
  std::uint32_t params_bytes;
};

/// [pre] kernel < Kernel::count_
const KernelSignature& kernel_signature(Kernel kernel);

/// Checks a program's dispatches against the kernel table and the number of
/// buffers the device has. Errors name the dispatch by position and kernel.
Status check_program(const FrameProgram& program, std::uint32_t buffer_count);

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
