// vulkan_device.h — the Vulkan compute backend: headless, compute only,
// Vulkan 1.2 (any GPU driver; Mesa's lavapipe on a CPU). Kernels
// (kernels/gpu/*.gpu) are compiled to SPIR-V at build time and embedded.
// A frame program is recorded once into a command buffer (again after a
// buffer it may bind is resized or destroyed) and replayed by every submit;
// wait() is one fence wait, after which the counters, copied at the end of
// the frame into mapped memory, are checked. Indirect dispatches are true
// vkCmdDispatchIndirect calls (vulkan_recording.cpp).
//
// Environment variables:
//   SINEW_VULKAN_VALIDATION=1  every instance enables VK_LAYER_KHRONOS_validation
//                              and counts the warnings and errors it reports
//                              (vulkan_validation_messages); the tests run so.
//                              Add VK_LAYER_ENABLES=VK_VALIDATION_FEATURE_ENABLE_
//                              SYNCHRONIZATION_VALIDATION_EXT to check barriers.
//   SINEW_VULKAN_DEVICE        the device, when DeviceOptions::device is empty.
//   SINEW_VULKAN_TIMESTAMPS    1: timestamps around every dispatch (Device::last_run_times,
//                              FrameStats::device); 0: none;
//                              unset: on, except on CPU devices (lavapipe),
//                              where each one costs a thread flush.
//   SINEW_VULKAN_STAGING=1     staged copies even where memory is shared (tests).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "backends/backend.h"

namespace sinew {

/// One Vulkan 1.2 device with a compute queue found on this machine.
struct VulkanDeviceInfo {
  std::string name;
  std::string type;    ///< "discrete GPU", "integrated GPU", "virtual GPU", "CPU" or "other"
  std::string driver;  ///< driver name and version, e.g. "llvmpipe Mesa 22.3.6"
  std::uint32_t api_version = 0;
  bool gpu = false;    ///< a discrete or integrated GPU (what backend "auto" may pick)
};

/// Every Vulkan device that supports Vulkan 1.2 and has a compute queue, in
/// the driver's order; an error when there is no Vulkan loader or driver.
Result<std::vector<VulkanDeviceInfo>> list_vulkan_devices();

/// [in] options.device: an index into list_vulkan_devices() or a substring
/// of the device name; empty: $SINEW_VULKAN_DEVICE, else the first discrete
/// GPU, else the first integrated GPU, else the first device. Errors: no
/// loader or driver, no matching device, a failed Vulkan call (named, with
/// its VkResult).
Result<std::unique_ptr<Device>> make_vulkan_device(const DeviceOptions& options);

/// Warnings and errors the validation layer reported so far in this process,
/// over every Vulkan instance (0 when validation is off), leaving out those
/// vulkan_validation_self_test caused on purpose.
std::uint64_t vulkan_validation_messages();

/// For tests: makes one deliberately invalid Vulkan call (a buffer without
/// usage flags) on the selected device, which the validation layer catches
/// and does not pass on to the driver, and returns how many messages the
/// layer reported for it (these are not counted by vulkan_validation_messages).
/// Errors: validation is off (SINEW_VULKAN_VALIDATION unset, or the layer is
/// not installed), or no device.
Result<std::uint64_t> vulkan_validation_self_test(const DeviceOptions& options);

}  // namespace sinew
