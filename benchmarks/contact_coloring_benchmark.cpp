// contact_coloring_benchmark — the frame's contacts coloured on the host
// (coloring/greedy_coloring.h: first-fit greedy in contact order with a
// balancing pass, what the solver does today) against the colouring on a
// device (coloring/device_contact_coloring.h: Jones-Plassmann with hashed
// priorities, a cap and an overflow set, then the sort by colour), on the
// real self-contacts of the kidney_57k surface bent so that its folds touch
// (tests/contact_coloring_support.h; 15,991 contacts at a third of the
// mean edge, every vertex movable), all of them (pruned:0) or pruned as the
// solver prunes them (pruned:1: a vertex's nearest, an edge's 4 nearest).
//   BM_HostGreedy                 colour_constraints over the contacts
//   BM_HostJonesPlassmann         the device's colouring, sequentially (its oracle)
//   BM_DeviceJonesPlassmann       the program on a device (backend 0 cpu, 1
//                                 opencl, 2 vulkan): the contact count written,
//                                 the colouring and the sort run, waited for
// Counters: contacts, colours (non-empty, the overflow set apart), the
// overflow set's size and the part of it left by the rounds.
//   bench_contact_coloring --benchmark_out=coloring.csv --benchmark_out_format=csv
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "backends/backend.h"
#include "benchmark_main.h"
#include "coloring/device_contact_coloring.h"
#include "coloring/greedy_coloring.h"
#include "coloring/jones_plassmann.h"
#include "contact_coloring_support.h"

namespace {

using sinew::test::ContactSet;

// set 0: every contact; 1: pruned as the solver prunes them (nearest few).
const ContactSet& kidney(std::int64_t set) {
  static const ContactSet all = sinew::test::kidney_contacts(SINEW_DATA_DIR, 1.0f / 3.0f, 0.0);
  static const ContactSet pruned = sinew::test::kidney_contacts(SINEW_DATA_DIR, 1.0f / 3.0f, 0.0, true);
  return set == 0 ? all : pruned;
}

void report(benchmark::State& state, const sinew::CappedColoring& c, std::uint32_t contacts) {
  state.counters["contacts"] = contacts;
  state.counters["colors"] = c.used_colors();
  state.counters["overflow"] = c.color_sizes.back();
  state.counters["out_of_rounds"] = c.out_of_rounds;
  state.counters["dispatches"] = 0;
}

void BM_HostGreedy(benchmark::State& state) {
  const ContactSet& s = kidney(state.range(0));
  if (s.contacts() == 0) return state.SkipWithError("no kidney mesh under " SINEW_DATA_DIR);
  sinew::Coloring c;
  for (auto _ : state) {
    c = sinew::color_constraints(s.particles, 4, s.movable);
    benchmark::DoNotOptimize(c.color_of.data());
  }
  state.counters["contacts"] = s.contacts();
  state.counters["colors"] = c.color_count();
  state.counters["overflow"] = 0;
  state.counters["out_of_rounds"] = 0;
  state.counters["dispatches"] = 0;
}
BENCHMARK(BM_HostGreedy)->Arg(0)->Arg(1)->ArgName("pruned")->Unit(benchmark::kMillisecond);

void BM_HostJonesPlassmann(benchmark::State& state) {
  const ContactSet& s = kidney(state.range(0));
  if (s.contacts() == 0) return state.SkipWithError("no kidney mesh under " SINEW_DATA_DIR);
  const auto colors = static_cast<std::uint32_t>(state.range(1)), rounds = static_cast<std::uint32_t>(state.range(2));
  sinew::CappedColoring c;
  for (auto _ : state) {
    auto r = sinew::jones_plassmann_coloring(s.particles, s.movable, colors, rounds);
    if (!r) return state.SkipWithError(r.error().message().c_str());
    c = std::move(*r);
  }
  report(state, c, s.contacts());
}
BENCHMARK(BM_HostJonesPlassmann)
    ->ArgsProduct({{0, 1}, {32, 64, 128}, {128, 254}})
    ->ArgNames({"pruned", "cap", "rounds"})
    ->Unit(benchmark::kMillisecond);

void BM_DeviceJonesPlassmann(benchmark::State& state) {
  const ContactSet& s = kidney(state.range(0));
  if (s.contacts() == 0) return state.SkipWithError("no kidney mesh under " SINEW_DATA_DIR);
  const char* names[] = {"cpu", "opencl", "vulkan"};
  const std::string backend = names[state.range(1)];
  const auto colors = static_cast<std::uint32_t>(state.range(2)), rounds = static_cast<std::uint32_t>(state.range(3));
  auto made = sinew::create_device({.backend = backend, .quiet = true});
  if (!made) return state.SkipWithError(("no " + backend + " device: " + made.error().message()).c_str());
  sinew::Device& device = **made;
  const std::uint32_t n = s.contacts();
  auto coloring =
      sinew::make_device_contact_coloring(device, n, static_cast<std::uint32_t>(s.movable.size()), colors, rounds);
  auto positions = device.create_buffer(s.movable.size() * 16, "positions");
  auto contacts = device.create_buffer(std::size_t{n} * 16, "contacts");
  if (!coloring || !positions || !contacts) return state.SkipWithError("device buffers");
  std::vector<float> x(4 * s.movable.size(), 0.0f);
  for (std::size_t p = 0; p < s.movable.size(); ++p) x[4 * p + 3] = s.movable[p] ? 1.0f : 0.0f;
  (void)device.write_buffer(*positions, 0, x.data(), x.size() * 4);
  (void)device.write_buffer(*contacts, 0, s.particles.data(), s.particles.size() * 4);
  sinew::FrameProgram program;
  sinew::append_device_contact_coloring(program, *coloring, *contacts, *positions);
  auto prepared = device.create_program(program);
  if (!prepared) return state.SkipWithError(prepared.error().message().c_str());
  const auto run = [&] {
    // What a frame pays: the count written, the program run (a host-side
    // detection's upload of the contacts is not counted, as for the host's).
    if (sinew::Status st = device.write_buffer(coloring->table, std::size_t{coloring->count_word()} * 4, &n, 4); !st)
      return st;
    return device.run_program(*prepared);
  };
  if (sinew::Status st = run(); !st) return state.SkipWithError(st.error().message().c_str());  // warm-up
  for (auto _ : state)
    if (sinew::Status st = run(); !st) return state.SkipWithError(st.error().message().c_str());
  auto c = sinew::read_device_contact_coloring(device, *coloring);
  if (!c) return state.SkipWithError(c.error().message().c_str());
  report(state, *c, n);
  state.counters["dispatches"] = static_cast<double>(program.dispatch_count());
}
BENCHMARK(BM_DeviceJonesPlassmann)
    ->ArgsProduct({{0, 1}, {0, 1, 2}, {32, 64, 128}, {128, 254}})
    ->ArgNames({"pruned", "backend", "cap", "rounds"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

SINEW_BENCHMARK_MAIN("bench_contact_coloring",
                     "The kidney_57k surface's self-contacts coloured on the host (greedy) and on a device "
                     "(Jones-Plassmann, capped, with an overflow set): time, colours, overflow.")
