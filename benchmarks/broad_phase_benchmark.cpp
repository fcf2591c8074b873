// broad_phase_benchmark — the self-collision broad phase of one surface per
// frame (issue 12): the liver_382k boundary (105,266 triangles) and the
// kidney_57k boundary (19,126), deformed smoothly every iteration (a
// bending organ), boxes inflated by a tenth of the mean edge. Variants,
// all producing the same pairs (tests/bvh_test.cpp):
//   Reference/refit    collision::Bvh refit + self traversal
//   Reference/rebuild  collision::Bvh build + self traversal
//   Embree/refit       Embree refit + rtcCollide + exact re-test
//   Embree/rebuild     Embree build + rtcCollide + exact re-test
//   Parallel/refit     collision::Bvh refit + the TBB self query (unsorted)
//   + narrow           and the triangle contacts of those pairs (thickness =
//                      twice the inflation, on TBB's threads)
//   Culled/refit       Parallel/refit skipping the flat patches
//                      (collision/normal_cones.h; their update counted)
//   + narrow           and the contacts of those pairs: the goal,
//                      refit + pairs + narrow phase, as the solver runs it
//                      (the vertices gathered in the tree's leaf order, the
//                      cones updated beside the boxes and the refit,
//                      pairs closer than the thickness in the rest shape
//                      skipped by the traversal, collision/rest_close.h)
// Each counts the boxes' computation too, and reports the pairs found.
// BM_KidneyOnLiver: the kidney surface sunk 5 mm into the liver surface
// (both bending), the pairs between them and their contacts (issue 12,
// part 5: kidney against liver), with the reference BVHs refitted, Embree
// refitted and Embree rebuilt; contacts at twice the inflation, on TBB's
// threads.
// BM_DeviceSelfBroadPhase: the same self-collision frame with the BVH on a
// device (collision/device_bvh.h: Karras's build, the refit and the
// bvh_self_pairs traversal in kernels) on each backend built: the boxes
// computed on the host and written, the tree refitted (or rebuilt), the
// pairs found, read back and sorted; or, with narrow:1, the narrow phase
// run on the device over them too (collision/device_narrow_phase.h) and
// the contacts read back instead.
//   bench_broad_phase --benchmark_out=broad.csv --benchmark_out_format=csv
#include <benchmark/benchmark.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "backends/backend.h"
#include "collision/bvh.h"
#include "collision/leaf_vertices.h"
#include "collision/device_bvh.h"
#include "collision/device_narrow_phase.h"
#include "collision/narrow_phase.h"
#include "collision/normal_cones.h"
#include "collision/parallel_pairs.h"
#include "collision/rest_close.h"
#if SINEW_HAS_EMBREE
#include "collision/embree_broad_phase.h"
#endif
#include "sinew/mesh.h"
#include "benchmark_main.h"

