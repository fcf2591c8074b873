// vulkan_recording.cpp — recording frame programs; their counters and timestamps.
//
// A frame program is recorded once into a command buffer (again only after
// a buffer it may bind was resized or destroyed) and every submission
// replays it. Descriptor sets are allocated and written at recording time,
// one per distinct tuple of bound buffers (vulkan_program.cpp), from the
// program's own descriptor pool.
//
// Commands. A dispatch binds its pipeline, descriptor set and push
// constants (its parameter struct) and launches ceil(count /
// launch_group_size(kernel)) groups; a Fill is vkCmdFillBuffer and a Copy
// vkCmdCopyBuffer (offsets and sizes in words * 4). A Barrier is one global
// memory barrier from every stage a command runs in (compute shader,
// transfer, indirect-command read) to all of them, covering shader and
// transfer writes against every later read or write (full_barrier). The
// recording opens with the same barrier, which orders it after the previous
// submission and the transfers of write_buffer (host writes are made
// visible by the submission itself).
//
// Indirect dispatch (a dispatch whose count is a counter word, read when it
// runs; `count` is its capacity) is a true vkCmdDispatchIndirect. Each
// indirect dispatch of a program owns a 3-word slot of the program's
// indirect-arguments buffer (STORAGE | INDIRECT_BUFFER usage). The segment
// of the program holding it (the commands between two barriers) is
// preceded by one dispatch of the built-in registry kernel indirect_args
// per indirect dispatch: over one item, binding the counter's buffer and
// the arguments buffer, with IndirectArgsParams {counter word, capacity,
// launch_group_size(kernel), 3 * slot}; it writes (ceil(min(count,
// capacity) / group size), 1, 1) into the slot. Then one barrier (shader
// writes -> indirect-command reads, DRAW_INDIRECT stage), and in the
// segment vkCmdDispatchIndirect(args, 12 * slot). So an indirect dispatch
// launches exactly the groups that cover its count, never more than its
// capacity's, and the kernel still guards items past the count itself.
// The counter must have been written before the barrier that precedes the
// segment (the contract of FrameProgram::dispatch_indirect).
//
// Counters. At the end of the recording a barrier (shader and transfer
// writes -> transfer reads) precedes one vkCmdCopyBuffer per declared
// counter word into the program's read-back buffer (host-visible, coherent,
// mapped), and the closing barrier makes every write of the frame visible
// to the host (transfer and shader writes -> host reads). So wait() reads
// the counters from mapped memory once the fence has signalled, with no
// extra submission.
//
// Timestamps (when the queue has them) are written before and after every
// dispatch of the program (not around the built-in indirect_args ones) and
// read when a submission is waited for. On a CPU device (lavapipe) each one
// costs a flush of the rasterizer threads, tens of microseconds, so there
// they are off unless SINEW_VULKAN_TIMESTAMPS=1; SINEW_VULKAN_TIMESTAMPS=0
// turns them off everywhere.
#include "backends/vulkan/vulkan_recording.h"

#include <cstdlib>
#include <cstring>
#include <string>

#include "backends/kernel_table.h"
#include "backends/vulkan/vulkan_common.h"

