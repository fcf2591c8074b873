// vulkan_buffers.cpp — the device's buffers. Each is its own VkBuffer and
// allocation of the size asked rounded up to 64 bytes (kernels may read a
// whole float4 at the end of any buffer): in mapped host-visible memory
// where the device shares memory with the host (copies are memcpy), else
// device-local with staged copies (vulkan_memory.cpp). A resize makes a new
// VkBuffer, copies the kept bytes over and frees the old one, so descriptor
// sets that pointed at it are stale: the generation tells programs to
// record again.
#include "backends/vulkan/vulkan_buffers.h"

#include <algorithm>
#include <cstring>

#include "backends/kernel_table.h"
#include "backends/vulkan/vulkan_common.h"

namespace sinew::vulkan {

void BufferTable::init(const Found& found, Memory& memory, Queue& queue) {
  found_ = &found;
  memory_ = &memory;
  queue_ = &queue;
}

void BufferTable::destroy() {
  for (Buffer& b : buffers_) memory_->destroy(b);
}

Status BufferTable::allocate(Buffer& b, const std::string& what) {
  b.size = (b.bytes + 63) / 64 * 64;
  const VkDeviceSize largest = found_->properties.limits.maxStorageBufferRange;
  if (b.size > largest)
    return Error(ErrorCode::out_of_memory, what + " (" + std::to_string(b.bytes) +
                                               " bytes): larger than the largest storage buffer of " +
                                               found_->info.name + " (" + std::to_string(largest) + " bytes)");
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  const bool unified = memory_->unified();
  Status s = unified ? memory_->make_buffer(b, usage, kUnified, kUnified | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, what)
                     : memory_->make_buffer(b, usage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                                            VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, what);
  if (s && unified) std::memset(b.mapped, 0, b.size);
  if (s && !unified)
    s = queue_->transfer(what + ": zero fill",
                         [&](VkCommandBuffer cmd) { vkCmdFillBuffer(cmd, b.buffer, 0, VK_WHOLE_SIZE, 0); });
  if (!s) memory_->destroy(b);
  return s;
}

Result<BufferHandle> BufferTable::create(std::size_t bytes, std::string_view label) {
  const std::string what = "create_buffer '" + std::string(label) + "'";
  if (bytes == 0) return Error(ErrorCode::internal, what + ": size must be > 0");
  Buffer b;
  b.label = label;
  b.bytes = bytes;
  if (Status s = allocate(b, what); !s) return s.error();
  buffers_.push_back(std::move(b));
  sizes_.push_back(bytes);
  return BufferHandle{static_cast<std::uint32_t>(buffers_.size() - 1)};
}

Result<Buffer*> BufferTable::live_buffer(BufferHandle buffer, const char* what) {
  if (buffer.id >= buffers_.size() || !buffers_[buffer.id].buffer)
    return Error(ErrorCode::internal, std::string(what) + ": not a live buffer of this device");
  return &buffers_[buffer.id];
}

Status BufferTable::destroy(BufferHandle buffer) {
  auto b = live_buffer(buffer, "destroy_buffer");
  if (!b) return b.status();
  memory_->destroy(**b);
  sizes_[buffer.id] = 0;
  ++generation_;  // programs binding it fail at their next recording
  return {};
}

Status BufferTable::resize(BufferHandle buffer, std::size_t bytes) {
  auto found = live_buffer(buffer, "resize_buffer");
  if (!found) return found.status();
  Buffer& old = **found;
  const std::string what = "resize_buffer '" + old.label + "'";
  if (bytes == 0) return Error(ErrorCode::internal, what + ": size must be > 0");
  Buffer b;
  b.label = old.label;
  b.bytes = bytes;
  if (Status s = allocate(b, what); !s) return s;  // zero-filled
  const std::size_t keep = std::min(bytes, old.bytes);
  if (b.mapped && old.mapped) {
    std::memcpy(b.mapped, old.mapped, keep);
  } else {
    const VkBufferCopy region{0, 0, keep};
    if (Status s = queue_->transfer(what + ": copying the contents",
                                    [&](VkCommandBuffer cmd) { vkCmdCopyBuffer(cmd, old.buffer, b.buffer, 1, &region); });
        !s) {
      memory_->destroy(b);
      return s;
    }
  }
  memory_->destroy(old);
  old = std::move(b);
  sizes_[buffer.id] = bytes;
  ++generation_;
  return {};
}

Status BufferTable::write(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) {
  auto found = live_buffer(buffer, "write_buffer");
  if (!found) return found.status();
  const Buffer& b = **found;
  if (Status s = check_buffer_range(b.label, b.bytes, offset, bytes, "write_buffer"); !s) return s;
  if (bytes == 0) return {};
  if (b.mapped) {  // nothing in flight: the device waited
    std::memcpy(static_cast<std::byte*>(b.mapped) + offset, data, bytes);
    return {};
  }
  const std::string what = "write_buffer '" + b.label + "'";
  if (Status s = memory_->ensure_staging(bytes, what); !s) return s;
  const Buffer& staging = memory_->staging();
  std::memcpy(staging.mapped, data, bytes);
  const VkBufferCopy region{0, offset, bytes};
  return queue_->transfer(what, [&](VkCommandBuffer cmd) { vkCmdCopyBuffer(cmd, staging.buffer, b.buffer, 1, &region); });
}

Status BufferTable::read(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) {
  auto found = live_buffer(buffer, "read_buffer");
  if (!found) return found.status();
  const Buffer& b = **found;
  if (Status s = check_buffer_range(b.label, b.bytes, offset, bytes, "read_buffer"); !s) return s;
  if (bytes == 0) return {};
  if (b.mapped) {
    std::memcpy(data, static_cast<const std::byte*>(b.mapped) + offset, bytes);
    return {};
  }
  const std::string what = "read_buffer '" + b.label + "'";
  if (Status s = memory_->ensure_staging(bytes, what); !s) return s;
  const Buffer& staging = memory_->staging();
  const VkBufferCopy region{offset, 0, bytes};
  if (Status s = queue_->transfer(what, [&](VkCommandBuffer cmd) { vkCmdCopyBuffer(cmd, b.buffer, staging.buffer, 1, &region); });
      !s)
    return s;
  std::memcpy(data, staging.mapped, bytes);
  return {};
}

std::uint32_t BufferTable::live() const {
  std::uint32_t n = 0;
  for (const Buffer& b : buffers_) n += b.buffer ? 1 : 0;
  return n;
}

std::uint64_t BufferTable::live_bytes() const {
  std::uint64_t n = 0;
  for (const Buffer& b : buffers_) n += b.buffer ? b.bytes : 0;
  return n;
}

}  // namespace sinew::vulkan