namespace {

using namespace sinew::collision;

struct Surface {
  std::vector<float> rest, positions;
  std::vector<std::uint32_t> triangles;
  float mean_edge = 0.0f;
  float size = 1.0f;  // extent along x (the mesh's units)
};

const Surface& surface(int which) {
  static std::map<int, Surface> cache;
  if (auto it = cache.find(which); it != cache.end()) return it->second;
  Surface& s = cache[which];
  const std::string file = std::string(SINEW_DATA_DIR) + (which == 0 ? "/meshes/tet/kidney_57k.node" : "/meshes/tet/liver_382k.node");
  auto mesh = sinew::read_tet_mesh(file);
  if (!mesh) return s;
  const sinew::TriMesh tri = sinew::extract_boundary_surface(*mesh);
  for (const auto& v : tri.vertices) s.rest.insert(s.rest.end(), {float(v[0]), float(v[1]), float(v[2]), 0.0f});
  double sum = 0.0;
  for (const auto& t : tri.triangles) {
    s.triangles.insert(s.triangles.end(), t.begin(), t.end());
    const auto& a = tri.vertices[t[0]];
    const auto& b = tri.vertices[t[1]];
    sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
  }
  s.mean_edge = float(sum / double(tri.triangles.size()));
  float lo = INFINITY, hi = -INFINITY;
  for (std::size_t v = 0; v < s.rest.size(); v += 4) lo = std::min(lo, s.rest[v]), hi = std::max(hi, s.rest[v]);
  s.size = hi - lo;
  s.positions = s.rest;
  return s;
}

// A deformation: every vertex moved from its rest position by a smooth
// field (one wave across the organ) of amplitude two mean edges, different
// each frame: the organ bends, its triangles keep their neighbours.
void deform(const Surface& s, std::vector<float>& x, int frame) {
  x = s.rest;
  const float a = 2.0f * s.mean_edge, k = 6.2831853f / s.size;
  for (std::size_t v = 0; v < x.size() / 4; ++v) {
    const float* r = &s.rest[4 * v];
    x[4 * v + 0] += a * std::sin(k * r[1] + 0.1f * float(frame));
    x[4 * v + 1] += a * std::sin(k * r[2] + 0.2f * float(frame));
    x[4 * v + 2] += a * std::sin(k * r[0] + 0.3f * float(frame));
  }
}

enum Variant {
  kReferenceRefit,
  kReferenceRebuild,
  kEmbreeRefit,
  kEmbreeRebuild,
  kParallelRefit,
  kParallelRefitNarrow,
  kCulledRefit,
  kCulledRefitNarrow
};

void BM_SelfBroadPhase(benchmark::State& state) {
  const Surface& s = surface(int(state.range(0)));
  const auto variant = Variant(state.range(1));
  if (s.triangles.empty()) {
    state.SkipWithError("mesh not found");
    return;
  }
  const float inflate = 0.1f * s.mean_edge;  // a contact distance of a tenth of an edge
  const SharesVertex skip{s.triangles};
  std::vector<float> x;
  std::vector<Aabb> boxes;
  deform(s, x, 0);
  (void)primitive_boxes(x, s.triangles, 3, inflate, boxes);
  Bvh tree;
  tree.build(boxes);
#if SINEW_HAS_EMBREE
  auto made = EmbreeBoxes::create();
  if (!made) {
    state.SkipWithError(made.error().message().c_str());
    return;
  }
  auto& set = *made;
  (void)set->build(boxes);
#else
  if (variant == kEmbreeRefit || variant == kEmbreeRebuild) {
    state.SkipWithError("built without Embree");
    return;
  }
#endif
  std::vector<Pair> pairs;
  std::vector<Contact> contacts;
  const TriangleOwnership ownership = triangle_ownership(s.triangles);  // once per mesh, as the solver does
  NormalCones cones;
  cones.update(tree, s.triangles, x);  // the connectivity, once per build, as the solver does
  std::vector<Pair> close;  // once per scene, as the solver does
  if (variant == kCulledRefitNarrow) (void)rest_close_pairs(s.rest, s.triangles, 2.0f * inflate, close);
  const PairSet rest_close(close, std::uint32_t(s.triangles.size() / 3));
  const SharesVertexOrListed<3> skip_rest_close{skip, &rest_close};
  LeafVertices leaf;
  int frame = 0;
  for (auto _ : state) {
    state.PauseTiming();
    deform(s, x, ++frame);
    state.ResumeTiming();
    if (variant == kCulledRefitNarrow) {
      // The solver's order (runtime/mesh_collision.cpp): the vertices
      // gathered in the tree's leaf order (leaf_vertices.h), the cones
      // beside the boxes and the refit, on the second core; then the pairs
      // (rest-close ones skipped) and their contacts.
      (void)leaf.index(tree, s.triangles, 3);
      (void)leaf.gather(x);
      tbb::parallel_invoke([&] { leaf.boxes(inflate, boxes), (void)tree.refit_leaves(boxes); },
                           [&] { cones.update(tree, s.triangles, leaf); });
      self_overlapping_pairs_parallel(tree, skip_rest_close, pairs, &cones);
      (void)triangle_contacts(x, s.triangles, ownership, pairs, 2.0f * inflate, contacts);
      benchmark::DoNotOptimize(contacts.data());
      continue;
    }
    (void)primitive_boxes(x, s.triangles, 3, inflate, boxes);
    switch (variant) {
      case kReferenceRefit:
      case kParallelRefit:
      case kParallelRefitNarrow:
      case kCulledRefit: tree.refit(boxes); break;
      case kCulledRefitNarrow: break;  // above
      case kReferenceRebuild: tree.build(boxes); break;
#if SINEW_HAS_EMBREE
      case kEmbreeRefit: (void)set->refit(boxes); break;
      case kEmbreeRebuild: (void)set->build(boxes); break;
#else
      default: break;
#endif
    }
    if (variant <= kReferenceRebuild) {
      self_overlapping_pairs(tree, skip, pairs);
    } else if (variant == kParallelRefit || variant == kParallelRefitNarrow) {
      self_overlapping_pairs_parallel(tree, skip, pairs);
      if (variant == kParallelRefitNarrow)
        (void)triangle_contacts(x, s.triangles, ownership, pairs, 2.0f * inflate, contacts);
    } else if (variant == kCulledRefit) {
      cones.update(tree, s.triangles, x);
      self_overlapping_pairs_parallel(tree, skip, pairs, &cones);
    } else {
#if SINEW_HAS_EMBREE
      (void)embree_self_pairs(*set, skip, pairs);
#endif
    }
    benchmark::DoNotOptimize(pairs.data());
  }
  static const char* names[] = {"reference refit", "reference rebuild", "Embree refit", "Embree rebuild",
                                "parallel refit (TBB, unsorted)", "parallel refit + narrow phase",
                                "culled parallel refit", "culled parallel refit + narrow phase (rest-close pairs skipped)"};
  state.SetLabel(std::string(state.range(0) == 0 ? "kidney_57k" : "liver_382k") + " surface, " + names[variant]);
  state.counters["triangles"] = double(s.triangles.size() / 3);
  state.counters["pairs"] = double(pairs.size());
  // Every run reports the same counters (the CSV reporter requires it): 0
  // contacts where the narrow phase does not run.
  state.counters["contacts"] = double(contacts.size());
}

// The kidney's surface placed over the middle of the liver's, sunk `depth`
// [mesh units] below the liver's highest point under its footprint.
const Surface& kidney_on_liver(float depth) {
  static Surface placed;
  if (!placed.triangles.empty()) return placed;
  const Surface& liver = surface(1);
  placed = surface(0);
  if (placed.triangles.empty() || liver.triangles.empty()) return placed;
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  float klo[3] = {INFINITY, INFINITY, INFINITY}, khi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t v = 0; v < liver.rest.size(); v += 4)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], liver.rest[v + k]), hi[k] = std::max(hi[k], liver.rest[v + k]);
  for (std::size_t v = 0; v < placed.rest.size(); v += 4)
    for (int k = 0; k < 3; ++k) klo[k] = std::min(klo[k], placed.rest[v + k]), khi[k] = std::max(khi[k], placed.rest[v + k]);
  const float cx = 0.5f * (lo[0] + hi[0]), cz = 0.5f * (lo[2] + hi[2]);
  float under = lo[1];
  for (std::size_t v = 0; v < liver.rest.size(); v += 4)
    if (std::abs(liver.rest[v] - cx) <= 0.5f * (khi[0] - klo[0]) && std::abs(liver.rest[v + 2] - cz) <= 0.5f * (khi[2] - klo[2]))
      under = std::max(under, liver.rest[v + 1]);
  const float shift[3] = {cx - 0.5f * (klo[0] + khi[0]), under - depth - klo[1], cz - 0.5f * (klo[2] + khi[2])};
  for (std::size_t v = 0; v < placed.rest.size(); v += 4)
    for (int k = 0; k < 3; ++k) placed.rest[v + k] += shift[k];
  placed.positions = placed.rest;
  return placed;
}

