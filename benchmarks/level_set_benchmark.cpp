// level_set_benchmark — sampling a level set (issue 14, part 2): samples
// per second of value + gradient through the level_set_sample kernel on
// each backend, against OpenVDB's own BoxSampler (value only, one thread,
// through a value accessor) on the same points in the same run.
//
// The level set: the tibia (data/meshes/surface, mm scaled to m) at 0.5 mm
// voxels, 2 mm bands. The points, 2^20 of them: half near its surface (a
// vertex moved up to 2.5 mm), half anywhere in its box grown by 5 mm;
// order:0 in random order, order:1 sorted along a Morton curve of their
// voxel (as a body's particles, stored in a memory-friendly order, sit near
// their neighbours), which lets an accessor reuse its cached nodes.
// Counters: samples_per_s (and per thread for the one-thread rows).
// BM_CutTick: cutting the bone per haptic tick; BM_PenaltyContact: a burr's
// force against the bone on the host (below).
//
//   SINEW_BACKEND=cpu build/benchmarks/bench_level_set --benchmark_format=csv
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <openvdb/tools/Interpolation.h>

#include "backends/backend.h"
#include "bench_support.h"
#include "level_set/device_level_set.h"
#include "level_set/level_set_impl.h"
#include "level_set_params.h"
#include "sinew/mesh.h"
#include "benchmark_main.h"

