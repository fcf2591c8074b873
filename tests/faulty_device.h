// faulty_device.h — a Device that forwards every call to a real one and
// fails one chosen call: the Nth buffer creation, resize, write, read-back,
// program creation, submission or wait since it was armed. The runtime must
// turn any device error into a named error, and never crash or leak.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>

#include "backends/backend.h"

namespace sinew::test {

class FaultyDevice final : public Device {
 public:
  enum class Call { create_buffer, resize_buffer, write_buffer, read_buffer, create_program, submit, wait };
  static constexpr Call kCalls[] = {Call::create_buffer, Call::resize_buffer,  Call::write_buffer, Call::read_buffer,
                                    Call::create_program, Call::submit,        Call::wait};

  static const char* name(Call call) {
    switch (call) {
      case Call::create_buffer: return "create_buffer";
      case Call::resize_buffer: return "resize_buffer";
      case Call::write_buffer: return "write_buffer";
      case Call::read_buffer: return "read_buffer";
      case Call::create_program: return "create_program";
      case Call::submit: return "submit";
      case Call::wait: return "wait";
    }
    return "?";
  }

  explicit FaultyDevice(std::unique_ptr<Device> inner) : inner_(std::move(inner)) {}

  /// Fails the `nth` (1-based) call of `call` from now on, once.
  void arm(Call call, std::uint64_t nth) {
    call_ = call;
    nth_ = nth;
    seen_ = 0;
    armed_ = true;
    fired_ = false;
  }
  void disarm() { armed_ = false; }
  [[nodiscard]] bool fired() const { return fired_; }
  /// The message every injected error carries.
  static std::string tag() { return "injected fault"; }

  std::string backend_name() const override { return inner_->backend_name(); }
  std::string device_name() const override { return inner_->device_name(); }
  Result<BufferHandle> create_buffer(std::size_t bytes, std::string_view label) override {
    if (hit(Call::create_buffer)) return fault(ErrorCode::out_of_memory);
    return inner_->create_buffer(bytes, label);
  }
  Status destroy_buffer(BufferHandle buffer) override { return inner_->destroy_buffer(buffer); }
  Status resize_buffer(BufferHandle buffer, std::size_t bytes) override {
    if (hit(Call::resize_buffer)) return fault(ErrorCode::out_of_memory);
    return inner_->resize_buffer(buffer, bytes);
  }
  Result<ProgramHandle> create_program(const FrameProgram& program) override {
    if (hit(Call::create_program)) return fault(ErrorCode::out_of_memory);
    return inner_->create_program(program);
  }
  Status destroy_program(ProgramHandle program) override { return inner_->destroy_program(program); }
  std::span<const std::uint32_t> counters() const override { return inner_->counters(); }
  std::span<const std::uint32_t> end_reads() const override { return inner_->end_reads(); }
  Status last_run_times(DeviceTimes& times) const override { return inner_->last_run_times(times); }
  DeviceObjects objects() const override { return inner_->objects(); }

 protected:
  Status write_buffer_impl(BufferHandle buffer, std::size_t offset, const void* data, std::size_t bytes) override {
    if (hit(Call::write_buffer)) return fault(ErrorCode::device_lost);
    return inner_->write_buffer(buffer, offset, data, bytes);
  }
  Status read_buffer_impl(BufferHandle buffer, std::size_t offset, void* data, std::size_t bytes) override {
    if (hit(Call::read_buffer)) return fault(ErrorCode::device_lost);
    return inner_->read_buffer(buffer, offset, data, bytes);
  }
  Status submit_impl(ProgramHandle program) override {
    if (hit(Call::submit)) return fault(ErrorCode::device_lost);
    return inner_->submit(program);
  }
  Status wait_impl() override {
    // The real device still finishes what it was given: a lost wait leaves
    // nothing in flight behind the next call.
    Status real = inner_->wait();
    count_end_reads(inner_->end_reads().size());  // they reach the host in this wait
    if (hit(Call::wait)) return fault(ErrorCode::device_lost);
    return real;
  }

 private:
  bool hit(Call call) {
    if (!armed_ || call != call_ || ++seen_ != nth_) return false;
    armed_ = false;
    fired_ = true;
    return true;
  }
  Error fault(ErrorCode code) const {
    return Error(code, tag() + ": " + name(call_) + " #" + std::to_string(nth_) + " on " + inner_->backend_name());
  }

  std::unique_ptr<Device> inner_;
  Call call_ = Call::submit;
  std::uint64_t nth_ = 0, seen_ = 0;
  bool armed_ = false, fired_ = false;
};

}  // namespace sinew::test
