// device_commands_test.cpp — the backend interface's commands and lifetimes
// on every backend: fill, copy, indirect dispatch, cooperative groups,
// counters and their capacity, submit and wait apart, destroying and
// resizing buffers and programs (the device gives back what it held).
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "primitive_params.h"
#include "test_support.h"
#include "xpbd_params.h"

namespace sinew {
namespace {

using test::BackendTest;

class DeviceCommands : public BackendTest {
 protected:
  void SetUp() override {
    BackendTest::SetUp();
    if (IsSkipped()) return;
    auto d = create_device({.backend = GetParam(), .quiet = true});
    ASSERT_TRUE(d.ok()) << d.error().message();
    device = std::move(*d);
  }
  BufferHandle words(const std::vector<std::uint32_t>& data) {
    auto b = device->create_buffer(data.size() * 4, "test words");
    EXPECT_TRUE(b.ok());
    EXPECT_TRUE(device->write_buffer(*b, 0, data.data(), data.size() * 4).ok());
    return *b;
  }
  std::vector<std::uint32_t> read(BufferHandle b, std::size_t count) {
    std::vector<std::uint32_t> out(count);
    EXPECT_TRUE(device->read_buffer(b, 0, out.data(), count * 4).ok());
    return out;
  }
  std::unique_ptr<Device> device;
};

TEST_P(DeviceCommands, FillAndCopyTouchExactlyTheirWords) {
  const BufferHandle a = words(std::vector<std::uint32_t>(10, 1));
  const BufferHandle b = words(std::vector<std::uint32_t>(10, 2));
  FrameProgram program;
  program.fill(a, 2, 5, 0xabcdef01u);
  program.barrier();
  program.copy(a, 1, b, 4, 3);  // a[1..4) = 1, f, f -> b[4..7)
  auto prepared = device->create_program(program);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message();
  SINEW_ASSERT_OK(device->run_program(*prepared));
  const std::uint32_t f = 0xabcdef01u;
  EXPECT_EQ(read(a, 10), (std::vector<std::uint32_t>{1, 1, f, f, f, f, f, 1, 1, 1}));
  EXPECT_EQ(read(b, 10), (std::vector<std::uint32_t>{2, 2, 2, 2, 1, f, f, 2, 2, 2}));
}

TEST_P(DeviceCommands, CommandsPastABufferOrOverlappingAreErrorsNamingThem) {
  const BufferHandle a = words(std::vector<std::uint32_t>(4, 0));
  FrameProgram fill;
  fill.fill(a, 2, 3, 0);
  auto bad = device->create_program(fill);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("command 1 (fill)"), std::string::npos) << bad.error().message();
  FrameProgram copy;
  copy.copy(a, 0, a, 1, 2);
  bad = device->create_program(copy);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("overlap"), std::string::npos) << bad.error().message();
  FrameProgram indirect;
  Dispatch d;
  d.kernel = Kernel::indirect_args;
  d.count = 4;
  d.indirect.buffer = a;
  d.binding_count = 2;
  d.bindings[0] = d.bindings[1] = a;
  d.params_bytes = sizeof(kernels::IndirectArgsParams);
  indirect.dispatch_raw(d);
  bad = device->create_program(indirect);
  ASSERT_FALSE(bad.ok()) << "an indirect count that is no declared counter";
  EXPECT_NE(bad.error().message().find("not a declared counter"), std::string::npos) << bad.error().message();
}

// An indirect dispatch covers the count its counter holds when it runs: a
// kernel that reads the count itself (scan_add: item i < n adds its block's
// offset) changes exactly n items on every backend.
TEST_P(DeviceCommands, IndirectDispatchCoversTheCountItsCounterHolds) {
  const std::uint32_t capacity = 1000;
  const BufferHandle data = words(std::vector<std::uint32_t>(capacity, 0));
  const BufferHandle sums = words(std::vector<std::uint32_t>(4, 1));
  for (std::uint32_t n : {0u, 1u, 255u, 256u, 257u, 999u, 1000u}) {
    const BufferHandle counts = words({7, 0});
    FrameProgram program;
    program.fill(data, 0, capacity, 0);
    program.fill(counts, 1, 1, n);  // a count known only on the device
    program.barrier();
    const std::uint32_t counter = program.counter("items", counts, 1, capacity);
    kernels::ScanParams p{};
    p.count_word = 1;
    p.capacity = capacity;
    program.dispatch_indirect(Kernel::scan_add, counter, {counts, data, sums}, p);
    auto prepared = device->create_program(program);
    ASSERT_TRUE(prepared.ok()) << prepared.error().message();
    SINEW_ASSERT_OK(device->run_program(*prepared));
    ASSERT_EQ(device->counters().size(), 1u);
    EXPECT_EQ(device->counters()[0], n);
    const auto got = read(data, capacity);
    EXPECT_EQ(std::count(got.begin(), got.end(), 1u), n) << "n = " << n;
    EXPECT_EQ(std::count(got.begin(), got.begin() + n, 1u), n) << "n = " << n << ": the first n items";
    SINEW_ASSERT_OK(device->destroy_program(*prepared));
  }
}

