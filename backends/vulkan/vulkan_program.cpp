// vulkan_program.cpp — resolving a frame program into recording steps.
//
// The program is cut into segments at its barriers. A segment's fills,
// copies and dispatches become steps in order; a segment holding indirect
// dispatches is preceded by one indirect_args step per indirect dispatch
// and one args_barrier (so the segment pays one extra barrier, however many
// indirect dispatches it has). Empty segments (count-0 dispatches and
// 0-word fills and copies are dropped) merge with their neighbours, and
// neither a leading nor a trailing barrier is kept: the recording opens and
// closes with barriers of its own (vulkan_recording.cpp).
#include "backends/vulkan/vulkan_program.h"

#include <map>
#include <variant>

#include "backends/kernel_table.h"

namespace sinew::vulkan {
namespace {

class Planner {
 public:
  Planner(PipelineCache& pipelines, const VkPhysicalDeviceLimits& limits, const std::string& device_name)
      : pipelines_(pipelines), limits_(limits), device_name_(device_name) {}

  Status add(const FrameProgram::Command& command, std::size_t position) {
    if (std::holds_alternative<Barrier>(command)) {
      if (segment_.empty()) return {};  // the previous barrier, or the opening one, already stands
      close_segment();
      plan_.steps.push_back({});  // Kind::barrier
      return {};
    }
    if (const auto* f = std::get_if<Fill>(&command)) {
      if (f->words == 0) return {};
      Step s;
      s.kind = Step::Kind::fill;
      s.target = f->buffer.id;
      s.target_offset = std::uint64_t{f->word} * 4;
      s.bytes = std::uint64_t{f->words} * 4;
      s.value = f->value;
      segment_.push_back(s);
      return {};
    }
    if (const auto* c = std::get_if<Copy>(&command)) {
      if (c->words == 0) return {};
      Step s;
      s.kind = Step::Kind::copy;
      s.source = c->source.id;
      s.source_offset = std::uint64_t{c->source_word} * 4;
      s.target = c->target.id;
      s.target_offset = std::uint64_t{c->target_word} * 4;
      s.bytes = std::uint64_t{c->words} * 4;
      segment_.push_back(s);
      return {};
    }
    const auto& d = std::get<Dispatch>(command);
    if (d.count == 0) return {};
    const std::string who =
        "frame program command " + std::to_string(position) + " (" + std::string(kernel_name(d.kernel)) + ")";
    auto pipe = pipelines_.pipeline(d.kernel);
    if (!pipe) return Error(pipe.error().code(), who + ": " + pipe.error().message());
    const std::uint32_t group = launch_group_size(d.kernel);
    const std::uint64_t groups = (std::uint64_t{d.count} + group - 1) / group;  // the capacity's when indirect
    if (groups > limits_.maxComputeWorkGroupCount[0])
      return Error(ErrorCode::backend_unavailable,
                   who + ": " + std::to_string(d.count) + " work items exceed what " + device_name_ +
                       " dispatches at once (" + std::to_string(limits_.maxComputeWorkGroupCount[0]) + " groups of " +
                       std::to_string(group) + ")");
    Step s;
    s.kind = Step::Kind::dispatch;
    s.dispatch = &d;
    s.set = set_of(binding_ids(d));
    if (d.indirect.buffer.valid()) {
      s.slot = plan_.slots++;
      Step args;
      args.kind = Step::Kind::indirect_args;
      args.slot = s.slot;
      args.set = set_of({d.indirect.buffer.id, kArgsBufferId});
      args.args = {d.indirect.word, d.count, group, 3 * s.slot};
      prelude_.push_back(args);
    } else {
      s.groups = static_cast<std::uint32_t>(groups);
    }
    ++plan_.dispatches;
    segment_.push_back(s);
    return {};
  }

  Result<Plan> finish() {
    close_segment();
    if (!plan_.steps.empty() && plan_.steps.back().kind == Step::Kind::barrier) plan_.steps.pop_back();
    if (plan_.slots > 0)
      if (auto pipe = pipelines_.pipeline(Kernel::indirect_args); !pipe) return pipe.error();
    return std::move(plan_);
  }

 private:
  static std::vector<std::uint32_t> binding_ids(const Dispatch& d) {
    std::vector<std::uint32_t> ids;
    for (std::uint32_t b = 0; b < d.binding_count; ++b) ids.push_back(d.bindings[b].id);
    return ids;
  }

  // The descriptor set binding `ids`, made once per distinct tuple.
  std::uint32_t set_of(std::vector<std::uint32_t> ids) {
    auto [it, added] = set_index_.emplace(ids, static_cast<std::uint32_t>(plan_.sets.size()));
    if (added) {
      plan_.descriptors += static_cast<std::uint32_t>(ids.size());
      plan_.sets.push_back(std::move(ids));
    }
    return it->second;
  }

  // Appends the segment, after its indirect_args steps and their barrier.
  void close_segment() {
    if (!prelude_.empty()) {
      plan_.steps.insert(plan_.steps.end(), prelude_.begin(), prelude_.end());
      Step barrier;
      barrier.kind = Step::Kind::args_barrier;
      plan_.steps.push_back(barrier);
    }
    plan_.steps.insert(plan_.steps.end(), segment_.begin(), segment_.end());
    prelude_.clear();
    segment_.clear();
  }

  PipelineCache& pipelines_;
  const VkPhysicalDeviceLimits& limits_;
  const std::string& device_name_;
  Plan plan_;
  std::vector<Step> segment_;  // the current segment's steps
  std::vector<Step> prelude_;  // its indirect_args steps
  std::map<std::vector<std::uint32_t>, std::uint32_t> set_index_;
};

}  // namespace

Result<Plan> plan_program(const FrameProgram& program, PipelineCache& pipelines, const VkPhysicalDeviceLimits& limits,
                          const std::string& device_name) {
  Planner planner(pipelines, limits, device_name);
  std::size_t position = 0;
  for (const auto& command : program.commands())
    if (Status s = planner.add(command, ++position); !s) return s.error();
  return planner.finish();
}

}  // namespace sinew::vulkan
