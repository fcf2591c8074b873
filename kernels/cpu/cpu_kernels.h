// cpu_kernels.h — the CPU reference function of every registered kernel
// (kernels/kernel_list.h), declared from the registry: kernels::NAME.
//
// Signature of every CPU kernel: its parameters (the struct from
// kernels/shared), the bound buffers in binding order, and the range to
// process: work items [begin, end) for independent kernels, work groups
// [begin, end) for cooperative ones (a group size in the registry), each
// group's work done in order (see backends/cpu/cpu_device.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "kernel_list.h"

namespace sinew::kernels {

using CpuKernelFn = void (*)(const void* params, std::byte* const* bindings, std::uint32_t begin,
                             std::uint32_t end);

#define SINEW_CPU_KERNEL_DECLARATION(name, binding_count, params_type, group_size) \
  void name(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
SINEW_KERNELS(SINEW_CPU_KERNEL_DECLARATION)
#undef SINEW_CPU_KERNEL_DECLARATION

}  // namespace sinew::kernels
