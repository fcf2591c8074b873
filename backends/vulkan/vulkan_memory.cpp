// vulkan_memory.cpp — buffers, the staging buffer and the queue.
//
// Where the device shares memory with the host (a CPU device such as
// lavapipe, or an integrated GPU) and has host-visible, coherent,
// device-local memory, every buffer lives there, mapped once: write_buffer
// and read_buffer are memcpy. Otherwise buffers are device-local and copies
// go through one host-visible staging buffer (grown on demand) with a
// transfer command buffer and a fence wait. SINEW_VULKAN_STAGING=1 forces the
// staged path (to test it on a unified-memory device).
#include "backends/vulkan/vulkan_memory.h"

#include <algorithm>
#include <cstdlib>

#include "backends/vulkan/vulkan_common.h"

namespace sinew::vulkan {

// ------------------------------------------------------------ memory

void Memory::init(const Found& found, VkDevice device) {
  device_ = device;
  vkGetPhysicalDeviceMemoryProperties(found.physical, &memory_);
  const VkPhysicalDeviceType type = found.properties.deviceType;
  const char* staging = std::getenv("SINEW_VULKAN_STAGING");
  unified_ = (type == VK_PHYSICAL_DEVICE_TYPE_CPU || type == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU) &&
             !(staging && std::string(staging) == "1") && memory_type(~0u, kUnified, kUnified).ok();
}

void Memory::destroy() { destroy(staging_); }

Result<std::uint32_t> Memory::memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags required,
                                          VkMemoryPropertyFlags preferred) const {
  for (VkMemoryPropertyFlags want : {preferred, required})
    for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
      if ((type_bits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & want) == want) return i;
  return Error(ErrorCode::internal, "no memory type with properties " + std::to_string(required));
}

Status Memory::make_buffer(Buffer& b, VkBufferUsageFlags usage, VkMemoryPropertyFlags required,
                           VkMemoryPropertyFlags preferred, const std::string& what) {
  auto info = vk_struct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  info.size = b.size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  if (VkResult r = vkCreateBuffer(device_, &info, nullptr, &b.buffer); r != VK_SUCCESS) {
    b.buffer = VK_NULL_HANDLE;
    return vk_error(what + ": vkCreateBuffer (" + std::to_string(b.size) + " bytes)", r);
  }
  ++native_;
  VkMemoryRequirements needs{};
  vkGetBufferMemoryRequirements(device_, b.buffer, &needs);
  auto type = memory_type(needs.memoryTypeBits, required, preferred);
  if (!type) return Error(ErrorCode::internal, what + ": " + type.error().message());
  auto alloc = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
  alloc.allocationSize = needs.size;
  alloc.memoryTypeIndex = *type;
  if (VkResult r = vkAllocateMemory(device_, &alloc, nullptr, &b.memory); r != VK_SUCCESS) {
    b.memory = VK_NULL_HANDLE;
    return vk_error(what + ": vkAllocateMemory (" + std::to_string(needs.size) + " bytes)", r);
  }
  ++native_;
  if (VkResult r = vkBindBufferMemory(device_, b.buffer, b.memory, 0); r != VK_SUCCESS)
    return vk_error(what + ": vkBindBufferMemory", r);
  if (required & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
    if (VkResult r = vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped); r != VK_SUCCESS) {
      b.mapped = nullptr;
      return vk_error(what + ": vkMapMemory", r);
    }
  return {};
}

void Memory::destroy(Buffer& b) {
  if (b.buffer) {
    vkDestroyBuffer(device_, b.buffer, nullptr);
    --native_;
  }
  if (b.memory) {
    vkFreeMemory(device_, b.memory, nullptr);  // unmaps too
    --native_;
  }
  b = Buffer{};
}

std::uint32_t Memory::native() const {
  return native_ - (staging_.buffer ? 1 : 0) - (staging_.memory ? 1 : 0);
}

Status Memory::ensure_staging(std::size_t bytes, const std::string& what) {
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

// ------------------------------------------------------------ queue

Status Queue::init(VkDevice device, std::uint32_t queue_family) {
  device_ = device;
  vkGetDeviceQueue(device_, queue_family, 0, &queue_);
  auto pool_info = vk_struct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  pool_info.queueFamilyIndex = queue_family;
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
  return {};
}

void Queue::destroy() {
  if (fence_) vkDestroyFence(device_, fence_, nullptr);
  if (transfer_pool_) vkDestroyCommandPool(device_, transfer_pool_, nullptr);
  fence_ = VK_NULL_HANDLE;
  transfer_pool_ = VK_NULL_HANDLE;
  transfer_commands_ = VK_NULL_HANDLE;
}

Status Queue::submit(VkCommandBuffer commands, const std::string& what) {
  auto submit = vk_struct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands;
  const VkResult r = vkQueueSubmit(queue_, 1, &submit, fence_);
  if (r == VK_SUCCESS) {
    in_flight_ = true;
    return {};
  }
  lost_ = lost_ || r == VK_ERROR_DEVICE_LOST;
  return vk_error(what + ": vkQueueSubmit", r);
}

Status Queue::wait(const std::string& what) {
  if (!in_flight_) return {};
  VkResult r = vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX);
  in_flight_ = false;  // after a failure too: the device is lost, or the fence with it
  if (r != VK_SUCCESS) {
    lost_ = lost_ || r == VK_ERROR_DEVICE_LOST;
    return vk_error(what + ": vkWaitForFences", r);
  }
  r = vkResetFences(device_, 1, &fence_);
  if (r != VK_SUCCESS) return vk_error(what + ": vkResetFences", r);
  return {};
}

Status Queue::submit_and_wait(VkCommandBuffer commands, const std::string& what) {
  if (Status s = submit(commands, what); !s) return s;
  return wait(what);
}

Result<VkCommandBuffer> Queue::begin_transfer(const std::string& what) {
  if (VkResult r = vkResetCommandBuffer(transfer_commands_, 0); r != VK_SUCCESS)
    return vk_error(what + ": vkResetCommandBuffer", r);
  auto begin = vk_struct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if (VkResult r = vkBeginCommandBuffer(transfer_commands_, &begin); r != VK_SUCCESS)
    return vk_error(what + ": vkBeginCommandBuffer", r);
  memory_barrier(transfer_commands_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
  return transfer_commands_;
}

Status Queue::end_transfer(const std::string& what) {
  memory_barrier(transfer_commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                 VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT);
  if (VkResult r = vkEndCommandBuffer(transfer_commands_); r != VK_SUCCESS)
    return vk_error(what + ": vkEndCommandBuffer", r);
  return submit_and_wait(transfer_commands_, what);
}

}  // namespace sinew::vulkan
