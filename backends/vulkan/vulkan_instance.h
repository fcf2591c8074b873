// vulkan_instance.h — the Vulkan instance, and the validation layer with its
// message counting. Every sinew Device (and list_vulkan_devices) makes its own
// instance; with SINEW_VULKAN_VALIDATION=1 each one enables
// VK_LAYER_KHRONOS_validation, whose warnings and errors are printed and
// counted over the whole process (the tests fail on any).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>

#include "sinew/result.h"

namespace sinew::vulkan {

inline constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

/// SINEW_VULKAN_VALIDATION=1.
bool validation_requested();
/// The loader knows kValidationLayer.
bool has_validation_layer();

/// Warnings and errors the layer reported so far over every instance, leaving
/// out those make_deliberate_mistake caused.
std::uint64_t validation_messages();

/// Makes one invalid call (a buffer without usage flags) on `device`, which
/// the validation layer catches and does not pass on to the driver; returns
/// how many messages the layer reported for it (not counted by
/// validation_messages). 0 where validation is off.
std::uint64_t make_deliberate_mistake(VkDevice device);

/// A VkInstance and, with validation, its debug messenger; destroys both.
struct Instance {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  bool validation = false;

  Instance() = default;
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;
  ~Instance();
};

/// A Vulkan 1.2 instance, with validation when requested and installed (else
/// a one-time warning through the log callback, sinew/log.h). Errors: a loader older than 1.2, a failed call.
Result<std::unique_ptr<Instance>> make_instance();

}  // namespace sinew::vulkan