namespace sinew::vulkan {

Status Recorder::init(const Found& found, VkDevice device, Memory& memory) {
  device_ = device;
  memory_ = &memory;
  const VkPhysicalDeviceType type = found.properties.deviceType;
  const char* stamps = std::getenv("SINEW_VULKAN_TIMESTAMPS");
  timestamps_ = found.timestamps && (stamps && *stamps ? std::string(stamps) != "0" : type != VK_PHYSICAL_DEVICE_TYPE_CPU);
  timestamp_bits_ = found.timestamp_bits;
  timestamp_period_ = found.properties.limits.timestampPeriod;
  auto pool_info = vk_struct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  pool_info.queueFamilyIndex = found.queue_family;
  if (VkResult r = vkCreateCommandPool(device_, &pool_info, nullptr, &program_pool_); r != VK_SUCCESS)
    return vk_error("vkCreateCommandPool", r);
  return {};
}

void Recorder::destroy() {
  if (program_pool_) vkDestroyCommandPool(device_, program_pool_, nullptr);
  program_pool_ = VK_NULL_HANDLE;
}

void Recorder::destroy(Recording& r) {
  if (r.commands) {
    vkFreeCommandBuffers(device_, program_pool_, 1, &r.commands);
    --native_;
  }
  if (r.pool) {
    vkDestroyDescriptorPool(device_, r.pool, nullptr);  // frees its sets
    --native_;
  }
  if (r.queries) {
    vkDestroyQueryPool(device_, r.queries, nullptr);
    --native_;
  }
  memory_->destroy(r.args);
  memory_->destroy(r.readback);
  r = Recording{};
}

Status Recorder::make_buffers(Recording& r, const Plan& plan, std::size_t counters, std::size_t end_words) {
  if (plan.slots > 0) {
    r.args.label = "indirect arguments";
    r.args.size = (std::uint64_t{plan.slots} * 12 + 63) / 64 * 64;
    r.args.bytes = r.args.size;
    if (Status s = memory_->make_buffer(r.args, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                                        0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "recording the frame program: indirect arguments");
        !s)
      return s;
  }
  r.counters = static_cast<std::uint32_t>(counters);
  r.end_words = static_cast<std::uint32_t>(end_words);
  if (counters + end_words > 0) {
    r.readback.label = "counter read-back";
    r.readback.size = ((counters + end_words) * 4 + 63) / 64 * 64;
    r.readback.bytes = r.readback.size;
    if (Status s = memory_->make_buffer(r.readback, VK_BUFFER_USAGE_TRANSFER_DST_BIT, kStaging,
                                        kStaging | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, "recording the frame program: counter read-back");
        !s)
      return s;
    std::memset(r.readback.mapped, 0, r.readback.size);
  }
  return {};
}

Result<std::vector<VkDescriptorSet>> Recorder::descriptor_sets(Recording& r, const Plan& plan,
                                                               const PipelineCache& pipelines,
                                                               std::span<const Buffer> buffers) {
  std::vector<VkDescriptorSet> sets(plan.sets.size());
  if (sets.empty()) return sets;
  const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, plan.descriptors};
  auto info = vk_struct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
  info.maxSets = static_cast<std::uint32_t>(sets.size());
  info.poolSizeCount = 1;
  info.pPoolSizes = &size;
  if (VkResult res = vkCreateDescriptorPool(device_, &info, nullptr, &r.pool); res != VK_SUCCESS) {
    r.pool = VK_NULL_HANDLE;
    return vk_error("recording the frame program: vkCreateDescriptorPool", res);
  }
  ++native_;
  std::vector<VkDescriptorSetLayout> layouts;
  for (const auto& bound : plan.sets) layouts.push_back(pipelines.made_set_layout(bound.size()));
  auto alloc = vk_struct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
  alloc.descriptorPool = r.pool;
  alloc.descriptorSetCount = static_cast<std::uint32_t>(layouts.size());
  alloc.pSetLayouts = layouts.data();
  if (VkResult res = vkAllocateDescriptorSets(device_, &alloc, sets.data()); res != VK_SUCCESS)
    return vk_error("recording the frame program: vkAllocateDescriptorSets", res);
  std::vector<VkDescriptorBufferInfo> infos;
  infos.reserve(plan.descriptors);  // the writes point into it
  std::vector<VkWriteDescriptorSet> writes;
  for (std::size_t s = 0; s < sets.size(); ++s) {
    for (std::size_t b = 0; b < plan.sets[s].size(); ++b) {
      const std::uint32_t id = plan.sets[s][b];
      infos.push_back({id == kArgsBufferId ? r.args.buffer : buffers[id].buffer, 0, VK_WHOLE_SIZE});
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
  return sets;
}

Status Recorder::record(Recording& r, const Plan& plan, std::span<const Counter> counters,
                        std::span<const EndRead> end_reads, const PipelineCache& pipelines,
                        std::span<const Buffer> buffers) {
  std::size_t end_words = 0;
  for (const EndRead& e : end_reads) end_words += e.words;
  if (Status s = make_buffers(r, plan, counters.size(), end_words); !s) return s;
  auto made_sets = descriptor_sets(r, plan, pipelines, buffers);
  if (!made_sets) return made_sets.error();

  if (timestamps_ && plan.dispatches > 0) {
    auto info = vk_struct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = 2 * plan.dispatches;
    if (VkResult res = vkCreateQueryPool(device_, &info, nullptr, &r.queries); res != VK_SUCCESS) {
      r.queries = VK_NULL_HANDLE;
      return vk_error("recording the frame program: vkCreateQueryPool", res);
    }
    ++native_;
  }

  auto alloc = vk_struct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  alloc.commandPool = program_pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  if (VkResult res = vkAllocateCommandBuffers(device_, &alloc, &r.commands); res != VK_SUCCESS) {
    r.commands = VK_NULL_HANDLE;
    return vk_error("recording the frame program: vkAllocateCommandBuffers", res);
  }
  ++native_;
  const VkCommandBuffer cmd = r.commands;
  const auto begin = vk_struct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  if (VkResult res = vkBeginCommandBuffer(cmd, &begin); res != VK_SUCCESS)
    return vk_error("recording the frame program: vkBeginCommandBuffer", res);
  if (r.queries) vkCmdResetQueryPool(cmd, r.queries, 0, 2 * plan.dispatches);
  full_barrier(cmd);  // after the previous submission and any transfer
  std::vector<Kernel> timed;
  record_steps(r, cmd, plan, *made_sets, pipelines, buffers, timed);
  record_counter_reads(r, cmd, counters, end_reads, buffers);
  // Every write of the frame visible to the host: read_buffer of mapped
  // memory, the counters (staged reads and later frames order themselves
  // with their own opening barriers).
  memory_barrier(cmd, kWorkStages, kWorkWrites, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  if (VkResult res = vkEndCommandBuffer(cmd); res != VK_SUCCESS)
    return vk_error("recording the frame program: vkEndCommandBuffer", res);
  if (r.queries) r.timed = std::move(timed);
  return {};
}

void Recorder::record_steps(const Recording& r, VkCommandBuffer cmd, const Plan& plan,
                            std::span<const VkDescriptorSet> sets, const PipelineCache& pipelines,
                            std::span<const Buffer> buffers, std::vector<Kernel>& timed) {
  VkPipeline bound = VK_NULL_HANDLE;
  auto bind = [&](Kernel kernel, std::uint32_t set, const void* params, std::uint32_t params_bytes) {
    const Pipeline& pipe = pipelines.made_pipeline(kernel);
    if (pipe.pipeline != bound) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, bound = pipe.pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipe.layout, 0, 1, &sets[set], 0, nullptr);
    vkCmdPushConstants(cmd, pipe.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, params_bytes, params);
  };
  for (const Step& s : plan.steps) {
    switch (s.kind) {
      case Step::Kind::barrier: full_barrier(cmd); break;
      case Step::Kind::args_barrier:
        memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
        break;
      case Step::Kind::fill: vkCmdFillBuffer(cmd, buffers[s.target].buffer, s.target_offset, s.bytes, s.value); break;
      case Step::Kind::copy: {
        const VkBufferCopy region{s.source_offset, s.target_offset, s.bytes};
        vkCmdCopyBuffer(cmd, buffers[s.source].buffer, buffers[s.target].buffer, 1, &region);
        break;
      }
      case Step::Kind::indirect_args:
        bind(Kernel::indirect_args, s.set, &s.args, sizeof s.args);
        vkCmdDispatch(cmd, 1, 1, 1);
        break;
      case Step::Kind::dispatch: {
        const Dispatch& d = *s.dispatch;
        bind(d.kernel, s.set, d.params, d.params_bytes);
        const auto query = static_cast<std::uint32_t>(2 * timed.size());
        if (r.queries) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, r.queries, query);
        if (s.slot != UINT32_MAX) vkCmdDispatchIndirect(cmd, r.args.buffer, VkDeviceSize{12} * s.slot);
        else vkCmdDispatch(cmd, s.groups, 1, 1);
        if (r.queries) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, r.queries, query + 1);
        timed.push_back(d.kernel);
        break;
      }
    }
  }
}

