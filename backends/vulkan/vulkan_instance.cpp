// vulkan_instance.cpp — the Vulkan instance and the validation layer: the
// layer's messages arrive in one callback that prints and counts them
// (vulkan_validation_messages), except while make_deliberate_mistake runs,
// whose messages are counted apart so that the tests can check the counter
// works without failing on it.
#include "backends/vulkan/vulkan_instance.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "backends/vulkan/vulkan_common.h"
#include "sinew/log.h"

namespace sinew::vulkan {

static std::atomic<std::uint64_t> g_validation_messages{0};
// Set while make_deliberate_mistake makes its deliberate mistake.
static thread_local std::uint64_t* t_deliberate_messages = nullptr;

static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                             VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                             void* /*user*/) {
  if (t_deliberate_messages) {
    ++*t_deliberate_messages;
    return VK_TRUE;  // the layer then skips the invalid call: the driver never sees it
  }
  g_validation_messages.fetch_add(1, std::memory_order_relaxed);
  log_message(severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? LogLevel::error : LogLevel::warning,
              std::string("Vulkan validation: ") + (data && data->pMessage ? data->pMessage : "(no message)"));
  return VK_FALSE;
}

bool validation_requested() {
  const char* v = std::getenv("SINEW_VULKAN_VALIDATION");
  return v && std::string(v) == "1";
}

bool has_validation_layer() {
  std::uint32_t n = 0;
  if (vkEnumerateInstanceLayerProperties(&n, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(n);
  if (vkEnumerateInstanceLayerProperties(&n, layers.data()) != VK_SUCCESS) return false;
  return std::any_of(layers.begin(), layers.end(),
                     [](const VkLayerProperties& l) { return std::strcmp(l.layerName, kValidationLayer) == 0; });
}

std::uint64_t validation_messages() { return g_validation_messages.load(std::memory_order_relaxed); }

std::uint64_t make_deliberate_mistake(VkDevice device) {
  std::uint64_t seen = 0;
  auto info = vk_struct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  info.size = 64;
  info.usage = 0;  // invalid: VUID-VkBufferCreateInfo-usage-requiredbitmask
  VkBuffer buffer = VK_NULL_HANDLE;
  t_deliberate_messages = &seen;
  const VkResult r = vkCreateBuffer(device, &info, nullptr, &buffer);
  t_deliberate_messages = nullptr;
  if (r == VK_SUCCESS && buffer) vkDestroyBuffer(device, buffer, nullptr);
  return seen;
}

Instance::~Instance() {
  if (messenger) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance, messenger, nullptr);
  }
  if (instance) vkDestroyInstance(instance, nullptr);
}

// NVIDIA's driver (580, on an H100) answers vkCreateInstance with
// VK_ERROR_INCOMPATIBLE_DRIVER once about 28 instances have been created and
// destroyed in one process: the loader unloads the driver with the last
// instance and loads it again with the next, and that reload stops working.
// One extra instance, without layers, held for the process's life keeps the
// drivers loaded (measured there: 60 simulations created and destroyed in a
// row all pass; without it the 29th fails). It is destroyed at exit.
void keep_drivers_loaded(const VkApplicationInfo& app) {
  static struct Keeper {
    VkInstance instance = VK_NULL_HANDLE;
    ~Keeper() {
      if (instance) vkDestroyInstance(instance, nullptr);
    }
  } keeper;
  static std::once_flag once;
  std::call_once(once, [&] {
    auto info = vk_struct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    info.pApplicationInfo = &app;
    if (vkCreateInstance(&info, nullptr, &keeper.instance) != VK_SUCCESS) keeper.instance = VK_NULL_HANDLE;
  });
}

Result<std::unique_ptr<Instance>> make_instance() {
  std::uint32_t loader = 0;
  if (vkEnumerateInstanceVersion(&loader) != VK_SUCCESS || loader < VK_API_VERSION_1_2)
    return Error(ErrorCode::backend_unavailable, "the Vulkan loader supports Vulkan " + std::to_string(VK_API_VERSION_MAJOR(loader)) + "." +
                 std::to_string(VK_API_VERSION_MINOR(loader)) + "; sinew needs 1.2");
  auto inst = std::make_unique<Instance>();
  inst->validation = validation_requested() && has_validation_layer();
  if (validation_requested() && !inst->validation) {
    static std::once_flag said;
    std::call_once(said, [] {
      log_message(LogLevel::warning, std::string("SINEW_VULKAN_VALIDATION=1 but ") + kValidationLayer +
                                         " is not installed (apt-get install vulkan-validationlayers); Vulkan runs "
                                         "without validation");
    });
  }
  auto app = vk_struct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.pApplicationName = "sinew";
  app.pEngineName = "sinew";
  app.apiVersion = VK_API_VERSION_1_2;
  auto messenger = vk_struct<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger.pfnUserCallback = on_validation_message;
  const char* layers[] = {kValidationLayer};
  const char* extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
  auto info = vk_struct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  info.pApplicationInfo = &app;
  if (inst->validation) {
    info.pNext = &messenger;  // also reports on vkCreateInstance and vkDestroyInstance
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = layers;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = extensions;
  }
  if (VkResult r = vkCreateInstance(&info, nullptr, &inst->instance); r != VK_SUCCESS) {
    inst->instance = VK_NULL_HANDLE;
    return vk_error("vkCreateInstance", r, ErrorCode::backend_unavailable);
  }
  keep_drivers_loaded(app);
  if (inst->validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(inst->instance, "vkCreateDebugUtilsMessengerEXT"));
    if (!create) return Error(ErrorCode::internal, "vkGetInstanceProcAddr(vkCreateDebugUtilsMessengerEXT) found nothing");
    if (VkResult r = create(inst->instance, &messenger, nullptr, &inst->messenger); r != VK_SUCCESS) {
      inst->messenger = VK_NULL_HANDLE;
      return vk_error("vkCreateDebugUtilsMessengerEXT", r);
    }
  }
  return inst;
}

}  // namespace sinew::vulkan