// A step right after an indirect dispatch that found nothing to do may
// write that dispatch's counter (here a fill sets it for the next
// dispatch): every thread of a backend must still see the count the empty
// dispatch had (the CPU backend skips barriers after empty dispatches only
// where that cannot race: cpu_device.cpp, run_steps). Run many times, so a
// race shows as wrong sums (or a hang, which the test's timeout catches).
TEST_P(DeviceCommands, AStepAfterAnEmptyIndirectDispatchMayRewriteItsCount) {
  const std::uint32_t capacity = 1000;  // 4 blocks of scan_add's 256
  const BufferHandle data = words(std::vector<std::uint32_t>(capacity, 0));
  const BufferHandle sums = words(std::vector<std::uint32_t>(4, 1));
  const BufferHandle counts = words({7, 0});
  FrameProgram program;
  program.fill(data, 0, capacity, 0);
  program.fill(counts, 1, 1, 0);
  program.barrier();
  const std::uint32_t counter = program.counter("items", counts, 1, capacity);
  kernels::ScanParams p{};
  p.count_word = 1;
  p.capacity = capacity;
  program.dispatch_indirect(Kernel::scan_add, counter, {counts, data, sums}, p);  // empty
  program.barrier();
  program.fill(counts, 1, 1, capacity);
  program.barrier();
  program.dispatch_indirect(Kernel::scan_add, counter, {counts, data, sums}, p);  // every item, once
  auto prepared = device->create_program(program);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message();
  for (int run = 0; run < 4000; ++run) {
    SINEW_ASSERT_OK(device->run_program(*prepared));
    const auto got = read(data, capacity);
    ASSERT_EQ(std::count(got.begin(), got.end(), 1u), std::ptrdiff_t{capacity}) << "run " << run;
  }
  SINEW_ASSERT_OK(device->destroy_program(*prepared));
}

// How many items an indirect dispatch launches, seen through a kernel that
// does not read the counter (xpbd_predict guards with its own parameter):
// exactly n on the CPU; whole groups of 64 covering n with Vulkan's
// indirect dispatch; OpenCL 1.2 has none and launches the capacity.
TEST_P(DeviceCommands, IndirectDispatchLaunchesWhatTheBackendDocuments) {
  const std::uint32_t capacity = 300;
  std::vector<float> x(4 * capacity, 0.0f), v(4 * capacity, 0.0f);
  for (std::uint32_t i = 0; i < capacity; ++i) {
    x[4 * i + 3] = 1.0f;  // movable
    v[4 * i] = 1.0f;
    v[4 * i + 3] = 1.0f;  // velocity damping factor 1: none
  }
  auto make = [&](const std::vector<float>& data) {
    auto b = device->create_buffer(data.size() * 4, "floats");
    EXPECT_TRUE(device->write_buffer(*b, 0, data.data(), data.size() * 4).ok());
    return *b;
  };
  const BufferHandle bx = make(x), bprev = make(x), bv = make(v);
  for (std::uint32_t n : {0u, 1u, 63u, 64u, 65u, 299u, 300u}) {
    SINEW_ASSERT_OK(device->write_buffer(bx, 0, x.data(), x.size() * 4));
    const BufferHandle counts = words({7, 0});
    FrameProgram program;
    program.fill(counts, 1, 1, n);
    program.barrier();
    const std::uint32_t counter = program.counter("particles", counts, 1, capacity);
    kernels::PredictParams p{};
    p.h = 0.5f;
    p.count = capacity;
    program.dispatch_indirect(Kernel::xpbd_predict, counter, {bx, bprev, bv}, p);
    auto prepared = device->create_program(program);
    ASSERT_TRUE(prepared.ok()) << prepared.error().message();
    SINEW_ASSERT_OK(device->run_program(*prepared));
    std::vector<float> got(x.size());
    SINEW_ASSERT_OK(device->read_buffer(bx, 0, got.data(), got.size() * 4));
    std::uint32_t moved = 0;
    for (std::uint32_t i = 0; i < capacity; ++i) moved += got[4 * i] == 0.5f ? 1 : 0;
    const std::uint32_t expected = GetParam() == "cpu"      ? n
                                   : GetParam() == "vulkan" ? std::min(capacity, (n + 63) / 64 * 64)
                                                            : capacity;
    EXPECT_EQ(moved, expected) << "n = " << n;
    SINEW_ASSERT_OK(device->destroy_program(*prepared));
  }
}

