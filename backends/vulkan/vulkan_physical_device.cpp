// vulkan_physical_device.cpp — device enumeration and choice. Devices older
// than Vulkan 1.2 or without a compute queue are left out, so that every
// device listed (list_vulkan_devices) can run every kernel.
#include "backends/vulkan/vulkan_physical_device.h"

#include <algorithm>
#include <cstdlib>

#include "backends/kernel_table.h"
#include "backends/vulkan/vulkan_common.h"

namespace sinew::vulkan {

std::string type_name(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
    default: return "other";
  }
}

std::string version_string(std::uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

Result<std::vector<Found>> find_devices(VkInstance instance) {
  std::uint32_t n = 0;
  if (VkResult r = vkEnumeratePhysicalDevices(instance, &n, nullptr); r != VK_SUCCESS)
    return vk_error("vkEnumeratePhysicalDevices", r, ErrorCode::backend_unavailable);
  std::vector<VkPhysicalDevice> physical(n);
  if (VkResult r = vkEnumeratePhysicalDevices(instance, &n, physical.data()); r != VK_SUCCESS && r != VK_INCOMPLETE)
    return vk_error("vkEnumeratePhysicalDevices", r, ErrorCode::backend_unavailable);
  std::vector<Found> found;
  for (VkPhysicalDevice p : physical) {
    Found f;
    f.physical = p;
    vkGetPhysicalDeviceProperties(p, &f.properties);
    if (f.properties.apiVersion < VK_API_VERSION_1_2) continue;
    std::uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(p, &families, nullptr);
    std::vector<VkQueueFamilyProperties> family(families);
    vkGetPhysicalDeviceQueueFamilyProperties(p, &families, family.data());
    const auto compute = std::find_if(family.begin(), family.end(),
                                      [](const VkQueueFamilyProperties& q) { return q.queueFlags & VK_QUEUE_COMPUTE_BIT; });
    if (compute == family.end()) continue;
    f.queue_family = static_cast<std::uint32_t>(compute - family.begin());
    f.timestamp_bits = compute->timestampValidBits;
    f.timestamps = f.timestamp_bits > 0 && f.properties.limits.timestampPeriod > 0.0f;
    auto driver = vk_struct<VkPhysicalDeviceDriverProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
    auto properties2 = vk_struct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    properties2.pNext = &driver;
    vkGetPhysicalDeviceProperties2(p, &properties2);
    const VkPhysicalDeviceType type = f.properties.deviceType;
    f.info = {f.properties.deviceName, type_name(type), std::string(driver.driverName) + " " + driver.driverInfo,
              f.properties.apiVersion,
              type == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU || type == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU};
    found.push_back(f);
  }
  if (found.empty())
    return Error(ErrorCode::backend_unavailable, "Vulkan found no device with Vulkan 1.2 and a compute queue");
  return found;
}

Result<std::size_t> choose(const std::vector<Found>& found, std::string selector) {
  if (selector.empty())
    if (const char* env = std::getenv("SINEW_VULKAN_DEVICE")) selector = env;
  if (selector.empty()) {
    for (VkPhysicalDeviceType type : {VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU})
      for (std::size_t i = 0; i < found.size(); ++i)
        if (found[i].properties.deviceType == type) return i;
    return std::size_t{0};
  }
  std::vector<std::string> names, labels;
  for (const Found& f : found) {
    names.push_back(f.info.name);
    labels.push_back(f.info.name + " (" + f.info.type + ")");
  }
  return match_device_selector(names, labels, selector, "Vulkan");
}

}  // namespace sinew::vulkan
