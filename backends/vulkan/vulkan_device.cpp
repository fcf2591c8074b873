// vulkan_device.cpp — the Vulkan compute backend: the sinew Device that glues
// the pieces together, and the backend's public functions.
//
// One instance, device and compute queue per sinew Device; every submission
// signals one fence, so at most one is in flight. submit() records the
// program again if a buffer was resized or destroyed since it was recorded
// (its descriptor sets point at VkBuffers), submits its command buffer and
// returns; wait() waits for the fence, reads the counters the recording
// copied into mapped memory and checks them against their capacities, and
// reads the timestamps (last_run_times). Calls that touch buffers, and the
// next submit, first finish a submission in flight. The pieces, each in the
// file named after its job:
//   vulkan_instance         the instance, the validation layer and its counter
//   vulkan_physical_device  which devices there are, which one to use
//   vulkan_memory           memory types, allocation, staging; the queue, fence and transfers
//   vulkan_buffers          the buffers the handles name: create, destroy, resize, host copies
//   vulkan_pipelines        pipelines from the embedded SPIR-V, set layouts
//   vulkan_program          a frame program resolved into steps (indirect dispatches, sets)
//   vulkan_recording        the steps recorded into a command buffer; counters, timestamps
#include "backends/vulkan/vulkan_device.h"

#include <vulkan/vulkan.h>

#include <memory>

#include "backends/kernel_table.h"
#include "backends/vulkan/vulkan_buffers.h"
#include "backends/vulkan/vulkan_common.h"
#include "backends/vulkan/vulkan_instance.h"
#include "backends/vulkan/vulkan_memory.h"
#include "backends/vulkan/vulkan_physical_device.h"
#include "backends/vulkan/vulkan_pipelines.h"
#include "backends/vulkan/vulkan_program.h"
#include "backends/vulkan/vulkan_recording.h"

namespace sinew {
namespace vulkan {

class VulkanDeviceImpl final : public Device {
 public:
  VulkanDeviceImpl() = default;
  VulkanDeviceImpl(const VulkanDeviceImpl&) = delete;
  VulkanDeviceImpl& operator=(const VulkanDeviceImpl&) = delete;

  ~VulkanDeviceImpl() override {
    if (!device_) return;
    vkDeviceWaitIdle(device_);
    for (auto& p : programs_)
      if (p) recorder_.destroy(p->recording);
    pipelines_.destroy();
    buffers_.destroy();
    memory_.destroy();
    queue_.destroy();
    recorder_.destroy();
    vkDestroyDevice(device_, nullptr);
  }

  // Everything made here is released by the destructor, also after a failure.
  Status init(const DeviceOptions& options) {
    auto inst = make_instance();
    if (!inst) return inst.error();
    instance_ = std::move(*inst);
    auto found = find_devices(instance_->instance);
    if (!found) return found.error();
    auto index = choose(*found, options.device);
    if (!index) return index.error();
    found_ = (*found)[*index];

    const float priority = 1.0f;
    auto queue_info = vk_struct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    queue_info.queueFamilyIndex = found_.queue_family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    auto device_info = vk_struct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    if (VkResult r = vkCreateDevice(found_.physical, &device_info, nullptr, &device_); r != VK_SUCCESS) {
      device_ = VK_NULL_HANDLE;
      return vk_error("vkCreateDevice on " + found_.info.name, r, ErrorCode::backend_unavailable);
    }
    memory_.init(found_, device_);
    if (Status s = recorder_.init(found_, device_, memory_); !s) return s;  // the program command pool
    if (Status s = queue_.init(device_, found_.queue_family); !s) return s;
    pipelines_.init(found_, device_);
    buffers_.init(found_, memory_, queue_);
    return {};
  }

  std::string backend_name() const override { return "vulkan"; }
  std::string device_name() const override {
    return "Vulkan: " + found_.info.name + " (" + found_.info.type + ", " + found_.info.driver + ", Vulkan " +
           version_string(found_.info.api_version) + (memory_.unified() ? ", host-visible memory" : ", staged copies") +
           (instance_->validation ? ", validation on)" : ")");
  }

