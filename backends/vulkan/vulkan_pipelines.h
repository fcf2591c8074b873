// vulkan_pipelines.h — compute pipelines from the embedded SPIR-V
// (kernels/glsl, compiled by glslc at build time), one per kernel, made on
// first use, and the descriptor set layouts they share.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "backends/vulkan/vulkan_physical_device.h"
#include "backends/backend.h"

namespace sinew::vulkan {

/// local_size_x of every kernels/glsl kernel.
inline constexpr std::uint32_t kLocalSize = 64;

/// Generated from kernels/glsl by cmake/EmbedSpirv.cmake; empty when the kernel has no GLSL twin.
std::span<const std::uint32_t> embedded_spirv(std::string_view kernel);

struct Pipeline {
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
};

/// Owns the descriptor set layouts (one per binding count) and every
/// kernel's pipeline and pipeline layout.
class PipelineCache {
 public:
  PipelineCache() = default;
  PipelineCache(const PipelineCache&) = delete;
  PipelineCache& operator=(const PipelineCache&) = delete;

  /// [in] device: `found`'s logical device; outlives every call.
  void init(const Found& found, VkDevice device);
  /// Releases every pipeline, pipeline layout and set layout. [pre] the device is idle.
  void destroy();

  /// The set layout of `bindings` storage buffers, made on first use.
  Result<VkDescriptorSetLayout> set_layout(std::uint32_t bindings);
  /// The set layout of `bindings` storage buffers; VK_NULL_HANDLE until set_layout made it.
  VkDescriptorSetLayout made_set_layout(std::size_t bindings) const { return set_layouts_[bindings]; }

  /// The kernel's pipeline, made on first use. Errors: the kernel has no
  /// SPIR-V, binds more storage buffers than the device allows, a failed call.
  Result<const Pipeline*> pipeline(Kernel kernel);
  /// The kernel's pipeline; empty handles until pipeline(kernel) made it.
  const Pipeline& made_pipeline(Kernel kernel) const { return pipelines_[static_cast<std::size_t>(kernel)]; }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  std::uint32_t max_storage_buffers_ = 0;  // maxPerStageDescriptorStorageBuffers
  std::string device_name_;                // for errors
  std::array<VkDescriptorSetLayout, Dispatch::max_bindings + 1> set_layouts_{};  // by binding count
  std::array<Pipeline, static_cast<std::size_t>(Kernel::count_)> pipelines_{};
};

}  // namespace sinew::vulkan