TEST_P(DeviceCommands, IndirectArgsGiveGroupCountsOfTheClampedCount) {
  const BufferHandle counts = words({5, 1000, 257, 0});
  const BufferHandle args = words(std::vector<std::uint32_t>(12, 99));
  FrameProgram program;
  const std::uint32_t cases[4][2] = {{0, 100}, {1, 300}, {2, 1000}, {3, 10}};  // (count word, capacity)
  for (std::uint32_t c = 0; c < 4; ++c) {
    kernels::IndirectArgsParams p{cases[c][0], cases[c][1], 256, 3 * c};
    program.dispatch(Kernel::indirect_args, 1, {counts, args}, p);
  }
  auto prepared = device->create_program(program);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message();
  SINEW_ASSERT_OK(device->run_program(*prepared));
  // 5 -> 1 group; min(1000, 300) = 300 -> 2; 257 -> 2; 0 -> 0
  EXPECT_EQ(read(args, 12), (std::vector<std::uint32_t>{1, 1, 1, 2, 1, 1, 2, 1, 1, 0, 1, 1}));
}

TEST_P(DeviceCommands, SubmitReturnsBeforeWaitAndCountersComeWithTheWait) {
  const BufferHandle counts = words({0, 0});
  FrameProgram program;
  program.fill(counts, 0, 1, 41);
  program.fill(counts, 1, 1, 3);
  program.counter("a", counts, 0, 100);
  program.counter("b", counts, 1, 2);
  auto prepared = device->create_program(program);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message();
  SINEW_ASSERT_OK(device->submit(*prepared));
  const Status waited = device->wait();
  ASSERT_FALSE(waited.ok()) << "counter b reached 3 of 2";
  EXPECT_EQ(waited.error().code(), ErrorCode::capacity_exceeded);
  EXPECT_NE(waited.error().message().find("'b' reached 3 of capacity 2"), std::string::npos) << waited.error().message();
  EXPECT_EQ(waited.error().message().find("'a'"), std::string::npos) << "a is within its capacity";
  ASSERT_EQ(device->counters().size(), 2u);
  EXPECT_EQ(device->counters()[0], 41u);
  EXPECT_EQ(device->counters()[1], 3u);
  SINEW_ASSERT_OK(device->wait());  // nothing in flight: returns at once
}

// End reads come back with the wait that ends the program, after its last
// command, one range after another — no read or wait of their own.
TEST_P(DeviceCommands, EndReadsComeWithTheWaitAfterTheLastCommand) {
  const BufferHandle a = words({1, 2, 3, 4, 5, 6});
  const BufferHandle b = words({7, 8, 9});
  FrameProgram program;
  program.fill(a, 1, 2, 40);
  program.barrier();
  program.copy(a, 1, b, 0, 1);  // b[0] = 40, written after a's fill
  EXPECT_EQ(program.read_at_end(a, 0, 4), 0u);
  EXPECT_EQ(program.read_at_end(b, 0, 2), 4u);
  EXPECT_EQ(program.end_read_words(), 6u);
  auto prepared = device->create_program(program);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message();
  for (int run = 0; run < 2; ++run) {
    const HostTransfers before = device->transfers();
    SINEW_ASSERT_OK(device->run_program(*prepared));
    const HostTransfers after = device->transfers();
    EXPECT_EQ(std::vector<std::uint32_t>(device->end_reads().begin(), device->end_reads().end()),
              (std::vector<std::uint32_t>{1, 40, 40, 4, 40, 8}));
    EXPECT_EQ(after.reads - before.reads, 0u) << "no read of their own";
    EXPECT_EQ(after.waits - before.waits, 1u) << "the program's end";
    EXPECT_EQ(after.read_bytes - before.read_bytes, 24u) << "counted as read back";
  }
  // A range past its buffer is an error naming it.
  FrameProgram past;
  past.read_at_end(b, 2, 2);
  auto refused = device->create_program(past);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message().find("end read 0"), std::string::npos) << refused.error().message();
}

