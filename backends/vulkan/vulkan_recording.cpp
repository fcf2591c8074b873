// vulkan_recording.cpp — recording frame programs, and their timestamps.
//
// create_program records the whole frame once into a command buffer: per
// dispatch bind pipeline, descriptor set and push constants, then
// vkCmdDispatch(ceil(count / 64)); per Barrier one compute -> compute
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
#include "backends/vulkan/vulkan_recording.h"

#include <cstdlib>
#include <string>

#include "backends/vulkan/vulkan_common.h"

namespace sinew::vulkan {

Status Recorder::init(const Found& found, VkDevice device) {
  device_ = device;
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

void Recorder::destroy(Program& p) {
  if (p.commands) vkFreeCommandBuffers(device_, program_pool_, 1, &p.commands);
  if (p.pool) vkDestroyDescriptorPool(device_, p.pool, nullptr);
  if (p.queries) vkDestroyQueryPool(device_, p.queries, nullptr);
  p = Program{};
}

Result<std::vector<VkDescriptorSet>> Recorder::descriptor_sets(Program& p,
                                                               std::span<const std::vector<std::uint32_t>* const> set_buffers,
                                                               std::uint32_t descriptors, const PipelineCache& pipelines,
                                                               std::span<const Buffer> buffers) {
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
    for (const auto* bound : set_buffers) layouts.push_back(pipelines.made_set_layout(bound->size()));
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
        infos.push_back({buffers[(*set_buffers[s])[b]].buffer, 0, VK_WHOLE_SIZE});
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
  return sets;
}

Status Recorder::record(Program& p, std::span<const Step> steps,
                        std::span<const std::vector<std::uint32_t>* const> set_buffers, std::uint32_t descriptors,
                        const PipelineCache& pipelines, std::span<const Buffer> buffers) {
  auto made_sets = descriptor_sets(p, set_buffers, descriptors, pipelines, buffers);
  if (!made_sets) return made_sets.error();
  const std::vector<VkDescriptorSet>& sets = *made_sets;

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
    const Pipeline& pipe = pipelines.made_pipeline(d.kernel);
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

Status Recorder::read_times(const Program& p, DeviceTimes& out) const {
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

double Recorder::ticks_to_ms(std::uint64_t ticks) const {
  if (timestamp_bits_ < 64) ticks &= (std::uint64_t{1} << timestamp_bits_) - 1;
  return static_cast<double>(ticks) * timestamp_period_ * 1e-6;
}

}  // namespace sinew::vulkan
