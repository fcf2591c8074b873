// vulkan_device.cpp — the Vulkan compute backend: the sinew Device that glues
// the pieces together, and the backend's public functions.
//
// One instance, device and compute queue per sinew Device; every call that
// waits does so on one fence, so at most one submission is in flight. The
// pieces, each in the file named after its job:
//   vulkan_instance         the instance, the validation layer and its counter
//   vulkan_physical_device  which devices there are, which one to use
//   vulkan_memory           buffers, staging, the queue, fence and transfers
//   vulkan_pipelines        pipelines from the embedded SPIR-V, set layouts
//   vulkan_recording        frame programs recorded into command buffers, timestamps
// This file resolves a frame program into the steps to record and owns the
// buffers and programs the handles name.
#include "backends/vulkan/vulkan_device.h"

#include <vulkan/vulkan.h>

#include <cstring>
#include <map>
#include <variant>

#include "backends/kernel_table.h"
#include "backends/vulkan/vulkan_common.h"
#include "backends/vulkan/vulkan_instance.h"
#include "backends/vulkan/vulkan_memory.h"
#include "backends/vulkan/vulkan_physical_device.h"
#include "backends/vulkan/vulkan_pipelines.h"
#include "backends/vulkan/vulkan_recording.h"

namespace sinew {
namespace vulkan {

class VulkanDeviceImpl final : public Device {
 public:
  VulkanDeviceImpl() = default;
  VulkanDeviceImpl(const VulkanDeviceImpl&) = delete;
  VulkanDeviceImpl& operator=(const VulkanDeviceImpl&) = delete;

  ~VulkanDeviceImpl() override {
    if (!device_) return;
    vkDeviceWaitIdle(device_);
    for (Program& p : programs_) recorder_.destroy(p);
    pipelines_.destroy();
    for (Buffer& b : buffers_) memory_.destroy(b);
    memory_.destroy();
    queue_.destroy();
    recorder_.destroy();
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
    if (Status s = recorder_.init(found_, device_); !s) return s;  // the program command pool
    if (Status s = queue_.init(device_, found_.queue_family); !s) return s;
    memory_.init(found_, device_);
    pipelines_.init(found_, device_);
    return {};
  }

  std::string backend_name() const override { return "vulkan"; }
  std::string device_name() const override {
    return "Vulkan: " + found_.info.name + " (" + found_.info.type + ", " + found_.info.driver + ", Vulkan " +
           version_string(found_.info.api_version) + (memory_.unified() ? ", host-visible memory" : ", staged copies") +
           (instance_->validation ? ", validation on)" : ")");
  }

  Result<BufferHandle> create_buffer(std::size_t bytes, std::string_view label) override {
    const std::string what = "create_buffer '" + std::string(label) + "'";
    if (bytes == 0) return Error(what + ": size must be > 0");
    if (Status s = check_lost(what); !s) return s.error();
    Buffer b;
    b.label = label;
    b.bytes = bytes;
    b.size = (bytes + 63) / 64 * 64;  // kernels may read whole float4s at the end of any buffer
    if (b.size > found_.properties.limits.maxStorageBufferRange)
      return Error(what + " (" + std::to_string(bytes) + " bytes): larger than the largest storage buffer of " +
                   found_.info.name + " (" + std::to_string(found_.properties.limits.maxStorageBufferRange) + " bytes)");
    const VkBufferUsageFlags usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    const bool unified = memory_.unified();
    Status s = unified ? memory_.make_buffer(b, usage, kUnified, kUnified | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, what)
                       : memory_.make_buffer(b, usage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                                             VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, what);
    if (s && unified) std::memset(b.mapped, 0, b.size);
    if (s && !unified)
      s = queue_.transfer(what + ": zero fill",
                          [&](VkCommandBuffer cmd) { vkCmdFillBuffer(cmd, b.buffer, 0, VK_WHOLE_SIZE, 0); });
    if (!s) {
      memory_.destroy(b);
      return s.error();
    }
    buffers_.push_back(std::move(b));
    return BufferHandle{static_cast<std::uint32_t>(buffers_.size() - 1)};
  }

  Status write_buffer(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) override {
    if (Status s = check_range(buffer, offset, bytes, "write_buffer"); !s) return s;
    if (bytes == 0) return {};
    const Buffer& b = buffers_[buffer.id];
    const std::string what = "write_buffer '" + b.label + "'";
    if (Status s = check_lost(what); !s) return s;
    if (b.mapped) {  // no work is in flight between calls: every submission is waited for
      std::memcpy(static_cast<std::byte*>(b.mapped) + offset, data, bytes);
      return {};
    }
    if (Status s = memory_.ensure_staging(bytes, what); !s) return s;
    const Buffer& staging = memory_.staging();
    std::memcpy(staging.mapped, data, bytes);
    const VkBufferCopy region{0, offset, bytes};
    return queue_.transfer(what, [&](VkCommandBuffer cmd) { vkCmdCopyBuffer(cmd, staging.buffer, b.buffer, 1, &region); });
  }

