// vulkan_recording.h — a frame program recorded once into a command buffer
// (its descriptor pool and sets, indirect-arguments and counter read-back
// buffers, barriers, fills, copies and dispatches) and replayed by every
// submission; the counters and timestamps read after it.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <vector>

#include "backends/backend.h"
#include "backends/vulkan/vulkan_memory.h"
#include "backends/vulkan/vulkan_physical_device.h"
#include "backends/vulkan/vulkan_pipelines.h"
#include "backends/vulkan/vulkan_program.h"

namespace sinew::vulkan {

/// What a recorded frame program holds; released by Recorder::destroy.
struct Recording {
  VkCommandBuffer commands = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkQueryPool queries = VK_NULL_HANDLE;  // two timestamps per dispatch
  std::vector<Kernel> timed;             // the kernel of each timed dispatch
  Buffer args;                           // indirect dispatch arguments: 3 words per slot
  Buffer readback;                       // host-visible, mapped: one word per counter, then the end reads
  std::uint32_t counters = 0;            // words of readback the counters take
  std::uint32_t end_words = 0;           // words of readback the end reads take, after the counters
};

/// Owns the command pool of every program's command buffer; records
/// programs, reads their counters and timestamps.
class Recorder {
 public:
  Recorder() = default;
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Decides timestamps() ($SINEW_VULKAN_TIMESTAMPS, the device type, its
  /// queue) and makes the program command pool ([in] device: `found`'s
  /// logical device; memory makes the recordings' buffers; both outlive
  /// every call).
  Status init(const Found& found, VkDevice device, Memory& memory);
  /// Releases the command pool. [pre] every recording destroyed, the device idle.
  void destroy();

  /// Timestamps around every dispatch.
  bool timestamps() const { return timestamps_; }

  /// Makes r's buffers, descriptor pool and sets and query pool, and
  /// records its command buffer. [in] plan: from plan_program (its
  /// pipelines made by `pipelines`); counters and end_reads: the
  /// program's, read back at the end of the recording; buffers: the
  /// device's, by id. On error r may hold part of what it needs: destroy it.
  Status record(Recording& r, const Plan& plan, std::span<const Counter> counters, std::span<const EndRead> end_reads,
                const PipelineCache& pipelines, std::span<const Buffer> buffers);
  /// Releases everything r holds and empties it. [pre] r is not in flight.
  void destroy(Recording& r);

  /// [out] values: the counters as r's last run left them. [pre] that run waited for.
  void read_counters(const Recording& r, std::vector<std::uint32_t>& values) const;
  /// [out] values: the end reads as r's last run left them. [pre] that run waited for.
  void read_end_reads(const Recording& r, std::vector<std::uint32_t>& values) const;
  /// [out] out: the device time of r's last run from its timestamps (timed =
  /// false where r has none). [pre] that run waited for.
  Status read_times(const Recording& r, DeviceTimes& out);
  /// [in] ticks: a difference of two timestamps (wraps at the counter's valid bits).
  double ticks_to_ms(std::uint64_t ticks) const;

  /// Command buffers, descriptor pools and query pools of live recordings.
  std::uint32_t native() const { return native_; }

 private:
  Status make_buffers(Recording& r, const Plan& plan, std::size_t counters, std::size_t end_words);
  Result<std::vector<VkDescriptorSet>> descriptor_sets(Recording& r, const Plan& plan, const PipelineCache& pipelines,
                                                       std::span<const Buffer> buffers);
  void record_steps(const Recording& r, VkCommandBuffer cmd, const Plan& plan, std::span<const VkDescriptorSet> sets,
                    const PipelineCache& pipelines, std::span<const Buffer> buffers, std::vector<Kernel>& timed);
  void record_counter_reads(const Recording& r, VkCommandBuffer cmd, std::span<const Counter> counters,
                            std::span<const EndRead> end_reads, std::span<const Buffer> buffers);

  VkDevice device_ = VK_NULL_HANDLE;
  Memory* memory_ = nullptr;
  VkCommandPool program_pool_ = VK_NULL_HANDLE;
  bool timestamps_ = false;  // timestamps around every dispatch
  std::uint32_t timestamp_bits_ = 0;
  float timestamp_period_ = 0.0f;      // ns per tick
  std::uint32_t native_ = 0;           // see native()
  std::vector<std::uint64_t> stamps_;  // read_times' read-back, reused
};

}  // namespace sinew::vulkan
