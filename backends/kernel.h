// kernel.h — the ids of the kernels of the registry (kernels/kernel_list.h),
// apart from the device interface: the scene compiler names the kernel that
// solves each block of constraints without depending on devices or programs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "kernel_list.h"
#include "sinew/device.h"

namespace sinew {

/// Every kernel of the registry, by name.
enum class Kernel : std::uint32_t {
#define SINEW_KERNEL_ENUM(name, bindings, params, group) name,
  SINEW_KERNELS(SINEW_KERNEL_ENUM)
#undef SINEW_KERNEL_ENUM
  count_  ///< number of kernels, not a kernel
};

inline constexpr std::size_t kernel_count = static_cast<std::size_t>(Kernel::count_);
static_assert(kernel_count <= DeviceTimes::max_kernels, "DeviceTimes cannot time every kernel");

/// The kernel's name, the same in every kernel language ("xpbd_predict").
std::string_view kernel_name(Kernel kernel);

}  // namespace sinew
