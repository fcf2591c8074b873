// vulkan_program.h — a frame program resolved into the steps the recorder
// records (vulkan_recording): pipelines made, work groups counted, one
// descriptor set per distinct tuple of bound buffers, each indirect
// dispatch given a slot of the program's indirect-arguments buffer and its
// `indirect_args` step, barriers only where they separate work.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "backends/backend.h"
#include "backends/vulkan/vulkan_pipelines.h"
#include "primitive_params.h"

namespace sinew::vulkan {

/// In a descriptor set's buffer ids: the program's own indirect-arguments buffer.
inline constexpr std::uint32_t kArgsBufferId = UINT32_MAX - 1;

/// One thing to record.
struct Step {
  enum class Kind {
    dispatch,       // a dispatch of the program: direct (groups) or indirect (slot)
    indirect_args,  // the built-in indirect_args kernel over one item, filling `slot`
    args_barrier,   // indirect_args writes -> indirect-command reads
    barrier,        // a Barrier of the program (full_barrier)
    fill,           // vkCmdFillBuffer of buffer `target`
    copy,           // vkCmdCopyBuffer from `source` to `target`
  };
  Kind kind = Kind::barrier;
  const Dispatch* dispatch = nullptr;  // dispatch: the program's command
  std::uint32_t set = 0;               // dispatch, indirect_args: index into Plan::sets
  std::uint32_t groups = 0;            // direct dispatch: work groups
  std::uint32_t slot = UINT32_MAX;     // indirect dispatch, indirect_args: 3-word slot of the args buffer
  kernels::IndirectArgsParams args{};  // indirect_args: its parameters
  std::uint32_t source = 0, target = 0;  // fill, copy: buffer ids
  std::uint64_t source_offset = 0, target_offset = 0, bytes = 0;  // fill, copy: in bytes
  std::uint32_t value = 0;                                        // fill
};

/// A frame program ready to record.
struct Plan {
  std::vector<Step> steps;
  std::vector<std::vector<std::uint32_t>> sets;  // per descriptor set, the buffer ids it binds in order
  std::uint32_t descriptors = 0;                 // over every set
  std::uint32_t slots = 0;                       // indirect dispatches (3 words of args each)
  std::uint32_t dispatches = 0;                  // dispatch steps (two timestamps each)
};

/// Resolves `program` (its commands outlive the plan). [pre] check_program
/// passed. Errors: a kernel without a pipeline here, more work groups than
/// the device dispatches at once (both backend_unavailable), a failed call.
Result<Plan> plan_program(const FrameProgram& program, PipelineCache& pipelines, const VkPhysicalDeviceLimits& limits,
                          const std::string& device_name);

}  // namespace sinew::vulkan
