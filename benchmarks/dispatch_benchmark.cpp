// dispatch_benchmark — the fixed cost of one dependent dispatch on each
// backend: a frame program of 1,000 small dispatches (64 or 4,096 particles
// of xpbd_predict) each followed by a barrier, as one colour of a scene
// would be. (The CPU backend runs dispatches under 1,024 items on the
// calling thread, so 64 shows its bare cost and 4,096 its thread fork/join.) The real time per dispatch is what every colour costs before it
// does any work; it decides how far colour counts must come down on GPUs.
//   bench_dispatch [--benchmark_out=d.csv --benchmark_out_format=csv]
#include <benchmark/benchmark.h>

#include "backends/backend.h"
#include "xpbd_params.h"
#include "benchmark_main.h"

namespace {

void BM_DispatchWithBarrier(benchmark::State& state, const char* backend) {
  const auto particles = static_cast<std::uint32_t>(state.range(0));
  auto made = sinew::create_device({.backend = backend, .quiet = true});
  if (!made) {
    state.SkipWithError(made.error().message().c_str());
    return;
  }
  sinew::Device& device = **made;
  sinew::BufferHandle b[3];
  for (auto& h : b) h = *device.create_buffer(particles * 16, "particles");
  const int dispatches = 1000;
  sinew::FrameProgram program;
  sinew::kernels::PredictParams p{};
  p.h = 1e-3f;
  p.count = particles;
  for (int i = 0; i < dispatches; ++i) {
    program.dispatch(sinew::Kernel::xpbd_predict, particles, {b[0], b[1], b[2]}, p);
    program.barrier();
  }
  auto prepared = device.create_program(program);
  if (!prepared) {
    state.SkipWithError(prepared.error().message().c_str());
    return;
  }
  (void)device.run_program(*prepared);  // warm-up
  for (auto _ : state) (void)device.run_program(*prepared);
  state.counters["time_per_dispatch"] =
      benchmark::Counter(double(dispatches), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetLabel(device.device_name());
}

BENCHMARK_CAPTURE(BM_DispatchWithBarrier, cpu, "cpu")->Arg(64)->Arg(4096)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DispatchWithBarrier, opencl, "opencl")->Arg(64)->Arg(4096)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DispatchWithBarrier, vulkan, "vulkan")->Arg(64)->Arg(4096)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

SINEW_BENCHMARK_MAIN("bench_dispatch",
                     "The fixed cost of a dependent dispatch: a program of 1,000 dispatches of xpbd_predict (64 or 4,096\nparticles), each followed by a barrier, on each backend.")
