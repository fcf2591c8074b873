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
//                      twice the inflation, one thread)
// Each counts the boxes' computation too, and reports the pairs found.
//   bench_broad_phase --benchmark_out=broad.csv --benchmark_out_format=csv
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "collision/bvh.h"
#include "collision/narrow_phase.h"
#include "collision/parallel_pairs.h"
#if SINEW_HAS_EMBREE
#include "collision/embree_broad_phase.h"
#endif
#include "sinew/mesh.h"

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

enum Variant { kReferenceRefit, kReferenceRebuild, kEmbreeRefit, kEmbreeRebuild, kParallelRefit, kParallelRefitNarrow };

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
  int frame = 0;
  for (auto _ : state) {
    state.PauseTiming();
    deform(s, x, ++frame);
    state.ResumeTiming();
    (void)primitive_boxes(x, s.triangles, 3, inflate, boxes);
    switch (variant) {
      case kReferenceRefit:
      case kParallelRefit:
      case kParallelRefitNarrow: tree.refit(boxes); break;
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
      if (variant == kParallelRefitNarrow) (void)triangle_contacts(x, s.triangles, pairs, 2.0f * inflate, contacts);
    } else {
#if SINEW_HAS_EMBREE
      (void)embree_self_pairs(*set, skip, pairs);
#endif
    }
    benchmark::DoNotOptimize(pairs.data());
  }
  static const char* names[] = {"reference refit", "reference rebuild", "Embree refit", "Embree rebuild",
                                "parallel refit (TBB, unsorted)", "parallel refit + narrow phase (1 thread)"};
  state.SetLabel(std::string(state.range(0) == 0 ? "kidney_57k" : "liver_382k") + " surface, " + names[variant]);
  state.counters["triangles"] = double(s.triangles.size() / 3);
  state.counters["pairs"] = double(pairs.size());
  // Every run reports the same counters (the CSV reporter requires it): 0
  // contacts where the narrow phase does not run.
  state.counters["contacts"] = double(contacts.size());
}

BENCHMARK(BM_SelfBroadPhase)
    ->ArgsProduct({{0, 1}, {kReferenceRefit, kReferenceRebuild, kEmbreeRefit, kEmbreeRebuild, kParallelRefit, kParallelRefitNarrow}})
    ->ArgNames({"mesh", "variant"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