  // ---------------------------------------------------------------- buffers
  // Each first finishes a submission in flight (its counters are then
  // checked, and wait() reports them).

  Result<BufferHandle> create_buffer(std::size_t bytes, std::string_view label) override {
    if (Status s = ready("create_buffer '" + std::string(label) + "'"); !s) return s.error();
    return buffers_.create(bytes, label);
  }
  Status destroy_buffer(BufferHandle buffer) override {
    if (Status s = ready("destroy_buffer"); !s) return s;
    return buffers_.destroy(buffer);
  }
  Status resize_buffer(BufferHandle buffer, std::size_t bytes) override {
    if (Status s = ready("resize_buffer"); !s) return s;
    return buffers_.resize(buffer, bytes);
  }
  Status write_buffer_impl(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) override {
    if (Status s = ready("write_buffer"); !s) return s;
    return buffers_.write(buffer, offset, data, bytes);
  }
  Status read_buffer_impl(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) override {
    if (Status s = ready("read_buffer"); !s) return s;
    return buffers_.read(buffer, offset, data, bytes);
  }

  // ---------------------------------------------------------------- programs

  Result<ProgramHandle> create_program(const FrameProgram& program) override {
    if (Status s = check_lost("create_program"); !s) return s.error();
    auto p = std::make_unique<Program>();
    p->source = program;
    if (Status s = record(*p); !s) return s.error();
    programs_.push_back(std::move(p));
    return ProgramHandle{static_cast<std::uint32_t>(programs_.size() - 1)};
  }

  Status destroy_program(ProgramHandle program) override {
    if (!live_program(program)) return Error(ErrorCode::internal, "destroy_program: not a live program of this device");
    if (Status s = drain(); !s) return s;  // it may be in flight
    recorder_.destroy(programs_[program.id]->recording);
    programs_[program.id].reset();
    return {};
  }

  Status submit_impl(ProgramHandle program) override {
    if (!live_program(program)) return Error(ErrorCode::internal, "submit: not a live program of this device");
    if (Status s = ready("submit"); !s) return s;
    pending_ = false;  // one submission at a time: the previous one's counters are not checked
    Program& p = *programs_[program.id];
    if (p.recorded_at != buffers_.generation())
      if (Status s = record(p); !s) return s;
    if (Status s = queue_.submit(p.recording.commands, "submit"); !s) return s;
    in_flight_ = program.id;
    return {};
  }

  Status wait_impl() override {
    if (Status s = drain(); !s) return s;
    if (!pending_) return {};
    pending_ = false;
    return pending_status_;
  }

  std::span<const std::uint32_t> counters() const override { return counters_; }
  std::span<const std::uint32_t> end_reads() const override { return end_reads_; }

  Status last_run_times(DeviceTimes& out) const override {
    out = times_;
    return times_status_;
  }

  DeviceObjects objects() const override {
    DeviceObjects o;
    o.buffers = buffers_.live();
    o.buffer_bytes = buffers_.live_bytes();
    for (const auto& p : programs_) o.programs += p ? 1 : 0;
    o.native = memory_.native() + recorder_.native();
    return o;
  }

  bool validation() const { return instance_->validation; }

  // See vulkan_validation_self_test.
  std::uint64_t make_deliberate_mistake() { return vulkan::make_deliberate_mistake(device_); }

 private:
  // A frame program, its recording and the buffer generation it was recorded at.
  struct Program {
    FrameProgram source;  // kept to record again after a buffer is resized or destroyed
    std::uint64_t recorded_at = 0;
    Recording recording;
  };

  bool live_program(ProgramHandle program) const { return program.id < programs_.size() && programs_[program.id]; }

