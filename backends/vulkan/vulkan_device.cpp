// vulkan_device.cpp — the Vulkan compute backend.
//
// One instance, device and compute queue per sinew Device; every call that
// waits does so on one fence, so at most one submission is in flight.
//
// Memory. Where the device shares memory with the host (a CPU device such as
// lavapipe, or an integrated GPU) and has host-visible, coherent,
// device-local memory, every buffer lives there, mapped once: write_buffer
// and read_buffer are memcpy. Otherwise buffers are device-local and copies
// go through one host-visible staging buffer (grown on demand) with a
// transfer command buffer and a fence wait. SINEW_VULKAN_STAGING=1 forces the
// staged path (to test it on a unified-memory device).
//
// Pipelines. One per kernel, made on first use from the embedded SPIR-V
// (kernels/glsl, compiled by glslc at build time). Its layout: one
// descriptor set of the kernel's storage buffers (set layouts shared by
// binding count) and a push-constant range of its parameter struct.
//
// Programs. create_program records the whole frame once into a command
// buffer: per dispatch bind pipeline, descriptor set and push constants,
// then vkCmdDispatch(ceil(count / 64)); per Barrier one compute -> compute
// memory barrier (shader writes -> shader reads and writes). Descriptor sets
// are allocated and written at create_program time, one per distinct tuple
// of bound buffers, from the program's own pool. The recording opens with a
// barrier after earlier transfers and dispatches and closes with one that
// makes the shader writes visible to the host and to transfers. run_program
// submits the command buffer and waits on the fence once.
//
// Timestamps (when the queue has them) are written before and after every
// dispatch and read only when asked (last_run_times). On a CPU device
// (lavapipe) each one costs a flush of the rasterizer threads, tens of
// microseconds, so there they are off unless SINEW_VULKAN_TIMESTAMPS=1;
// SINEW_VULKAN_TIMESTAMPS=0 turns them off everywhere.
#include "backends/vulkan/vulkan_device.h"

#include <vulkan/vulkan.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <span>

#include "backends/kernel_table.h"

