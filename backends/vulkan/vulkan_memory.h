// vulkan_memory.h — device memory and moving data to and from it: buffers
// (memory type choice, allocation, mapping, and the count of what is
// allocated), the staging buffer, the compute queue with its one fence
// (every submission signals it, so at most one is in flight), and the
// one-shot transfer command buffer.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "backends/vulkan/vulkan_physical_device.h"
#include "sinew/result.h"

namespace sinew::vulkan {

/// A VkBuffer and its own memory; released by Memory::destroy.
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;  // host-visible memory, mapped for the buffer's life
  VkDeviceSize size = 0;   // allocated (rounded up)
  std::size_t bytes = 0;   // asked for
  std::string label;
};

/// Memory shared with the host: every buffer lives there, mapped once.
inline constexpr VkMemoryPropertyFlags kUnified =
    VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
/// The staging buffer's memory.
inline constexpr VkMemoryPropertyFlags kStaging = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;

/// The device's memory types and the buffers made in them; owns the staging
/// buffer. Buffers it makes are the caller's, released with destroy(Buffer&).
class Memory {
 public:
  Memory() = default;
  Memory(const Memory&) = delete;
  Memory& operator=(const Memory&) = delete;

  /// Reads the memory types of `found` and decides unified() (device is
  /// `found`'s logical device and outlives every call).
  void init(const Found& found, VkDevice device);
  /// Releases the staging buffer. [pre] the device is idle.
  void destroy();

  /// Buffers live in host-visible, coherent, device-local memory, mapped
  /// (write_buffer and read_buffer are memcpy); else device-local with
  /// staged copies.
  bool unified() const { return unified_; }

  /// The first memory type allowed by `type_bits` with `preferred`, else with `required`.
  Result<std::uint32_t> memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags required,
                                    VkMemoryPropertyFlags preferred) const;

  /// [in,out] b: size set; gets its buffer and memory, mapped when `required`
  /// is host-visible. On error b may hold part of them: destroy it.
  Status make_buffer(Buffer& b, VkBufferUsageFlags usage, VkMemoryPropertyFlags required,
                     VkMemoryPropertyFlags preferred, const std::string& what);
  /// Releases b's buffer and memory (unmapping it) and empties b.
  void destroy(Buffer& b);

  /// VkBuffers and VkDeviceMemory allocations made and not yet released,
  /// leaving out the staging buffer (the device's own).
  std::uint32_t native() const;

  /// Grows the staging buffer to at least `bytes` (whole 64 KiB, at least 1 MiB).
  Status ensure_staging(std::size_t bytes, const std::string& what);
  const Buffer& staging() const { return staging_; }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory_{};
  bool unified_ = false;  // buffers in host-visible device memory, mapped
  std::uint32_t native_ = 0;  // VkBuffer and VkDeviceMemory objects alive
  Buffer staging_;
};

/// The compute queue, its one fence and the one-shot transfer command buffer
/// (and its pool). Remembers a lost device.
class Queue {
 public:
  Queue() = default;
  Queue(const Queue&) = delete;
  Queue& operator=(const Queue&) = delete;

  /// Gets queue 0 of `queue_family`; makes the transfer command pool and
  /// buffer and the fence. Errors name the failed call.
  Status init(VkDevice device, std::uint32_t queue_family);
  /// Releases the fence and the transfer pool. [pre] the device is idle.
  void destroy();

  /// A submission or wait returned VK_ERROR_DEVICE_LOST.
  bool lost() const { return lost_; }

  /// Submits `commands`, signalling the fence, and returns. [pre] nothing in flight.
  Status submit(VkCommandBuffer commands, const std::string& what);
  /// A submission signals the fence and has not been waited for.
  bool in_flight() const { return in_flight_; }
  /// Waits for the fence, then resets it; nothing in flight: returns at once.
  Status wait(const std::string& what);
  Status submit_and_wait(VkCommandBuffer commands, const std::string& what);

  /// Records `copy` between barriers that order it after every earlier
  /// dispatch and transfer and before every later one, submits, waits.
  /// [pre] nothing in flight.
  template <class Record>
  Status transfer(const std::string& what, Record copy) {
    auto cmd = begin_transfer(what);
    if (!cmd) return cmd.error();
    copy(*cmd);
    return end_transfer(what);
  }
  /// The first and second half of transfer: resets and begins the transfer
  /// command buffer with the opening barrier; the closing barrier, end, submit, wait.
  Result<VkCommandBuffer> begin_transfer(const std::string& what);
  Status end_transfer(const std::string& what);

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool transfer_pool_ = VK_NULL_HANDLE;
  VkCommandBuffer transfer_commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool in_flight_ = false;
  bool lost_ = false;
};

}  // namespace sinew::vulkan
