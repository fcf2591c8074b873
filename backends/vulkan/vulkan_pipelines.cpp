// vulkan_pipelines.cpp — pipeline creation. One pipeline per kernel, made on
// first use from the embedded SPIR-V (so a device makes only the kernels its
// scenes dispatch). Its layout: one descriptor set of the kernel's storage
// buffers (set layouts shared by binding count) and a push-constant range of
// its parameter struct.
#include "backends/vulkan/vulkan_pipelines.h"

#include <algorithm>

#include "backends/kernel_table.h"
#include "backends/vulkan/vulkan_common.h"

namespace sinew::vulkan {

void PipelineCache::init(const Found& found, VkDevice device) {
  device_ = device;
  max_storage_buffers_ = found.properties.limits.maxPerStageDescriptorStorageBuffers;
  max_group_size_ = std::min(found.properties.limits.maxComputeWorkGroupSize[0],
                             found.properties.limits.maxComputeWorkGroupInvocations);
  device_name_ = found.info.name;
}

void PipelineCache::destroy() {
  for (Pipeline& p : pipelines_) {
    if (p.pipeline) vkDestroyPipeline(device_, p.pipeline, nullptr);
    if (p.layout) vkDestroyPipelineLayout(device_, p.layout, nullptr);
    p = Pipeline{};
  }
  for (VkDescriptorSetLayout& l : set_layouts_) {
    if (l) vkDestroyDescriptorSetLayout(device_, l, nullptr);
    l = VK_NULL_HANDLE;
  }
}

Result<VkDescriptorSetLayout> PipelineCache::set_layout(std::uint32_t bindings) {
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

Result<const Pipeline*> PipelineCache::pipeline(Kernel kernel) {
  Pipeline& p = pipelines_[static_cast<std::size_t>(kernel)];
  if (p.pipeline) return &p;
  const KernelSignature& sig = kernel_signature(kernel);
  const std::string name(sig.name);
  const std::span<const std::uint32_t> spirv = embedded_spirv(sig.name);
  // Only when the build is out of step with the kernel registry (a test
  // makes every kernel's pipeline): an error, not a skipped test.
  if (spirv.empty()) return Error(ErrorCode::internal, "the embedded SPIR-V has no kernel " + name);
  if (sig.bindings > max_storage_buffers_)
    return Error(ErrorCode::backend_unavailable, "kernel " + name + " binds " + std::to_string(sig.bindings) +
                                                     " storage buffers; " + device_name_ + " allows " +
                                                     std::to_string(max_storage_buffers_));
  if (launch_group_size(kernel) > max_group_size_)
    return Error(ErrorCode::backend_unavailable, "kernel " + name + " runs in groups of " +
                                                     std::to_string(launch_group_size(kernel)) + "; " + device_name_ +
                                                     " allows at most " + std::to_string(max_group_size_));
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

}  // namespace sinew::vulkan