  // Checks p against the device's buffers and records it afresh (at
  // creation, and at a submit after a buffer was resized or destroyed: its
  // descriptor sets point at VkBuffers). [pre] p is not in flight.
  Status record(Program& p) {
    recorder_.destroy(p.recording);
    if (Status s = check_program(p.source, buffers_.sizes()); !s) return s;
    auto plan = plan_program(p.source, pipelines_, found_.properties.limits, found_.info.name);
    if (!plan) return plan.error();
    Status s = recorder_.record(p.recording, *plan, p.source.counters(), p.source.end_reads(), pipelines_,
                                buffers_.all());
    if (!s) {
      recorder_.destroy(p.recording);
      return s;
    }
    p.recorded_at = buffers_.generation();
    return {};
  }

  // Finishes the submission in flight, if any: reads its counters (checked
  // against their capacities; wait() returns the result) and timestamps.
  Status drain() {
    if (in_flight_ == UINT32_MAX) return {};
    const Program& p = *programs_[in_flight_];
    in_flight_ = UINT32_MAX;
    if (Status s = queue_.wait("waiting for the frame program"); !s) return s;
    recorder_.read_counters(p.recording, counters_);
    recorder_.read_end_reads(p.recording, end_reads_);
    count_end_reads(end_reads_.size());
    pending_status_ = check_counters(p.source.counters(), counters_);
    pending_ = true;
    times_status_ = recorder_.read_times(p.recording, times_);
    return {};
  }

  // Nothing in flight and the device not lost: buffers may be touched and
  // the queue used.
  Status ready(const std::string& what) {
    if (Status s = drain(); !s) return s;
    return check_lost(what);
  }

  Status check_lost(const std::string& what) const {
    if (queue_.lost())
      return Error(ErrorCode::device_lost,
                   what + ": the Vulkan device " + found_.info.name + " was lost earlier (VK_ERROR_DEVICE_LOST)");
    return {};
  }

  std::unique_ptr<Instance> instance_;  // destroyed last
  Found found_;
  VkDevice device_ = VK_NULL_HANDLE;
  // The pieces release what they own when the destructor says so: after
  // vkDeviceWaitIdle, before vkDestroyDevice.
  Memory memory_;            // the staging buffer
  Recorder recorder_;        // the program command pool
  Queue queue_;              // the queue, fence and transfer command buffer
  PipelineCache pipelines_;  // pipelines and set layouts
  BufferTable buffers_;
  std::vector<std::unique_ptr<Program>> programs_;  // nullptr: destroyed (ids are never reused)
  std::uint32_t in_flight_ = UINT32_MAX;  // the program submitted and not yet waited for
  bool pending_ = false;                  // a finished submission whose counter check wait() has not returned
  Status pending_status_;
  std::vector<std::uint32_t> counters_;  // of the last program waited for
  std::vector<std::uint32_t> end_reads_;  // of the last program waited for
  DeviceTimes times_;                    // its timestamps, read when it was waited for
  Status times_status_;
};

}  // namespace vulkan

Result<std::vector<VulkanDeviceInfo>> list_vulkan_devices() {
  auto instance = vulkan::make_instance();
  if (!instance) return instance.error();
  auto found = vulkan::find_devices((*instance)->instance);
  if (!found) return found.error();
  std::vector<VulkanDeviceInfo> out;
  for (const vulkan::Found& f : *found) out.push_back(f.info);
  return out;
}

Result<std::unique_ptr<Device>> make_vulkan_device(const DeviceOptions& options) {
  auto device = std::make_unique<vulkan::VulkanDeviceImpl>();
  if (Status s = device->init(options); !s) return s.error();
  return std::unique_ptr<Device>(std::move(device));
}

std::uint64_t vulkan_validation_messages() { return vulkan::validation_messages(); }

Result<std::uint64_t> vulkan_validation_self_test(const DeviceOptions& options) {
  if (!vulkan::validation_requested()) return Error(ErrorCode::backend_unavailable, "Vulkan validation is off (set SINEW_VULKAN_VALIDATION=1)");
  auto device = std::make_unique<vulkan::VulkanDeviceImpl>();
  if (Status s = device->init(options); !s) return s.error();
  if (!device->validation())
    return Error(ErrorCode::backend_unavailable,
                 std::string("Vulkan validation is off: ") + vulkan::kValidationLayer + " is not installed");
  return device->make_deliberate_mistake();
}

}  // namespace sinew