TEST_P(DeviceCommands, ResizeKeepsTheContentsAndProgramsFollowTheNewSize) {
  const BufferHandle a = words({1, 2, 3, 4});
  const BufferHandle b = words({0, 0, 0, 0});
  FrameProgram program;
  program.copy(a, 0, b, 0, 4);
  auto prepared = device->create_program(program);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message();
  SINEW_ASSERT_OK(device->resize_buffer(a, 64 * 4));
  SINEW_ASSERT_OK(device->resize_buffer(b, 2 * 4 + 8));  // still holds the 4 words copied
  EXPECT_EQ(read(a, 4), (std::vector<std::uint32_t>{1, 2, 3, 4}));
  EXPECT_EQ(read(a, 64)[63], 0u) << "the new words are zero";
  const std::uint32_t five[] = {5, 6, 7, 8};
  SINEW_ASSERT_OK(device->write_buffer(a, 0, five, sizeof five));
  SINEW_ASSERT_OK(device->run_program(*prepared));  // prepared again for the new buffers
  EXPECT_EQ(read(b, 4), (std::vector<std::uint32_t>{5, 6, 7, 8}));
  SINEW_ASSERT_OK(device->resize_buffer(b, 4));  // now too small for the program's copy
  const Status s = device->run_program(*prepared);
  EXPECT_FALSE(s.ok()) << "a copy past the resized buffer's end";
}

TEST_P(DeviceCommands, DestroyingGivesBackWhatTheDeviceHeld) {
  const DeviceObjects baseline = device->objects();
  std::vector<BufferHandle> made;
  for (int i = 0; i < 5; ++i) made.push_back(words(std::vector<std::uint32_t>(1000 + i, 1)));
  FrameProgram program;
  for (int i = 0; i + 1 < 5; ++i) {
    program.copy(made[i], 0, made[i + 1], 0, 100);
    program.barrier();
    kernels::ReduceParams p{};
    p.capacity = 100;
    p.in_stride = 1;
    program.dispatch(Kernel::reduce_blocks, 256, {made[0], made[i], made[i + 1]}, p);
    program.barrier();
  }
  std::vector<ProgramHandle> programs;
  for (int rebuild = 0; rebuild < 3; ++rebuild) {  // a scene whose program is rebuilt
    auto prepared = device->create_program(program);
    ASSERT_TRUE(prepared.ok()) << prepared.error().message();
    SINEW_ASSERT_OK(device->run_program(*prepared));
    programs.push_back(*prepared);
  }
  const DeviceObjects full = device->objects();
  EXPECT_EQ(full.buffers, baseline.buffers + 5);
  EXPECT_EQ(full.programs, baseline.programs + 3);
  EXPECT_GT(full.native, baseline.native);
  for (int i = 0; i < 3; ++i) SINEW_ASSERT_OK(device->resize_buffer(made[i], 4000 * 4 + i));
  for (ProgramHandle p : programs) SINEW_ASSERT_OK(device->destroy_program(p));
  for (BufferHandle b : made) SINEW_ASSERT_OK(device->destroy_buffer(b));
  const DeviceObjects after = device->objects();
  EXPECT_EQ(after.buffers, baseline.buffers);
  EXPECT_EQ(after.buffer_bytes, baseline.buffer_bytes);
  EXPECT_EQ(after.programs, baseline.programs);
  EXPECT_EQ(after.native, baseline.native) << "every backend object is freed";
  EXPECT_FALSE(device->destroy_buffer(made[0]).ok()) << "a destroyed buffer is gone";
  EXPECT_FALSE(device->destroy_program(programs[0]).ok());
  EXPECT_FALSE(device->submit(programs[0]).ok());
}

TEST_P(DeviceCommands, AProgramBindingADestroyedBufferCannotBeSubmitted) {
  const BufferHandle a = words({1, 2}), b = words({0, 0});
  FrameProgram program;
  program.copy(a, 0, b, 0, 2);
  auto prepared = device->create_program(program);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message();
  SINEW_ASSERT_OK(device->destroy_buffer(a));
  const Status s = device->submit(*prepared);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message().find("not a buffer of this device"), std::string::npos) << s.error().message();
}

INSTANTIATE_TEST_SUITE_P(Backends, DeviceCommands, ::testing::ValuesIn(test::backends()), test::backend_name);

}  // namespace
}  // namespace sinew