enum PairVariant { kPairsReference, kPairsEmbreeRefit, kPairsEmbreeRebuild };

void BM_KidneyOnLiver(benchmark::State& state) {
  const Surface& liver = surface(1);
  const Surface& kidney = kidney_on_liver(5.0f);  // the meshes are in millimetres
  const auto variant = PairVariant(state.range(0));
  const bool narrow = state.range(1) != 0;
  if (liver.triangles.empty() || kidney.triangles.empty()) {
    state.SkipWithError("mesh not found");
    return;
  }
  const float inflate = 0.1f * liver.mean_edge;
  // One position array holding both surfaces (the kidney's vertices after
  // the liver's), as the solver's particles are.
  const auto liver_vertices = static_cast<std::uint32_t>(liver.rest.size() / 4);
  std::vector<std::uint32_t> kidney_triangles(kidney.triangles);
  for (auto& v : kidney_triangles) v += liver_vertices;
  std::vector<float> x, xl, xk;
  std::vector<Aabb> boxes_l, boxes_k;
  const auto place = [&](int frame) {
    deform(liver, xl, frame);
    deform(kidney, xk, frame);
    x = xl;
    x.insert(x.end(), xk.begin(), xk.end());
  };
  place(0);
  (void)primitive_boxes(x, liver.triangles, 3, inflate, boxes_l);
  (void)primitive_boxes(x, kidney_triangles, 3, inflate, boxes_k);
  Bvh tree_l, tree_k;
  tree_l.build(boxes_l);
  tree_k.build(boxes_k);
#if SINEW_HAS_EMBREE
  auto made_l = EmbreeBoxes::create();
  auto made_k = EmbreeBoxes::create();
  if (!made_l || !made_k) {
    state.SkipWithError("Embree device");
    return;
  }
  (void)(*made_l)->build(boxes_l);
  (void)(*made_k)->build(boxes_k);
#else
  if (variant != kPairsReference) {
    state.SkipWithError("built without Embree");
    return;
  }
#endif
  // The narrow phase takes one triangle list: the liver's, then the kidney's.
  std::vector<std::uint32_t> all(liver.triangles);
  all.insert(all.end(), kidney_triangles.begin(), kidney_triangles.end());
  const auto offset = static_cast<std::uint32_t>(liver.triangles.size() / 3);
  const TriangleOwnership ownership = triangle_ownership(all);
  std::vector<Pair> pairs, shifted;
  std::vector<Contact> contacts;
  int frame = 0;
  for (auto _ : state) {
    state.PauseTiming();
    place(++frame);
    state.ResumeTiming();
    (void)primitive_boxes(x, liver.triangles, 3, inflate, boxes_l);
    (void)primitive_boxes(x, kidney_triangles, 3, inflate, boxes_k);
    switch (variant) {
      case kPairsReference:
        tree_l.refit(boxes_l);
        tree_k.refit(boxes_k);
        overlapping_pairs(tree_k, tree_l, pairs);
        break;
#if SINEW_HAS_EMBREE
      case kPairsEmbreeRefit:
        (void)(*made_l)->refit(boxes_l);
        (void)(*made_k)->refit(boxes_k);
        (void)embree_pairs(**made_k, **made_l, pairs);
        break;
      case kPairsEmbreeRebuild:
        (void)(*made_l)->build(boxes_l);
        (void)(*made_k)->build(boxes_k);
        (void)embree_pairs(**made_k, **made_l, pairs);
        break;
#endif
      default: break;
    }
    if (narrow) {
      shifted.resize(pairs.size());
      for (std::size_t i = 0; i < pairs.size(); ++i) shifted[i] = {pairs[i].first + offset, pairs[i].second};
      (void)triangle_contacts(x, all, ownership, shifted, 2.0f * inflate, contacts);
    }
    benchmark::DoNotOptimize(pairs.data());
  }
  static const char* names[] = {"reference refit", "Embree refit", "Embree rebuild"};
  state.SetLabel(std::string("kidney_57k on liver_382k, ") + names[variant] + (narrow ? " + narrow phase" : ""));
  state.counters["triangles"] = double((liver.triangles.size() + kidney.triangles.size()) / 3);
  state.counters["pairs"] = double(pairs.size());
  state.counters["contacts"] = double(contacts.size());
}