void Recorder::record_counter_reads(const Recording& r, VkCommandBuffer cmd, std::span<const Counter> counters,
                                    std::span<const EndRead> end_reads, std::span<const Buffer> buffers) {
  if (counters.empty() && end_reads.empty()) return;
  memory_barrier(cmd, kWorkStages, kWorkWrites, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  for (std::size_t c = 0; c < counters.size(); ++c) {
    const VkBufferCopy region{VkDeviceSize{counters[c].word} * 4, VkDeviceSize{c} * 4, 4};
    vkCmdCopyBuffer(cmd, buffers[counters[c].buffer.id].buffer, r.readback.buffer, 1, &region);
  }
  VkDeviceSize at = VkDeviceSize{r.counters} * 4;
  for (const EndRead& e : end_reads) {
    const VkBufferCopy region{VkDeviceSize{e.word} * 4, at, VkDeviceSize{e.words} * 4};
    vkCmdCopyBuffer(cmd, buffers[e.buffer.id].buffer, r.readback.buffer, 1, &region);
    at += region.size;
  }
}

void Recorder::read_counters(const Recording& r, std::vector<std::uint32_t>& values) const {
  values.resize(r.counters);
  if (r.counters) std::memcpy(values.data(), r.readback.mapped, std::size_t{r.counters} * 4);
}

void Recorder::read_end_reads(const Recording& r, std::vector<std::uint32_t>& values) const {
  values.resize(r.end_words);
  if (r.end_words)
    std::memcpy(values.data(), static_cast<const std::uint32_t*>(r.readback.mapped) + r.counters,
                std::size_t{r.end_words} * 4);
}

Status Recorder::read_times(const Recording& r, DeviceTimes& out) {
  out = {};
  if (!r.queries || r.timed.empty()) return {};
  // Two timestamps per dispatch, read into storage kept between frames.
  stamps_.resize(2 * r.timed.size());
  const VkResult res = vkGetQueryPoolResults(device_, r.queries, 0, static_cast<std::uint32_t>(stamps_.size()),
                                             stamps_.size() * sizeof(std::uint64_t), stamps_.data(),
                                             sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
  if (res != VK_SUCCESS) return vk_error("vkGetQueryPoolResults", res);
  out.timed = true;
  out.span_ms = ticks_to_ms(stamps_.back() - stamps_.front());
  for (std::size_t i = 0; i < r.timed.size(); ++i) {
    const auto k = static_cast<std::size_t>(r.timed[i]);
    out.kernel_ms[k] += ticks_to_ms(stamps_[2 * i + 1] - stamps_[2 * i]);
    ++out.dispatches[k];
  }
  return {};
}

double Recorder::ticks_to_ms(std::uint64_t ticks) const {
  if (timestamp_bits_ < 64) ticks &= (std::uint64_t{1} << timestamp_bits_) - 1;
  return static_cast<double>(ticks) * timestamp_period_ * 1e-6;
}

}  // namespace sinew::vulkan
