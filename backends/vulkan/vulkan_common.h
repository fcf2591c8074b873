// vulkan_common.h — what every file of the Vulkan backend uses: VkResult
// names and error codes for error messages, vk_struct (a zeroed struct with
// its sType) and the global memory barriers the backend records. Small
// enough to be inline, so each piece (instance, physical device, memory,
// buffers, pipelines, program plans, recording) needs only this header and its own.
#pragma once

#include <vulkan/vulkan.h>

#include <string>

#include "sinew/result.h"

namespace sinew::vulkan {

inline std::string result_name(VkResult r) {
  switch (r) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_INCOMPLETE: return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY (out of host memory)";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY (out of device memory)";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST (the device was lost: a driver reset, hang or crash)";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
      return "VK_ERROR_INCOMPATIBLE_DRIVER (no Vulkan 1.2 driver installed? e.g. apt-get install mesa-vulkan-drivers)";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FRAGMENTED_POOL: return "VK_ERROR_FRAGMENTED_POOL";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    case VK_ERROR_VALIDATION_FAILED_EXT: return "VK_ERROR_VALIDATION_FAILED_EXT";
    case VK_ERROR_UNKNOWN: return "VK_ERROR_UNKNOWN";
    default: return "VkResult " + std::to_string(static_cast<int>(r));
  }
}

/// The ErrorCode of a failed call's VkResult: out of host or device memory
/// -> out_of_memory, a lost device -> device_lost, no driver ->
/// backend_unavailable, anything else (bad handles, a bug) -> internal.
inline ErrorCode error_code(VkResult r) {
  switch (r) {
    case VK_ERROR_OUT_OF_HOST_MEMORY:
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return ErrorCode::out_of_memory;
    case VK_ERROR_DEVICE_LOST: return ErrorCode::device_lost;
    case VK_ERROR_INCOMPATIBLE_DRIVER: return ErrorCode::backend_unavailable;
    default: return ErrorCode::internal;
  }
}

/// "<call> failed: <result_name(r)>", with error_code(r).
inline Error vk_error(const std::string& call, VkResult r) {
  return Error(error_code(r), call + " failed: " + result_name(r));
}
/// The same, with `code` where error_code(r) would say internal (e.g.
/// backend_unavailable for a failure to open the device at all).
inline Error vk_error(const std::string& call, VkResult r, ErrorCode code) {
  const ErrorCode from_result = error_code(r);
  return Error(from_result == ErrorCode::internal ? code : from_result, call + " failed: " + result_name(r));
}

/// A Vulkan struct, zeroed, with its sType set.
template <class T>
T vk_struct(VkStructureType type) {
  T t{};
  t.sType = type;
  return t;
}

/// Records one global memory barrier (no buffer or image barriers).
inline void memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src_access,
                           VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) {
  auto barrier = vk_struct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  barrier.srcAccessMask = src_access;
  barrier.dstAccessMask = dst_access;
  vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

/// The stages a frame program's commands run in: dispatches (their shaders,
/// and the indirect-argument read of an indirect one), fills and copies.
inline constexpr VkPipelineStageFlags kWorkStages =
    VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;
/// Every write of those commands.
inline constexpr VkAccessFlags kWorkWrites = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
/// Every access of those commands.
inline constexpr VkAccessFlags kWorkAccesses = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                                               VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                                               VK_ACCESS_INDIRECT_COMMAND_READ_BIT;

/// A frame program's Barrier: every earlier dispatch, fill and copy (and
/// indirect-argument read) completes and its writes are visible to every
/// later one, whichever of them reads or writes.
inline void full_barrier(VkCommandBuffer cmd) {
  memory_barrier(cmd, kWorkStages, kWorkWrites, kWorkStages, kWorkAccesses);
}

}  // namespace sinew::vulkan