  Status read_buffer(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) override {
    if (Status s = check_range(buffer, offset, bytes, "read_buffer"); !s) return s;
    if (bytes == 0) return {};
    const Buffer& b = buffers_[buffer.id];
    const std::string what = "read_buffer '" + b.label + "'";
    if (Status s = check_lost(what); !s) return s;
    if (b.mapped) {
      std::memcpy(data, static_cast<const std::byte*>(b.mapped) + offset, bytes);
      return {};
    }
    if (Status s = memory_.ensure_staging(bytes, what); !s) return s;
    const Buffer& staging = memory_.staging();
    const VkBufferCopy region{offset, 0, bytes};
    if (Status s = queue_.transfer(what, [&](VkCommandBuffer cmd) { vkCmdCopyBuffer(cmd, b.buffer, staging.buffer, 1, &region); });
        !s)
      return s;
    std::memcpy(data, staging.mapped, bytes);
    return {};
  }

  Result<ProgramHandle> create_program(const FrameProgram& program) override {
    if (Status s = check_program(program, static_cast<std::uint32_t>(buffers_.size())); !s) return s.error();
    if (Status s = check_lost("create_program"); !s) return s.error();
    // Resolve the commands: pipelines (made on first use), one descriptor
    // set per distinct tuple of bound buffers, barriers between dispatches only.
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
      auto pipe = pipelines_.pipeline(d->kernel);
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
    Status s = recorder_.record(p, steps, set_buffers, descriptors, pipelines_, buffers_);
    if (!s) {
      recorder_.destroy(p);
      return s.error();
    }
    programs_.push_back(std::move(p));
    return ProgramHandle{static_cast<std::uint32_t>(programs_.size() - 1)};
  }

  Status run_program(ProgramHandle program) override {
    if (program.id >= programs_.size()) return Error("run_program: not a program of this device");
    if (Status s = check_lost("run_program"); !s) return s;
    last_run_ = UINT32_MAX;
    if (Status s = queue_.submit_and_wait(programs_[program.id].commands, "run_program"); !s) return s;
    last_run_ = program.id;
    return {};
  }

  Status last_run_times(DeviceTimes& out) const override {
    out = {};
    if (last_run_ >= programs_.size() || !programs_[last_run_].queries) return {};
    return recorder_.read_times(programs_[last_run_], out);
  }

  bool validation() const { return instance_->validation; }

  // See vulkan_validation_self_test.
  std::uint64_t make_deliberate_mistake() { return vulkan::make_deliberate_mistake(device_); }

 private:
  Status check_range(BufferHandle buffer, std::size_t offset, std::size_t bytes, const char* what) const {
    if (buffer.id >= buffers_.size()) return Error(std::string(what) + ": not a buffer of this device");
    const Buffer& b = buffers_[buffer.id];
    return check_buffer_range(b.label, b.bytes, offset, bytes, what);
  }

  Status check_lost(const std::string& what) const {
    if (queue_.lost())
      return Error(what + ": the Vulkan device " + found_.info.name + " was lost earlier (VK_ERROR_DEVICE_LOST)");
    return {};
  }

  std::unique_ptr<Instance> instance_;  // destroyed last
  Found found_;
  VkDevice device_ = VK_NULL_HANDLE;
  // The pieces release what they own when the destructor says so: after
  // vkDeviceWaitIdle, before vkDestroyDevice.
  Recorder recorder_;        // the program command pool
  Queue queue_;              // the queue, fence and transfer command buffer
  Memory memory_;            // the staging buffer
  PipelineCache pipelines_;  // pipelines and set layouts
  std::vector<Buffer> buffers_;
  std::vector<Program> programs_;
  std::uint32_t last_run_ = UINT32_MAX;
};

}  // namespace vulkan

Result<std::vector<VulkanDeviceInfo>> list_vulkan_devices() {
  auto instance = vulkan::make_instance();
  if (!instance) return instance.error();
  auto found = vulkan::find_devices((*instance)->instance);
  if (!found) return found.error();
  std::vector<VulkanDeviceInfo> out;
  for (const vulkan::Found& f : *found) out.push_back(f.info);
  return out;
}

Result<std::unique_ptr<Device>> make_vulkan_device(const DeviceOptions& options) {
  auto device = std::make_unique<vulkan::VulkanDeviceImpl>();
  if (Status s = device->init(options); !s) return s.error();
  return std::unique_ptr<Device>(std::move(device));
}

std::uint64_t vulkan_validation_messages() { return vulkan::validation_messages(); }

Result<std::uint64_t> vulkan_validation_self_test(const DeviceOptions& options) {
  if (!vulkan::validation_requested()) return Error("Vulkan validation is off (set SINEW_VULKAN_VALIDATION=1)");
  auto device = std::make_unique<vulkan::VulkanDeviceImpl>();
  if (Status s = device->init(options); !s) return s.error();
  if (!device->validation())
    return Error(std::string("Vulkan validation is off: ") + vulkan::kValidationLayer + " is not installed");
  return device->make_deliberate_mistake();
}

}  // namespace sinew
