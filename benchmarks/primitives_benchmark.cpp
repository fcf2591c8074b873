// primitives_benchmark — the device primitives on each backend: exclusive
// scan, compaction (half the items kept), stable radix sort of 32-bit keys
// with a payload, and a float sum, over 2^16 and 2^20 items. One frame
// program per primitive, run repeatedly; items per second is what a
// broad phase, a neighbour search or a contact compaction can afford.
//   bench_primitives [--benchmark_filter=sort] [--benchmark_out=p.csv --benchmark_out_format=csv]
#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

#include "backends/backend.h"
#include "program/primitives.h"
#include "benchmark_main.h"

namespace {

using namespace sinew;

enum class Primitive { scan, compact, sort, sum };

void BM_Primitive(benchmark::State& state, const char* backend, Primitive what) {
  const auto n = static_cast<std::uint32_t>(state.range(0));
  auto made = create_device({.backend = backend, .quiet = true});
  if (!made) {
    state.SkipWithError(made.error().message().c_str());
    return;
  }
  Device& device = **made;
  std::mt19937 rng(1);
  std::vector<std::uint32_t> data(n), flags(n);
  for (auto& d : data) d = rng();
  for (auto& f : flags) f = rng() & 1u;
  auto buffer = [&](const std::vector<std::uint32_t>& words, std::size_t count) {
    auto b = *device.create_buffer(std::max<std::size_t>(count, 1) * 4, "bench");
    if (!words.empty()) (void)device.write_buffer(b, 0, words.data(), words.size() * 4);
    return b;
  };
  const BufferHandle counts = buffer({n, 0}, 2);
  const BufferHandle a = buffer(data, n), b = buffer({}, n), c = buffer(flags, n), d = buffer({}, n);
  FrameProgram program;
  const DeviceCount count{counts, 0, n};
  switch (what) {
    case Primitive::scan:
      append_exclusive_scan(program, count, {a, 0}, {b, 0}, {buffer({}, scan_scratch_words(n)), 0});
      break;
    case Primitive::compact:
      append_compact(program, count, c, a, b, {counts, 1, n}, "kept", buffer({}, compact_scratch_words(n)));
      break;
    case Primitive::sort:
      append_radix_sort(program, count, 32, a, c, b, d, {buffer({}, radix_sort_scratch_words(n)), 0});
      break;
    case Primitive::sum:
      append_reduce(program, count, ReduceOp::sum_f32, {a, 0}, 1, {buffer({}, reduce_scratch_words(n)), 0});
      break;
  }
  auto prepared = device.create_program(program);
  if (!prepared) {
    state.SkipWithError(prepared.error().message().c_str());
    return;
  }
  if (Status s = device.run_program(*prepared); !s) {  // warm-up; keys sorted from here on: the cost is the same
    state.SkipWithError(s.error().message().c_str());
    return;
  }
  for (auto _ : state) (void)device.run_program(*prepared);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * n);
  state.counters["dispatches"] = static_cast<double>(program.dispatch_count());
  state.SetLabel(device.device_name());
}

#define SINEW_BENCH_PRIMITIVE(backend)                                                                       \
  BENCHMARK_CAPTURE(BM_Primitive, scan_##backend, #backend, Primitive::scan)->Arg(1 << 16)->Arg(1 << 20)   \
      ->UseRealTime()->Unit(benchmark::kMillisecond);                                                       \
  BENCHMARK_CAPTURE(BM_Primitive, compact_##backend, #backend, Primitive::compact)->Arg(1 << 16)->Arg(1 << 20) \
      ->UseRealTime()->Unit(benchmark::kMillisecond);                                                       \
  BENCHMARK_CAPTURE(BM_Primitive, sort_##backend, #backend, Primitive::sort)->Arg(1 << 16)->Arg(1 << 20)   \
      ->UseRealTime()->Unit(benchmark::kMillisecond);                                                       \
  BENCHMARK_CAPTURE(BM_Primitive, sum_##backend, #backend, Primitive::sum)->Arg(1 << 16)->Arg(1 << 20)     \
      ->UseRealTime()->Unit(benchmark::kMillisecond);

SINEW_BENCH_PRIMITIVE(cpu)
SINEW_BENCH_PRIMITIVE(opencl)
SINEW_BENCH_PRIMITIVE(vulkan)

}  // namespace

SINEW_BENCHMARK_MAIN("bench_primitives",
                     "Scan, compaction, radix sort and reduction as frame programs over 2^16 and 2^20 items on each backend.")