namespace {

using namespace sinew;

constexpr double kVoxel = 5e-4;

struct Setup {
  LevelSet level_set;
  std::vector<std::array<float, 3>> random, sorted;
};

std::uint64_t spread(std::uint64_t v) {  // 21 bits to every third of 63
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

const Setup* setup() {
  static const Setup* made = []() -> const Setup* {
    auto mesh = read_stl(std::string(SINEW_DATA_DIR) + "/meshes/surface/VHF_Left_Bone_Tibia_smooth.stl");
    if (!mesh) return nullptr;
    scale_mesh(*mesh, 1e-3);
    auto level_set = LevelSet::from_mesh(*mesh, {.voxel_size = kVoxel, .exterior_band = 2e-3, .interior_band = 2e-3});
    if (!level_set) return nullptr;
    auto* s = new Setup{*level_set, {}, {}};
    const auto b = s->level_set.bounds();
    std::mt19937 rng(1);
    std::uniform_int_distribution<std::size_t> vertex(0, mesh->vertices.size() - 1);
    std::uniform_real_distribution<double> near(-2.5e-3, 2.5e-3), unit(0.0, 1.0);
    for (std::size_t q = 0; q < (std::size_t{1} << 20); ++q) {
      std::array<float, 3> p{};
      if (q % 2 == 0) {
        const auto& v = mesh->vertices[vertex(rng)];
        p = {float(v[0] + near(rng)), float(v[1] + near(rng)), float(v[2] + near(rng))};
      } else {
        for (int k = 0; k < 3; ++k) p[k] = float(b[k] - 5e-3 + unit(rng) * (b[k + 3] - b[k] + 1e-2));
      }
      s->random.push_back(p);
    }
    std::vector<std::pair<std::uint64_t, std::size_t>> keys;
    for (std::size_t q = 0; q < s->random.size(); ++q) {
      std::uint64_t key = 0;
      for (int k = 0; k < 3; ++k)
        key |= spread(std::uint64_t(std::int64_t(s->random[q][k] / kVoxel) + (1 << 20))) << k;
      keys.emplace_back(key, q);
    }
    std::sort(keys.begin(), keys.end());
    for (const auto& [key, q] : keys) s->sorted.push_back(s->random[q]);
    return s;
  }();
  return made;
}

void BM_OpenVdbBoxSampler(benchmark::State& state) {
  const Setup* s = setup();
  if (!s) {
    state.SkipWithError("the tibia level set could not be built");
    return;
  }
  const auto& points = state.range(0) == 1 ? s->sorted : s->random;
  const openvdb::FloatGrid& grid = *s->level_set.internals().grid;
  double sum = 0.0;
  for (auto _ : state) {
    openvdb::FloatGrid::ConstAccessor access = grid.getConstAccessor();
    const openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
        access, grid.transform());
    for (const auto& p : points) sum += sampler.wsSample(openvdb::Vec3R(p[0], p[1], p[2]));
  }
  benchmark::DoNotOptimize(sum);
  state.counters["samples_per_s"] =
      benchmark::Counter(double(points.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel("openvdb BoxSampler value only 1 thread");
}

void BM_KernelSample(benchmark::State& state) {
  const Setup* s = setup();
  if (!s) {
    state.SkipWithError("the tibia level set could not be built");
    return;
  }
  const auto& points = state.range(0) == 1 ? s->sorted : s->random;
  const int threads = static_cast<int>(state.range(1));
  auto device = create_device({.backend = bench::backend(), .threads = threads, .quiet = true});
  if (!device) {
    state.SkipWithError(device.error().message().c_str());
    return;
  }
  auto grid = upload_level_set(**device, s->level_set);
  if (!grid) {
    state.SkipWithError(grid.error().message().c_str());
    return;
  }
  std::vector<float> xyzw;
  for (const auto& p : points) xyzw.insert(xyzw.end(), {p[0], p[1], p[2], 0.0f});
  auto in = (*device)->create_buffer(xyzw.size() * 4, "points");
  auto out = (*device)->create_buffer(xyzw.size() * 4, "samples");
  if (!in || !out || !(*device)->write_buffer(*in, 0, xyzw.data(), xyzw.size() * 4)) {
    state.SkipWithError("buffers");
    return;
  }
  kernels::LevelSetSampleParams p{};
  p.count = static_cast<std::uint32_t>(points.size());
  p.inv_voxel = grid->inv_voxel;
  p.inv_two_voxel = grid->inv_two_voxel;
  FrameProgram program;
  program.dispatch(Kernel::level_set_sample, p.count, {grid->grid, *in, *out}, p);
  auto prepared = (*device)->create_program(program);
  if (!prepared || !(*device)->run_program(*prepared)) {  // a first run builds what the backend builds lazily
    state.SkipWithError("program");
    return;
  }
  for (auto _ : state)
    if (Status st = (*device)->run_program(*prepared); !st) {
      state.SkipWithError(st.error().message().c_str());
      return;
    }
  state.counters["samples_per_s"] =
      benchmark::Counter(double(points.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel(bench::backend() + (bench::backend() == "cpu" ? " " + std::to_string(threads) + " thread(s)" : ""));
}

// A haptic tick of bone cutting (issue 14, part 4): a 3 mm burr (radius
// 1.5 mm) plunging 1 mm per tick into the tibia's plateau, 20 mm deep,
// cut from the level set (0.5 or 0.25 mm voxels, range(0) in um; its whole
// inside stored) and the changed leaves written to the backend's copy.
// Counters: the median tick [ms] (cut_ms + upload_ms), the bytes written
// per tick, the voxels changed, the volume removed per tick [mm^3].
void BM_CutTick(benchmark::State& state) {
  const double voxel = double(state.range(0)) * 1e-6;
  auto mesh = read_stl(std::string(SINEW_DATA_DIR) + "/meshes/surface/VHF_Left_Bone_Tibia_smooth.stl");
  if (!mesh) {
    state.SkipWithError(mesh.error().message().c_str());
    return;
  }
  scale_mesh(*mesh, 1e-3);
  auto bone = LevelSet::from_mesh(*mesh, {.voxel_size = voxel, .exterior_band = 3.0 * voxel,
                                          .interior_band = std::numeric_limits<double>::infinity()});
  if (!bone) {
    state.SkipWithError(bone.error().message().c_str());
    return;
  }
  auto device = create_device({.backend = bench::backend(), .quiet = true});
  if (!device) {
    state.SkipWithError(device.error().message().c_str());
    return;
  }
  auto grid = upload_level_set(**device, *bone);
  if (!grid) {
    state.SkipWithError(grid.error().message().c_str());
    return;
  }
  // The top: the highest vertex (z is the bone's long axis), moved 5 mm
  // towards the bone's middle (onto the plateau). Each pass of 20 ticks
  // plunges the burr 1 mm per tick from where it first touches the bone;
  // the next pass is 4 mm over in y, into fresh bone.
  std::array<double, 3> top = mesh->vertices[0];
  for (const auto& v : mesh->vertices)
    if (v[2] > top[2]) top = v;
  const auto b = bone->bounds();
  for (int k = 0; k < 2; ++k) top[k] += top[k] < 0.5 * (b[k] + b[k + 3]) ? 5e-3 : -5e-3;
  std::vector<double> cut_ms, upload_ms, bytes, voxels, removed;
  int tick = 0;
  double y = top[1], z = top[2];
  for (auto _ : state) {
    if (tick % 20 == 0) {  // a new pass: the burr's centre where it first touches
      y = top[1] + 4e-3 * (tick / 20);
      for (z = top[2] + 3e-3; bone->value({top[0], y, z}) > 1.5e-3 && z > b[2]; z -= 1e-4) {
      }
    }
    ++tick;
    const Pose from{.position = {top[0], y, z}}, to{.position = {top[0], y, z - 1e-3}};
    z -= 1e-3;
    const auto t0 = std::chrono::steady_clock::now();
    auto report = bone->cut({.kind = CutterShape::Kind::sphere, .radius = 1.5e-3}, from, to);
    const auto t1 = std::chrono::steady_clock::now();
    std::uint64_t written = 0;
    if (!report || !update_level_set(**device, *grid, *bone, *report, &written)) {
      state.SkipWithError("cut");
      return;
    }
    const auto t2 = std::chrono::steady_clock::now();
    cut_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    upload_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    bytes.push_back(double(written));
    voxels.push_back(double(report->changed_voxels));
    removed.push_back(report->removed_volume * 1e9);
  }
  state.counters["cut_ms"] = bench::median(cut_ms);
  state.counters["upload_ms"] = bench::median(upload_ms);
  state.counters["bytes"] = bench::median(bytes);
  state.counters["voxels"] = bench::median(voxels);
  state.counters["removed_mm3"] = bench::median(removed);
  state.counters["grid_mb"] = double(grid->bytes) / 1e6;
  state.SetLabel(bench::backend());
}

// A burr against the bone on the host, as a haptic tick would compute it
// (penalty_contact): a 3 mm burr's surface points (its level set's zero
// level at range(0) um spacing) pressed 0.5 mm into the tibia's top (0.5 mm
// voxels, the inside stored). Counters: points, touching, the force [N].
void BM_PenaltyContact(benchmark::State& state) {
  const double spacing = double(state.range(0)) * 1e-6;
  auto mesh = read_stl(std::string(SINEW_DATA_DIR) + "/meshes/surface/VHF_Left_Bone_Tibia_smooth.stl");
  if (!mesh) {
    state.SkipWithError(mesh.error().message().c_str());
    return;
  }
  scale_mesh(*mesh, 1e-3);
  static const auto bone = LevelSet::from_mesh(
      *mesh, {.voxel_size = 5e-4, .exterior_band = 1.5e-3, .interior_band = std::numeric_limits<double>::infinity()});
  auto burr = LevelSet::sphere({0, 0, 0}, 1.5e-3, {.voxel_size = spacing, .exterior_band = 4 * spacing,
                                                   .interior_band = 4 * spacing});
  if (!bone || !burr) {
    state.SkipWithError("level sets");
    return;
  }
  const SurfacePoints points = surface_points(burr->surface());
  std::array<double, 3> top = mesh->vertices[0];
  for (const auto& v : mesh->vertices)
    if (v[2] > top[2]) top = v;
  PenaltyContact contact{};
  for (auto _ : state) {
    auto c = penalty_contact(*bone, points, {.position = {top[0], top[1], top[2] + 1e-3}}, 1e9);
    if (!c) {
      state.SkipWithError(c.error().message().c_str());
      return;
    }
    contact = *c;
  }
  state.counters["points"] = double(points.points.size());
  state.counters["touching"] = double(contact.touching);
  state.counters["force_n"] = std::hypot(contact.force[0], contact.force[1], contact.force[2]);
  state.SetLabel("host, 1 thread");
}

BENCHMARK(BM_OpenVdbBoxSampler)->ArgName("order")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_KernelSample)
    ->ArgNames({"order", "threads"})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({0, 2})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_CutTick)->ArgName("voxel_um")->Arg(500)->Arg(250)->Iterations(40)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PenaltyContact)->ArgName("spacing_um")->Arg(200)->Arg(100)->Arg(50)->Unit(benchmark::kMillisecond);

}  // namespace

SINEW_BENCHMARK_MAIN("bench_level_set",
                     "Sampling a level set (the tibia at 0.5 mm voxels): samples per second of value + gradient on each\nbackend, against OpenVDB's own BoxSampler on the same 2^20 points.")