// The self broad phase of BM_SelfBroadPhase with the device BVH: range(0)
// the mesh (0 kidney, 1 liver), range(1) the backend (0 cpu, 1 opencl, 2
// vulkan), range(2) 1 to rebuild the tree every frame, 0 to refit it,
// range(3) 1 to add the narrow phase on the device
// (collision/device_narrow_phase.h; thickness twice the inflation, as the
// host's "+ narrow" rows): the positions written too, the contacts read
// back (sorted, duplicates removed) instead of the pairs. No normal cones
// or rest-close pairs on the device: it tests every self pair.
void BM_DeviceSelfBroadPhase(benchmark::State& state) {
  const Surface& s = surface(int(state.range(0)));
  static const char* backends[] = {"cpu", "opencl", "vulkan"};
  const char* backend = backends[state.range(1)];
  const bool rebuild = state.range(2) != 0;
  const bool narrow = state.range(3) != 0;
  if (s.triangles.empty()) {
    state.SkipWithError("mesh not found");
    return;
  }
  auto made = sinew::create_device({.backend = backend, .quiet = true});
  if (!made) {
    state.SkipWithError(made.error().message().c_str());
    return;
  }
  sinew::Device& device = **made;
  const float inflate = 0.1f * s.mean_edge;
  std::vector<float> x;
  std::vector<Aabb> boxes;
  deform(s, x, 0);
  (void)primitive_boxes(x, s.triangles, 3, inflate, boxes);
  const auto n = static_cast<std::uint32_t>(boxes.size());
  // Build bounds: the rest surface grown by the deformation's reach
  // (centres outside would only be clamped).
  std::array<float, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t v = 0; v < s.rest.size(); v += 4)
    for (std::size_t k = 0; k < 3; ++k) lo[k] = std::min(lo[k], s.rest[v + k]), hi[k] = std::max(hi[k], s.rest[v + k]);
  for (std::size_t k = 0; k < 3; ++k) lo[k] -= 3.0f * s.mean_edge, hi[k] += 3.0f * s.mean_edge;
  // Room for four times the pairs of the first frame.
  Bvh tree;
  tree.build(boxes);
  std::vector<Pair> pairs;
  self_overlapping_pairs(tree, SharesVertex{s.triangles}, pairs);
  const auto capacity = static_cast<std::uint32_t>(4 * pairs.size() + 1024);
  auto bvh = make_device_bvh(device, n);
  auto ids = device.create_buffer(s.triangles.size() * 4, "vertex ids");
  auto pair_buffer = device.create_buffer(std::size_t{capacity} * 8, "pairs");
  auto counter = device.create_buffer(16, "pair and contact counters");
  auto positions = device.create_buffer(s.rest.size() * 4, "positions");
  if (!bvh || !ids || !pair_buffer || !counter || !positions) {
    state.SkipWithError("device buffers");
    return;
  }
  (void)device.write_buffer(*ids, 0, s.triangles.data(), s.triangles.size() * 4);
  const sinew::DeviceCount count{*counter, 0, capacity};
  auto triangles = make_device_triangles(device, s.triangles);
  auto contact_room = make_device_contacts(device, capacity, *counter, 1);  // as many as pairs
  if (!triangles || !contact_room) {
    state.SkipWithError("device narrow phase buffers");
    return;
  }
  // The first frame builds; the timed frames rebuild or only refit.
  const auto program_of = [&](bool build) -> sinew::Result<sinew::ProgramHandle> {
    sinew::FrameProgram program;
    if (build) {
      if (sinew::Status st = append_device_bvh_build(program, *bvh, n, lo, hi); !st) return st.error();
    }
    if (sinew::Status st = append_device_bvh_refit(program, *bvh, n); !st) return st.error();
    if (sinew::Status st = append_device_bvh_self_pairs(program, *bvh, n, *ids, *pair_buffer, count); !st)
      return st.error();
    if (narrow)
      if (sinew::Status st = append_device_triangle_contacts(program, *positions, *triangles, *pair_buffer, count,
                                                             *contact_room, 2.0f * inflate);
          !st)
        return st.error();
    return device.create_program(program);
  };
  auto first = program_of(true);
  auto frame_program = program_of(rebuild);
  if (!first || !frame_program) {
    state.SkipWithError("device program");
    return;
  }
  const auto f = [](const std::vector<Aabb>& b) {
    std::vector<float> words;
    words.reserve(6 * b.size());
    for (const Aabb& a : b) words.insert(words.end(), {a.lo[0], a.lo[1], a.lo[2], a.hi[0], a.hi[1], a.hi[2]});
    return words;
  };
  std::vector<float> words = f(boxes);
  (void)device.write_buffer(bvh->boxes, 0, words.data(), words.size() * 4);
  (void)device.write_buffer(*positions, 0, x.data(), x.size() * 4);
  std::vector<Contact> contacts;
  if (!device.run_program(*first)) {
    state.SkipWithError("first frame failed");
    return;
  }
  int frame = 0;
  for (auto _ : state) {
    state.PauseTiming();
    deform(s, x, ++frame);
    state.ResumeTiming();
    (void)primitive_boxes(x, s.triangles, 3, inflate, boxes);
    words = f(boxes);
    (void)device.write_buffer(bvh->boxes, 0, words.data(), words.size() * 4);
    if (narrow) (void)device.write_buffer(*positions, 0, x.data(), x.size() * 4);
    if (sinew::Status st = device.run_program(*frame_program); !st) {
      state.SkipWithError(st.error().message().c_str());
      break;
    }
    if (narrow) {
      auto made_contacts = read_device_contacts(device, *contact_room, count);
      if (!made_contacts) {
        state.SkipWithError(made_contacts.error().message().c_str());
        break;
      }
      contacts = std::move(*made_contacts);
      benchmark::DoNotOptimize(contacts.data());
      continue;
    }
    auto found = read_device_bvh_pairs(device, *pair_buffer, count);
    if (!found) {
      state.SkipWithError(found.error().message().c_str());
      break;
    }
    pairs = std::move(*found);
    benchmark::DoNotOptimize(pairs.data());
  }
  state.SetLabel(std::string(state.range(0) == 0 ? "kidney_57k" : "liver_382k") + " surface, device BVH on " + backend +
                 (rebuild ? ", rebuild" : ", refit") + (narrow ? " + narrow phase" : ""));
  state.counters["triangles"] = double(s.triangles.size() / 3);
  std::uint32_t found_pairs = 0;  // the last frame's (narrow: not read back, the counter only)
  (void)device.read_buffer(*counter, 0, &found_pairs, 4);
  state.counters["pairs"] = double(found_pairs);
  state.counters["contacts"] = double(contacts.size());  // 0 without the narrow phase (the CSV wants every column)
}

BENCHMARK(BM_KidneyOnLiver)
    ->ArgsProduct({{kPairsReference, kPairsEmbreeRefit, kPairsEmbreeRebuild}, {0, 1}})
    ->ArgNames({"variant", "narrow"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK(BM_SelfBroadPhase)
    ->ArgsProduct({{0, 1},
                   {kReferenceRefit, kReferenceRebuild, kEmbreeRefit, kEmbreeRebuild, kParallelRefit,
                    kParallelRefitNarrow, kCulledRefit, kCulledRefitNarrow}})
    ->ArgNames({"mesh", "variant"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK(BM_DeviceSelfBroadPhase)
    ->ArgsProduct({{0, 1}, {0, 1, 2}, {0, 1}, {0, 1}})
    ->ArgNames({"mesh", "backend", "rebuild", "narrow"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

SINEW_BENCHMARK_MAIN("bench_broad_phase",
                     "Self-collision broad phase of an organ surface (kidney_57k, liver_382k bent by a wave each frame):\nthe reference BVH against Embree, boxes + refit or rebuild + traversal + sort.")
