// vulkan_recording.h — a frame program recorded once into a command buffer
// (its descriptor pool and sets, barriers and dispatches) and replayed by
// every run_program; and the timestamps written around its dispatches.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <vector>

#include "backends/vulkan/vulkan_memory.h"
#include "backends/vulkan/vulkan_physical_device.h"
#include "backends/vulkan/vulkan_pipelines.h"
#include "backends/backend.h"

namespace sinew::vulkan {

/// One step of a recording: a dispatch, or a barrier between dispatches.
struct Step {
  const Dispatch* dispatch = nullptr;  // nullptr: a barrier
  std::uint32_t set = 0;               // index into the descriptor sets (set_buffers of record)
  std::uint32_t groups = 0;            // work groups
};

/// A recorded frame program; released by Recorder::destroy.
struct Program {
  VkCommandBuffer commands = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkQueryPool queries = VK_NULL_HANDLE;  // two timestamps per dispatch
  std::vector<Kernel> timed;             // the kernel of each timed dispatch
};

/// Owns the command pool of every program's command buffer; records
/// programs, reads their timestamps.
class Recorder {
 public:
  Recorder() = default;
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Decides timestamps() ($SINEW_VULKAN_TIMESTAMPS, the device type, its
  /// queue) and makes the program command pool ([in] device: `found`'s
  /// logical device; outlives every call).
  Status init(const Found& found, VkDevice device);
  /// Releases the command pool. [pre] every program destroyed, the device idle.
  void destroy();

  /// Timestamps around every dispatch.
  bool timestamps() const { return timestamps_; }

  /// Allocates and writes the program's descriptor sets and records its
  /// command buffer. [in] steps: dispatches and the barriers between them,
  /// their pipelines made by `pipelines`; set_buffers: per descriptor set, the
  /// indices into `buffers` it binds (its layout made by `pipelines`);
  /// descriptors: their total count. On error p may hold part of what it
  /// needs: destroy it.
  Status record(Program& p, std::span<const Step> steps, std::span<const std::vector<std::uint32_t>* const> set_buffers,
                std::uint32_t descriptors, const PipelineCache& pipelines, std::span<const Buffer> buffers);
  /// Releases p's command buffer, descriptor pool and query pool and empties p.
  void destroy(Program& p);

  /// [out] out: the device time of p's last run from its timestamps; [pre]
  /// out zeroed, p.queries made, p's last submission waited for.
  Status read_times(const Program& p, DeviceTimes& out) const;
  /// [in] ticks: a difference of two timestamps (wraps at the counter's valid bits).
  double ticks_to_ms(std::uint64_t ticks) const;

 private:
  Result<std::vector<VkDescriptorSet>> descriptor_sets(Program& p,
                                                       std::span<const std::vector<std::uint32_t>* const> set_buffers,
                                                       std::uint32_t descriptors, const PipelineCache& pipelines,
                                                       std::span<const Buffer> buffers);

  VkDevice device_ = VK_NULL_HANDLE;
  VkCommandPool program_pool_ = VK_NULL_HANDLE;
  bool timestamps_ = false;  // timestamps around every dispatch
  std::uint32_t timestamp_bits_ = 0;
  float timestamp_period_ = 0.0f;              // ns per tick
  mutable std::vector<std::uint64_t> stamps_;  // read_times' read-back, reused
};

}  // namespace sinew::vulkan