namespace sinew {
namespace vulkan {
// Generated from kernels/glsl by cmake/EmbedSpirv.cmake; empty when the kernel has no GLSL twin.
std::span<const std::uint32_t> embedded_spirv(std::string_view kernel);
}  // namespace vulkan

namespace {

constexpr std::uint32_t kLocalSize = 64;  // local_size_x of every kernels/glsl kernel
constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::string result_name(VkResult r) {
  switch (r) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_INCOMPLETE: return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY (out of host memory)";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY (out of device memory)";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST (the device was lost: a driver reset, hang or crash)";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
      return "VK_ERROR_INCOMPATIBLE_DRIVER (no Vulkan 1.2 driver installed? e.g. apt-get install mesa-vulkan-drivers)";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FRAGMENTED_POOL: return "VK_ERROR_FRAGMENTED_POOL";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    case VK_ERROR_VALIDATION_FAILED_EXT: return "VK_ERROR_VALIDATION_FAILED_EXT";
    case VK_ERROR_UNKNOWN: return "VK_ERROR_UNKNOWN";
    default: return "VkResult " + std::to_string(static_cast<int>(r));
  }
}

Error vk_error(const std::string& call, VkResult r) { return Error(call + " failed: " + result_name(r)); }

// A Vulkan struct, zeroed, with its sType set.
template <class T>
T vk_struct(VkStructureType type) {
  T t{};
  t.sType = type;
  return t;
}

// ------------------------------------------------------------ validation

std::atomic<std::uint64_t> g_validation_messages{0};
// Set while vulkan_validation_self_test makes its deliberate mistake.
thread_local std::uint64_t* t_deliberate_messages = nullptr;

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                      VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                                      const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                      void* /*user*/) {
  if (t_deliberate_messages) {
    ++*t_deliberate_messages;
    return VK_TRUE;  // the layer then skips the invalid call: the driver never sees it
  }
  g_validation_messages.fetch_add(1, std::memory_order_relaxed);
  std::fprintf(stderr, "sinew: Vulkan validation %s: %s\n",
               severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
               data && data->pMessage ? data->pMessage : "(no message)");
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

// ------------------------------------------------------------ instance

struct Instance {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  bool validation = false;

  Instance() = default;
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;
  ~Instance() {
    if (messenger) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      if (destroy) destroy(instance, messenger, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
  }
};

Result<std::unique_ptr<Instance>> make_instance() {
  std::uint32_t loader = 0;
  if (vkEnumerateInstanceVersion(&loader) != VK_SUCCESS || loader < VK_API_VERSION_1_2)
    return Error("the Vulkan loader supports Vulkan " + std::to_string(VK_API_VERSION_MAJOR(loader)) + "." +
                 std::to_string(VK_API_VERSION_MINOR(loader)) + "; sinew needs 1.2");
  auto inst = std::make_unique<Instance>();
  inst->validation = validation_requested() && has_validation_layer();
  if (validation_requested() && !inst->validation) {
    static std::once_flag said;
    std::call_once(said, [] {
      std::fprintf(stderr, "sinew: SINEW_VULKAN_VALIDATION=1 but %s is not installed (apt-get install "
                           "vulkan-validationlayers); Vulkan runs without validation\n", kValidationLayer);
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
    return vk_error("vkCreateInstance", r);
  }
  if (inst->validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(inst->instance, "vkCreateDebugUtilsMessengerEXT"));
    if (!create) return Error("vkGetInstanceProcAddr(vkCreateDebugUtilsMessengerEXT) found nothing");
    if (VkResult r = create(inst->instance, &messenger, nullptr, &inst->messenger); r != VK_SUCCESS) {
      inst->messenger = VK_NULL_HANDLE;
      return vk_error("vkCreateDebugUtilsMessengerEXT", r);
    }
  }
  return inst;
}

// ------------------------------------------------------------ physical devices

struct Found {
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0;
  bool timestamps = false;  // the compute queue family writes timestamps
  std::uint32_t timestamp_bits = 0;
  VkPhysicalDeviceProperties properties{};
  VulkanDeviceInfo info;
};

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

// Every device of Vulkan 1.2 or later with a compute queue.
Result<std::vector<Found>> find_devices(VkInstance instance) {
  std::uint32_t n = 0;
  if (VkResult r = vkEnumeratePhysicalDevices(instance, &n, nullptr); r != VK_SUCCESS)
    return vk_error("vkEnumeratePhysicalDevices", r);
  std::vector<VkPhysicalDevice> physical(n);
  if (VkResult r = vkEnumeratePhysicalDevices(instance, &n, physical.data()); r != VK_SUCCESS && r != VK_INCOMPLETE)
    return vk_error("vkEnumeratePhysicalDevices", r);
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
  if (found.empty()) return Error("Vulkan found no device with Vulkan 1.2 and a compute queue");
  return found;
}

// The device named by `selector` (an index, or a substring of the name);
// empty: the first discrete GPU, else the first integrated GPU, else the first device.
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

// ------------------------------------------------------------ the device

struct VkBuf {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;  // host-visible memory, mapped for the buffer's life
  VkDeviceSize size = 0;   // allocated (rounded up)
  std::size_t bytes = 0;   // asked for
  std::string label;
};

struct Pipeline {
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
};

struct Program {
  VkCommandBuffer commands = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkQueryPool queries = VK_NULL_HANDLE;  // two timestamps per dispatch
  std::vector<Kernel> timed;             // the kernel of each timed dispatch
};

class VulkanDeviceImpl final : public Device {
 public:
  VulkanDeviceImpl() = default;
  VulkanDeviceImpl(const VulkanDeviceImpl&) = delete;
  VulkanDeviceImpl& operator=(const VulkanDeviceImpl&) = delete;

  ~VulkanDeviceImpl() override {
    if (!device_) return;
    vkDeviceWaitIdle(device_);
    for (Program& p : programs_) destroy(p);
    for (Pipeline& p : pipelines_) {
      if (p.pipeline) vkDestroyPipeline(device_, p.pipeline, nullptr);
      if (p.layout) vkDestroyPipelineLayout(device_, p.layout, nullptr);
    }
    for (VkDescriptorSetLayout l : set_layouts_)
      if (l) vkDestroyDescriptorSetLayout(device_, l, nullptr);
    for (VkBuf& b : buffers_) destroy(b);
    destroy(staging_);
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (transfer_pool_) vkDestroyCommandPool(device_, transfer_pool_, nullptr);
    if (program_pool_) vkDestroyCommandPool(device_, program_pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }

  // Everything made here is released by the destructor, also after a failure.
  Status init(const DeviceOptions& options) {
    auto inst = make_instance();
    if (!inst) return inst.error();
    instance_ = std::move(*inst);
    auto found = find_devices(instance_->instance);
    if (!found) return found.error();
    auto index = choose(*found, options.device);
    if (!index) return index.error();
    found_ = (*found)[*index];

    const float priority = 1.0f;
    auto queue_info = vk_struct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    queue_info.queueFamilyIndex = found_.queue_family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    auto device_info = vk_struct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    if (VkResult r = vkCreateDevice(found_.physical, &device_info, nullptr, &device_); r != VK_SUCCESS) {
      device_ = VK_NULL_HANDLE;
      return vk_error("vkCreateDevice on " + found_.info.name, r);
    }
    vkGetDeviceQueue(device_, found_.queue_family, 0, &queue_);

    auto pool_info = vk_struct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
    pool_info.queueFamilyIndex = found_.queue_family;
    if (VkResult r = vkCreateCommandPool(device_, &pool_info, nullptr, &program_pool_); r != VK_SUCCESS)
      return vk_error("vkCreateCommandPool", r);
    pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT | VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    if (VkResult r = vkCreateCommandPool(device_, &pool_info, nullptr, &transfer_pool_); r != VK_SUCCESS)
      return vk_error("vkCreateCommandPool", r);
    auto alloc = vk_struct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    alloc.commandPool = transfer_pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    if (VkResult r = vkAllocateCommandBuffers(device_, &alloc, &transfer_commands_); r != VK_SUCCESS)
      return vk_error("vkAllocateCommandBuffers", r);
    const auto fence_info = vk_struct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    if (VkResult r = vkCreateFence(device_, &fence_info, nullptr, &fence_); r != VK_SUCCESS)
      return vk_error("vkCreateFence", r);

    vkGetPhysicalDeviceMemoryProperties(found_.physical, &memory_);
    const VkPhysicalDeviceType type = found_.properties.deviceType;
    const char* staging = std::getenv("SINEW_VULKAN_STAGING");
    unified_ = (type == VK_PHYSICAL_DEVICE_TYPE_CPU || type == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU) &&
               !(staging && std::string(staging) == "1") && memory_type(~0u, kUnified, kUnified).ok();
    const char* stamps = std::getenv("SINEW_VULKAN_TIMESTAMPS");
    timestamps_ = found_.timestamps && (stamps && *stamps ? std::string(stamps) != "0" : type != VK_PHYSICAL_DEVICE_TYPE_CPU);
    return {};
  }

  std::string backend_name() const override { return "vulkan"; }
  std::string device_name() const override {
    return "Vulkan: " + found_.info.name + " (" + found_.info.type + ", " + found_.info.driver + ", Vulkan " +
           version_string(found_.info.api_version) + (unified_ ? ", host-visible memory" : ", staged copies") +
           (instance_->validation ? ", validation on)" : ")");
  }

  Result<BufferHandle> create_buffer(std::size_t bytes, std::string_view label) override {
    const std::string what = "create_buffer '" + std::string(label) + "'";
    if (bytes == 0) return Error(what + ": size must be > 0");
    if (Status s = check_lost(what); !s) return s.error();
    VkBuf b;
    b.label = label;
    b.bytes = bytes;
    b.size = (bytes + 63) / 64 * 64;  // kernels may read whole float4s at the end of any buffer
    if (b.size > found_.properties.limits.maxStorageBufferRange)
      return Error(what + " (" + std::to_string(bytes) + " bytes): larger than the largest storage buffer of " +
                   found_.info.name + " (" + std::to_string(found_.properties.limits.maxStorageBufferRange) + " bytes)");
    const VkBufferUsageFlags usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    Status s = unified_ ? make_buffer(b, usage, kUnified, kUnified | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, what)
                        : make_buffer(b, usage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, what);
    if (s && unified_) std::memset(b.mapped, 0, b.size);
    if (s && !unified_)
      s = transfer(what + ": zero fill", [&](VkCommandBuffer cmd) { vkCmdFillBuffer(cmd, b.buffer, 0, VK_WHOLE_SIZE, 0); });
    if (!s) {
      destroy(b);
      return s.error();
    }
    buffers_.push_back(std::move(b));
    return BufferHandle{static_cast<std::uint32_t>(buffers_.size() - 1)};
  }

  Status write_buffer(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) override {
    if (Status s = check_range(buffer, offset, bytes, "write_buffer"); !s) return s;
    if (bytes == 0) return {};
    const VkBuf& b = buffers_[buffer.id];
    const std::string what = "write_buffer '" + b.label + "'";
    if (Status s = check_lost(what); !s) return s;
    if (b.mapped) {  // no work is in flight between calls: every submission is waited for
      std::memcpy(static_cast<std::byte*>(b.mapped) + offset, data, bytes);
      return {};
    }
    if (Status s = ensure_staging(bytes, what); !s) return s;
    std::memcpy(staging_.mapped, data, bytes);
    const VkBufferCopy region{0, offset, bytes};
    return transfer(what, [&](VkCommandBuffer cmd) { vkCmdCopyBuffer(cmd, staging_.buffer, b.buffer, 1, &region); });
  }

  Status read_buffer(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) override {
    if (Status s = check_range(buffer, offset, bytes, "read_buffer"); !s) return s;
    if (bytes == 0) return {};
    const VkBuf& b = buffers_[buffer.id];
    const std::string what = "read_buffer '" + b.label + "'";
    if (Status s = check_lost(what); !s) return s;
    if (b.mapped) {
      std::memcpy(data, static_cast<const std::byte*>(b.mapped) + offset, bytes);
      return {};
    }
    if (Status s = ensure_staging(bytes, what); !s) return s;
    const VkBufferCopy region{offset, 0, bytes};
    if (Status s = transfer(what, [&](VkCommandBuffer cmd) { vkCmdCopyBuffer(cmd, b.buffer, staging_.buffer, 1, &region); }); !s)
      return s;
    std::memcpy(data, staging_.mapped, bytes);
    return {};
  }

  Result<ProgramHandle> create_program(const FrameProgram& program) override {
    if (Status s = check_program(program, static_cast<std::uint32_t>(buffers_.size())); !s) return s.error();
    if (Status s = check_lost("create_program"); !s) return s.error();
    // Resolve the commands: pipelines (made on first use), one descriptor
    // set per distinct tuple of bound buffers, barriers between dispatches only.
    struct Step {
      const Dispatch* dispatch = nullptr;  // nullptr: a barrier
      std::uint32_t set = 0;
      std::uint32_t groups = 0;
    };
    std::vector<Step> steps;
    std::map<std::vector<std::uint32_t>, std::uint32_t> set_of;
    std::vector<const std::vector<std::uint32_t>*> set_buffers;
    std::uint32_t descriptors = 0;
    std::size_t position = 0;
    for (const auto& command : program.commands()) {
      ++position;
      const auto* d = std::get_if<Dispatch>(&command);
      if (!d) {
        if (!steps.empty() && steps.back().dispatch) steps.push_back({});
        continue;
      }
      if (d->count == 0) continue;
      auto pipe = pipeline(d->kernel);
      if (!pipe) return pipe.error();
      const std::uint32_t groups = (d->count + kLocalSize - 1) / kLocalSize;
      if (groups > found_.properties.limits.maxComputeWorkGroupCount[0])
        return Error("frame program command " + std::to_string(position) + " (" + std::string(kernel_name(d->kernel)) +
                     "): " + std::to_string(d->count) + " work items exceed what " + found_.info.name +
                     " dispatches at once (" + std::to_string(found_.properties.limits.maxComputeWorkGroupCount[0]) +
                     " groups of " + std::to_string(kLocalSize) + ")");
      std::vector<std::uint32_t> key;
      for (std::uint32_t b = 0; b < d->binding_count; ++b) key.push_back(d->bindings[b].id);
      auto [it, added] = set_of.emplace(std::move(key), static_cast<std::uint32_t>(set_buffers.size()));
      if (added) {
        set_buffers.push_back(&it->first);
        descriptors += d->binding_count;
      }
      steps.push_back({d, it->second, groups});
    }
    if (!steps.empty() && !steps.back().dispatch) steps.pop_back();  // the closing barrier covers it

    Program p;
    Status s = record(p, steps, set_buffers, descriptors);
    if (!s) {
      destroy(p);
      return s.error();
    }
    programs_.push_back(std::move(p));
    return ProgramHandle{static_cast<std::uint32_t>(programs_.size() - 1)};
  }

  Status run_program(ProgramHandle program) override {
    if (program.id >= programs_.size()) return Error("run_program: not a program of this device");
    if (Status s = check_lost("run_program"); !s) return s;
    last_run_ = UINT32_MAX;
    if (Status s = submit_and_wait(programs_[program.id].commands, "run_program"); !s) return s;
    last_run_ = program.id;
    return {};
  }

  Status last_run_times(DeviceTimes& out) const override {
    out = {};
    if (last_run_ >= programs_.size() || !programs_[last_run_].queries) return {};
    const Program& p = programs_[last_run_];
    // Two timestamps per dispatch, read into storage kept between frames.
    stamps_.resize(2 * p.timed.size());
    if (stamps_.empty()) return {};
    const VkResult r = vkGetQueryPoolResults(device_, p.queries, 0, static_cast<std::uint32_t>(stamps_.size()),
                                             stamps_.size() * sizeof(std::uint64_t), stamps_.data(),
                                             sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
    if (r != VK_SUCCESS) return vk_error("vkGetQueryPoolResults", r);
    out.timed = true;
    out.span_ms = ticks_to_ms(stamps_.back() - stamps_.front());
    for (std::size_t i = 0; i < p.timed.size(); ++i) {
      const auto k = static_cast<std::size_t>(p.timed[i]);
      out.kernel_ms[k] += ticks_to_ms(stamps_[2 * i + 1] - stamps_[2 * i]);
      ++out.dispatches[k];
    }
    return {};
  }

  bool validation() const { return instance_->validation; }

  // See vulkan_validation_self_test.
  std::uint64_t make_deliberate_mistake() {
    std::uint64_t seen = 0;
    auto info = vk_struct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    info.size = 64;
    info.usage = 0;  // invalid: VUID-VkBufferCreateInfo-usage-requiredbitmask
    VkBuffer buffer = VK_NULL_HANDLE;
    t_deliberate_messages = &seen;
    const VkResult r = vkCreateBuffer(device_, &info, nullptr, &buffer);
    t_deliberate_messages = nullptr;
    if (r == VK_SUCCESS && buffer) vkDestroyBuffer(device_, buffer, nullptr);
    return seen;
  }

 private:
  static constexpr VkMemoryPropertyFlags kUnified =
      VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  static constexpr VkMemoryPropertyFlags kStaging = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;

  Status check_range(BufferHandle buffer, std::size_t offset, std::size_t bytes, const char* what) const {
    if (buffer.id >= buffers_.size()) return Error(std::string(what) + ": not a buffer of this device");
    const VkBuf& b = buffers_[buffer.id];
    return check_buffer_range(b.label, b.bytes, offset, bytes, what);
  }

  Status check_lost(const std::string& what) const {
    if (lost_) return Error(what + ": the Vulkan device " + found_.info.name + " was lost earlier (VK_ERROR_DEVICE_LOST)");
    return {};
  }

  // The first memory type allowed by `type_bits` with `preferred`, else with `required`.
  Result<std::uint32_t> memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags required,
                                    VkMemoryPropertyFlags preferred) const {
    for (VkMemoryPropertyFlags want : {preferred, required})
      for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
        if ((type_bits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & want) == want) return i;
    return Error("no memory type with properties " + std::to_string(required));
  }

  Status make_buffer(VkBuf& b, VkBufferUsageFlags usage, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred,
                     const std::string& what) {
    auto info = vk_struct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    info.size = b.size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if (VkResult r = vkCreateBuffer(device_, &info, nullptr, &b.buffer); r != VK_SUCCESS) {
      b.buffer = VK_NULL_HANDLE;
      return vk_error(what + ": vkCreateBuffer (" + std::to_string(b.size) + " bytes)", r);
    }
    VkMemoryRequirements needs{};
    vkGetBufferMemoryRequirements(device_, b.buffer, &needs);
    auto type = memory_type(needs.memoryTypeBits, required, preferred);
    if (!type) return Error(what + ": " + type.error().message());
    auto alloc = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    alloc.allocationSize = needs.size;
    alloc.memoryTypeIndex = *type;
    if (VkResult r = vkAllocateMemory(device_, &alloc, nullptr, &b.memory); r != VK_SUCCESS) {
      b.memory = VK_NULL_HANDLE;
      return vk_error(what + ": vkAllocateMemory (" + std::to_string(needs.size) + " bytes)", r);
    }
    if (VkResult r = vkBindBufferMemory(device_, b.buffer, b.memory, 0); r != VK_SUCCESS)
      return vk_error(what + ": vkBindBufferMemory", r);
    if (required & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
      if (VkResult r = vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped); r != VK_SUCCESS) {
        b.mapped = nullptr;
        return vk_error(what + ": vkMapMemory", r);
      }
    return {};
  }

  void destroy(VkBuf& b) {
    if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
    if (b.memory) vkFreeMemory(device_, b.memory, nullptr);  // unmaps too
    b = VkBuf{};
  }

  void destroy(Program& p) {
    if (p.commands) vkFreeCommandBuffers(device_, program_pool_, 1, &p.commands);
    if (p.pool) vkDestroyDescriptorPool(device_, p.pool, nullptr);
    if (p.queries) vkDestroyQueryPool(device_, p.queries, nullptr);
    p = Program{};
  }

  Status ensure_staging(std::size_t bytes, const std::string& what) {
    if (staging_.size >= bytes) return {};
    destroy(staging_);
    staging_.label = "staging";
    staging_.size = std::max<VkDeviceSize>((bytes + 65535) / 65536 * 65536, VkDeviceSize{1} << 20);
    staging_.bytes = staging_.size;
    Status s = make_buffer(staging_, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, kStaging,
                           kStaging | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, what + ": staging buffer");
    if (!s) destroy(staging_);
    return s;
  }

  Status submit_and_wait(VkCommandBuffer commands, const std::string& what) {
    auto submit = vk_struct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commands;
    VkResult r = vkQueueSubmit(queue_, 1, &submit, fence_);
    if (r == VK_SUCCESS) {
      r = vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX);
      if (r != VK_SUCCESS) {
        lost_ = lost_ || r == VK_ERROR_DEVICE_LOST;
        return vk_error(what + ": vkWaitForFences", r);
      }
      r = vkResetFences(device_, 1, &fence_);
      if (r != VK_SUCCESS) return vk_error(what + ": vkResetFences", r);
      return {};
    }
    lost_ = lost_ || r == VK_ERROR_DEVICE_LOST;
    return vk_error(what + ": vkQueueSubmit", r);
  }

  // Records `copy` between barriers that order it after every earlier
  // dispatch and transfer and before every later one, submits, waits.
  template <class Record>
  Status transfer(const std::string& what, Record copy) {
    if (VkResult r = vkResetCommandBuffer(transfer_commands_, 0); r != VK_SUCCESS)
      return vk_error(what + ": vkResetCommandBuffer", r);
    auto begin = vk_struct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    if (VkResult r = vkBeginCommandBuffer(transfer_commands_, &begin); r != VK_SUCCESS)
      return vk_error(what + ": vkBeginCommandBuffer", r);
    memory_barrier(transfer_commands_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
    copy(transfer_commands_);
    memory_barrier(transfer_commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT);
    if (VkResult r = vkEndCommandBuffer(transfer_commands_); r != VK_SUCCESS)
      return vk_error(what + ": vkEndCommandBuffer", r);
    return submit_and_wait(transfer_commands_, what);
  }

  static void memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src_access,
                             VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) {
    auto barrier = vk_struct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    barrier.srcAccessMask = src_access;
    barrier.dstAccessMask = dst_access;
    vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 1, &barrier, 0, nullptr, 0, nullptr);
  }

  Result<VkDescriptorSetLayout> set_layout(std::uint32_t bindings) {
    VkDescriptorSetLayout& layout = set_layouts_[bindings];
    if (layout) return layout;
    std::array<VkDescriptorSetLayoutBinding, Dispatch::max_bindings> b{};
    for (std::uint32_t i = 0; i < bindings; ++i)
      b[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    auto info = vk_struct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    info.bindingCount = bindings;
    info.pBindings = b.data();
    if (VkResult r = vkCreateDescriptorSetLayout(device_, &info, nullptr, &layout); r != VK_SUCCESS) {
      layout = VK_NULL_HANDLE;
      return vk_error("vkCreateDescriptorSetLayout", r);
    }
    return layout;
  }

  // The kernel's pipeline, made on first use.
  Result<const Pipeline*> pipeline(Kernel kernel) {
    Pipeline& p = pipelines_[static_cast<std::size_t>(kernel)];
    if (p.pipeline) return &p;
    const KernelSignature& sig = kernel_signature(kernel);
    const std::string name(sig.name);
    const std::span<const std::uint32_t> spirv = vulkan::embedded_spirv(sig.name);
    // Only when kernels/glsl is out of step with the kernel table (a test
    // makes every kernel's pipeline): an error, not a skipped test.
    if (spirv.empty()) return Error("internal: the embedded SPIR-V has no kernel " + name);
    if (sig.bindings > found_.properties.limits.maxPerStageDescriptorStorageBuffers)
      return Error("kernel " + name + " binds " + std::to_string(sig.bindings) + " storage buffers; " + found_.info.name +
                   " allows " + std::to_string(found_.properties.limits.maxPerStageDescriptorStorageBuffers));
    auto set = set_layout(sig.bindings);
    if (!set) return set.error();
    if (!p.layout) {
      const VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sig.params_bytes};
      auto info = vk_struct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
      info.setLayoutCount = 1;
      info.pSetLayouts = &*set;
      info.pushConstantRangeCount = 1;
      info.pPushConstantRanges = &push;
      if (VkResult r = vkCreatePipelineLayout(device_, &info, nullptr, &p.layout); r != VK_SUCCESS) {
        p.layout = VK_NULL_HANDLE;
        return vk_error(name + ": vkCreatePipelineLayout", r);
      }
    }
    auto module_info = vk_struct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    module_info.codeSize = spirv.size_bytes();
    module_info.pCode = spirv.data();
    VkShaderModule module = VK_NULL_HANDLE;
    if (VkResult r = vkCreateShaderModule(device_, &module_info, nullptr, &module); r != VK_SUCCESS)
      return vk_error(name + ": vkCreateShaderModule", r);
    auto info = vk_struct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    info.stage = vk_struct<VkPipelineShaderStageCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module;
    info.stage.pName = "main";
    info.layout = p.layout;
    const VkResult r = vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &p.pipeline);
    vkDestroyShaderModule(device_, module, nullptr);
    if (r != VK_SUCCESS) {
      p.pipeline = VK_NULL_HANDLE;
      return vk_error(name + ": vkCreateComputePipelines", r);
    }
    return &p;
  }

  // Allocates and writes the program's descriptor sets and records its
  // command buffer (see the top of this file). [in] steps: dispatches and
  // the barriers between them.
  template <class Step>
  Status record(Program& p, const std::vector<Step>& steps, const std::vector<const std::vector<std::uint32_t>*>& set_buffers,
                std::uint32_t descriptors) {
    std::vector<VkDescriptorSet> sets(set_buffers.size());
    if (!sets.empty()) {
      const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, descriptors};
      auto info = vk_struct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
      info.maxSets = static_cast<std::uint32_t>(sets.size());
      info.poolSizeCount = 1;
      info.pPoolSizes = &size;
      if (VkResult r = vkCreateDescriptorPool(device_, &info, nullptr, &p.pool); r != VK_SUCCESS) {
        p.pool = VK_NULL_HANDLE;
        return vk_error("create_program: vkCreateDescriptorPool", r);
      }
      std::vector<VkDescriptorSetLayout> layouts;
      for (const auto* buffers : set_buffers) layouts.push_back(set_layouts_[buffers->size()]);
      auto alloc = vk_struct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
      alloc.descriptorPool = p.pool;
      alloc.descriptorSetCount = static_cast<std::uint32_t>(layouts.size());
      alloc.pSetLayouts = layouts.data();
      if (VkResult r = vkAllocateDescriptorSets(device_, &alloc, sets.data()); r != VK_SUCCESS)
        return vk_error("create_program: vkAllocateDescriptorSets", r);
      std::vector<VkDescriptorBufferInfo> infos;
      infos.reserve(descriptors);  // the writes point into it
      std::vector<VkWriteDescriptorSet> writes;
      for (std::size_t s = 0; s < sets.size(); ++s) {
        for (std::size_t b = 0; b < set_buffers[s]->size(); ++b) {
          infos.push_back({buffers_[(*set_buffers[s])[b]].buffer, 0, VK_WHOLE_SIZE});
          auto w = vk_struct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
          w.dstSet = sets[s];
          w.dstBinding = static_cast<std::uint32_t>(b);
          w.descriptorCount = 1;
          w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
          w.pBufferInfo = &infos.back();
          writes.push_back(w);
        }
      }
      vkUpdateDescriptorSets(device_, static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
    }

    std::uint32_t dispatches = 0;
    for (const Step& s : steps) dispatches += s.dispatch ? 1 : 0;
    if (timestamps_ && dispatches > 0) {
      auto info = vk_struct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
      info.queryType = VK_QUERY_TYPE_TIMESTAMP;
      info.queryCount = 2 * dispatches;
      if (VkResult r = vkCreateQueryPool(device_, &info, nullptr, &p.queries); r != VK_SUCCESS) {
        p.queries = VK_NULL_HANDLE;
        return vk_error("create_program: vkCreateQueryPool", r);
      }
    }

    auto alloc = vk_struct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    alloc.commandPool = program_pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    if (VkResult r = vkAllocateCommandBuffers(device_, &alloc, &p.commands); r != VK_SUCCESS) {
      p.commands = VK_NULL_HANDLE;
      return vk_error("create_program: vkAllocateCommandBuffers", r);
    }
    const VkCommandBuffer cmd = p.commands;
    const auto begin = vk_struct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    if (VkResult r = vkBeginCommandBuffer(cmd, &begin); r != VK_SUCCESS)
      return vk_error("create_program: vkBeginCommandBuffer", r);
    if (p.queries) vkCmdResetQueryPool(cmd, p.queries, 0, 2 * dispatches);
    // After the previous frame's dispatches and any transfer (host writes are
    // made visible by the submission itself).
    memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    VkPipeline bound = VK_NULL_HANDLE;
    for (const Step& s : steps) {
      if (!s.dispatch) {
        memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
        continue;
      }
      const Dispatch& d = *s.dispatch;
      const Pipeline& pipe = pipelines_[static_cast<std::size_t>(d.kernel)];
      if (pipe.pipeline != bound) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, bound = pipe.pipeline);
      vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipe.layout, 0, 1, &sets[s.set], 0, nullptr);
      vkCmdPushConstants(cmd, pipe.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, d.params_bytes, d.params);
      const auto query = static_cast<std::uint32_t>(2 * p.timed.size());
      if (p.queries) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, p.queries, query);
      vkCmdDispatch(cmd, s.groups, 1, 1);
      if (p.queries) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, p.queries, query + 1);
      p.timed.push_back(d.kernel);
    }
    // Shader writes visible to read_buffer: mapped memory (host) or a staged copy (transfer).
    memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_HOST_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT);
    if (VkResult r = vkEndCommandBuffer(cmd); r != VK_SUCCESS) return vk_error("create_program: vkEndCommandBuffer", r);
    if (!p.queries) p.timed.clear();
    return {};
  }

  // [in] ticks: a difference of two timestamps (wraps at the counter's valid bits).
  double ticks_to_ms(std::uint64_t ticks) const {
    if (found_.timestamp_bits < 64) ticks &= (std::uint64_t{1} << found_.timestamp_bits) - 1;
    return static_cast<double>(ticks) * found_.properties.limits.timestampPeriod * 1e-6;
  }

  std::unique_ptr<Instance> instance_;  // destroyed last
  Found found_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool program_pool_ = VK_NULL_HANDLE;
  VkCommandPool transfer_pool_ = VK_NULL_HANDLE;
  VkCommandBuffer transfer_commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory_{};
  bool unified_ = false;     // buffers in host-visible device memory, mapped
  bool timestamps_ = false;  // timestamps around every dispatch
  mutable std::vector<std::uint64_t> stamps_;  // last_run_times' read-back, reused
  bool lost_ = false;
  std::array<VkDescriptorSetLayout, Dispatch::max_bindings + 1> set_layouts_{};  // by binding count
  std::array<Pipeline, static_cast<std::size_t>(Kernel::count_)> pipelines_{};
  std::vector<VkBuf> buffers_;
  VkBuf staging_;
  std::vector<Program> programs_;
  std::uint32_t last_run_ = UINT32_MAX;
};

}  // namespace

Result<std::vector<VulkanDeviceInfo>> list_vulkan_devices() {
  auto instance = make_instance();
  if (!instance) return instance.error();
  auto found = find_devices((*instance)->instance);
  if (!found) return found.error();
  std::vector<VulkanDeviceInfo> out;
  for (const Found& f : *found) out.push_back(f.info);
  return out;
}

Result<std::unique_ptr<Device>> make_vulkan_device(const DeviceOptions& options) {
  auto device = std::make_unique<VulkanDeviceImpl>();
  if (Status s = device->init(options); !s) return s.error();
  return std::unique_ptr<Device>(std::move(device));
}

std::uint64_t vulkan_validation_messages() { return g_validation_messages.load(std::memory_order_relaxed); }

Result<std::uint64_t> vulkan_validation_self_test(const DeviceOptions& options) {
  if (!validation_requested()) return Error("Vulkan validation is off (set SINEW_VULKAN_VALIDATION=1)");
  auto device = std::make_unique<VulkanDeviceImpl>();
  if (Status s = device->init(options); !s) return s.error();
  if (!device->validation())
    return Error(std::string("Vulkan validation is off: ") + kValidationLayer + " is not installed");
  return device->make_deliberate_mistake();
}

}  // namespace sinew
