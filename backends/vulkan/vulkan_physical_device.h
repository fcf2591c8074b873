// vulkan_physical_device.h — which Vulkan devices this machine has and which
// one a sinew Device uses: every device of Vulkan 1.2 or later with a compute
// queue, chosen by index or name substring, else by type (a discrete GPU
// before an integrated one).
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "backends/vulkan/vulkan_device.h"

namespace sinew::vulkan {

/// One usable device and what the backend needs to know about it.
struct Found {
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0;
  bool timestamps = false;  // the compute queue family writes timestamps
  std::uint32_t timestamp_bits = 0;
  VkPhysicalDeviceProperties properties{};
  VulkanDeviceInfo info;
};

/// "discrete GPU", "integrated GPU", "virtual GPU", "CPU" or "other".
std::string type_name(VkPhysicalDeviceType type);

/// "major.minor.patch" of a Vulkan API version.
std::string version_string(std::uint32_t v);

/// Every device of Vulkan 1.2 or later with a compute queue (its first
/// compute queue family). Errors: none found, a failed call.
Result<std::vector<Found>> find_devices(VkInstance instance);

/// The device named by `selector` (an index, or a substring of the name);
/// empty: $SINEW_VULKAN_DEVICE, else the first discrete GPU, else the first
/// integrated GPU, else the first device.
Result<std::size_t> choose(const std::vector<Found>& found, std::string selector);

}  // namespace sinew::vulkan
