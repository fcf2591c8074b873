// vulkan_buffers.h — the buffers a Vulkan device's handles name: creating,
// destroying and resizing them (ids never reused; a generation counter that
// every resize and destroy bumps, so programs know to record again), and
// copies between them and the host (mapped memory, or staged transfers).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "backends/backend.h"
#include "backends/vulkan/vulkan_memory.h"
#include "backends/vulkan/vulkan_physical_device.h"

namespace sinew::vulkan {

/// Every buffer a device made, by id (destroyed ones stay as empty entries).
/// Calls that use the queue (staged copies, a resize) need nothing in
/// flight: the device waits first.
class BufferTable {
 public:
  BufferTable() = default;
  BufferTable(const BufferTable&) = delete;
  BufferTable& operator=(const BufferTable&) = delete;

  /// [in] found, memory, queue: the device's; outlive every call.
  void init(const Found& found, Memory& memory, Queue& queue);
  /// Releases every buffer. [pre] the device is idle.
  void destroy();

  /// A zero-filled buffer of `bytes` (> 0) bytes.
  Result<BufferHandle> create(std::size_t bytes, std::string_view label);
  /// Frees the buffer; its id stays unused.
  Status destroy(BufferHandle buffer);
  /// A new VkBuffer and memory of `bytes` (> 0), holding the first
  /// min(old, new) bytes of the old one and zeros after; the old one freed.
  Status resize(BufferHandle buffer, std::size_t bytes);
  Status write(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes);
  Status read(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes);

  /// The buffers by id (destroyed: no VkBuffer).
  std::span<const Buffer> all() const { return buffers_; }
  /// Bytes asked for, by id; 0 for destroyed ones (check_program).
  std::span<const std::size_t> sizes() const { return sizes_; }
  /// Bumped by every resize and destroy.
  std::uint64_t generation() const { return generation_; }
  /// Live buffers and the bytes asked for them.
  std::uint32_t live() const;
  std::uint64_t live_bytes() const;

 private:
  Result<Buffer*> live_buffer(BufferHandle buffer, const char* what);
  // [in,out] b: label, bytes set; gets its VkBuffer and memory, zero-filled.
  Status allocate(Buffer& b, const std::string& what);

  const Found* found_ = nullptr;
  Memory* memory_ = nullptr;
  Queue* queue_ = nullptr;
  std::vector<Buffer> buffers_;
  std::vector<std::size_t> sizes_;
  std::uint64_t generation_ = 0;
};

}  // namespace sinew::vulkan
