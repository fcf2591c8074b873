// device_bvh_test.cpp — the kernels that build a BVH on the device
// (kernels/shared/bvh_params.h, Karras HPG 2012): the Morton codes equal
// codes interleaved bit by bit here, the internal nodes form a valid binary
// tree over the sorted leaves (every node reached once, each covering a
// contiguous range split where its keys first differ), with duplicate
// codes too; every GPU backend gives the CPU reference's bits. The
// traversals (bvh_self_pairs, bvh_tree_pairs) find exactly the pairs of the
// CPU reference BVH and the brute force (collision/bvh.h) on every backend,
// on the boundary surfaces of the real meshes and on degenerate boxes; a
// capacity below the pair count is a capacity_exceeded error with the
// exact count, and nothing is written past the capacity.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <random>
#include <vector>

#include "agreement_support.h"
#include "bvh_params.h"
#include "collision/aabb.h"
#include "collision/bvh.h"
#include "collision/device_bvh.h"
#include "device_bvh_support.h"
#include "program/primitives.h"
#include "surface_support.h"
#include "test_support.h"

namespace sinew::test {
namespace {

using kernels::KarrasParams;
using kernels::MortonParams;

std::vector<std::uint32_t> words_of(const std::vector<float>& w) {
  std::vector<std::uint32_t> u(w.size());
  std::memcpy(u.data(), w.data(), w.size() * 4);
  return u;
}

KernelCase morton_case(std::mt19937& rng, std::uint32_t n) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> boxes;
  for (std::uint32_t i = 0; i < n; ++i) {
    float c[3], h = 0.01f * (u(rng) + 1.0f);
    for (float& x : c) x = u(rng);
    if (i % 17 == 3) c[0] = 5.0f;  // outside the bounds given: clamped to the last cell
    boxes.insert(boxes.end(), {c[0] - h, c[1] - h, c[2] - h, c[0] + h, c[1] + h, c[2] + h});
  }
  MortonParams p{};
  p.count = n;
  p.lo_x = p.lo_y = p.lo_z = -1.0f;
  p.inv_extent_x = p.inv_extent_y = p.inv_extent_z = 0.5f;
  KernelCase c{Kernel::bvh_morton_codes, n, {}, bytes_of(p)};
  c.bindings.push_back({boxes, false});
  c.bindings.push_back({std::vector<float>(n), true});
  c.bindings.push_back({std::vector<float>(n), true});
  return c;
}

// Interleaving bit by bit (x in bit 3k + 2, y in 3k + 1, z in 3k).
std::uint32_t interleave(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  std::uint32_t code = 0;
  for (int k = 0; k < 10; ++k)
    code |= ((x >> k) & 1u) << (3 * k + 2) | ((y >> k) & 1u) << (3 * k + 1) | ((z >> k) & 1u) << (3 * k);
  return code;
}

TEST(DeviceBvh, MortonCodesInterleaveTheCellsOfTheCentre) {
  std::mt19937 rng(41);
  const KernelCase c = morton_case(rng, 1000);
  const auto out = run_on("cpu", c);
  ASSERT_EQ(out.size(), 3u);
  const auto codes = words_of(out[1]), indices = words_of(out[2]);
  for (std::uint32_t i = 0; i < 1000; ++i) {
    const float* b = &c.bindings[0].data[6 * i];
    std::uint32_t cell[3];
    for (int k = 0; k < 3; ++k) {
      const double t = (0.5 * (double(b[k]) + double(b[k + 3])) + 1.0) * 0.5 * 1024.0;
      cell[k] = t <= 0.0 ? 0u : t >= 1023.0 ? 1023u : std::uint32_t(t);
    }
    // The kernel rounds in float: a centre within float rounding of a cell
    // boundary may land in the neighbouring cell.
    const std::uint32_t want = interleave(cell[0], cell[1], cell[2]);
    if (codes[i] != want) {
      bool neighbour = false;
      for (int dx = -1; dx <= 1 && !neighbour; ++dx)
        for (int dy = -1; dy <= 1 && !neighbour; ++dy)
          for (int dz = -1; dz <= 1 && !neighbour; ++dz)
            neighbour = codes[i] == interleave(std::min(1023u, cell[0] + dx), std::min(1023u, cell[1] + dy),
                                               std::min(1023u, cell[2] + dz));
      EXPECT_TRUE(neighbour) << "primitive " << i;
    }
    EXPECT_EQ(indices[i], i);
    EXPECT_LT(codes[i], 1u << 30);
  }
}

KernelCase karras_case(std::mt19937& rng, std::uint32_t n, std::uint32_t distinct) {
  std::vector<std::uint32_t> codes(n);
  for (auto& k : codes) k = std::uint32_t(rng() % distinct) * (0x3FFFFFFFu / distinct);  // duplicates when distinct < n
  std::sort(codes.begin(), codes.end());
  KarrasParams p{};
  p.count = n;
  KernelCase c{Kernel::bvh_karras_nodes, n - 1, {}, bytes_of(p)};
  c.bindings.push_back({as_words(codes), false});
  c.bindings.push_back({std::vector<float>(2 * (n - 1)), true});
  c.bindings.push_back({std::vector<float>(2 * n - 1), true});
  return c;
}

// Walks the tree from the root: every node once, each node's parent
// right, leaves in sorted order (so each node covers a contiguous range),
// and each node whose range holds different codes split where their
// highest differing bit flips (Karras's construction).
void expect_valid_tree(const std::vector<std::uint32_t>& codes, const std::vector<std::uint32_t>& children,
                       const std::vector<std::uint32_t>& parents, std::uint32_t n) {
  ASSERT_EQ(parents[0], SINEW_BVH_NONE);
  std::vector<int> seen(n - 1, 0);
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const std::uint32_t node = stack.back();
    stack.pop_back();
    ASSERT_LT(node, n - 1);
    ASSERT_EQ(seen[node]++, 0) << "internal node " << node << " reached twice";
    for (int side = 1; side >= 0; --side) {  // left first in the walk
      const std::uint32_t c = children[2 * node + side];
      const std::uint32_t slot = (c & SINEW_BVH_LEAF) ? (n - 1) + (c & ~SINEW_BVH_LEAF) : c;
      ASSERT_EQ(parents[slot], node) << "parent of child " << c;
      if (!(c & SINEW_BVH_LEAF)) stack.push_back(c);
    }
  }
  for (std::uint32_t i = 0; i + 1 < n; ++i) ASSERT_EQ(seen[i], 1) << "internal node " << i << " not reached";
  // In-order leaves: 0, 1, ..., n - 1 (the sorted order), each once.
  std::vector<std::uint32_t> in_order;
  std::vector<std::pair<std::uint32_t, bool>> walk{{0, false}};
  while (!walk.empty()) {
    auto [c, leaf] = walk.back();
    walk.pop_back();
    if (leaf) {
      in_order.push_back(c);
      continue;
    }
    for (int side = 1; side >= 0; --side) {
      const std::uint32_t child = children[2 * c + side];
      walk.push_back({child & ~SINEW_BVH_LEAF, (child & SINEW_BVH_LEAF) != 0});
    }
  }
  ASSERT_EQ(in_order.size(), n);
  for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(in_order[i], i);
  // The first and last leaf under each child (depth <= 64: recursion is fine).
  const std::function<std::uint32_t(std::uint32_t, int)> end_leaf = [&](std::uint32_t c, int side) -> std::uint32_t {
    return (c & SINEW_BVH_LEAF) ? (c & ~SINEW_BVH_LEAF) : end_leaf(children[2 * c + std::uint32_t(side)], side);
  };
  for (std::uint32_t i = 0; i + 1 < n; ++i) {
    const std::uint32_t first = end_leaf(children[2 * i], 0), split = end_leaf(children[2 * i], 1);
    const std::uint32_t last = end_leaf(children[2 * i + 1], 1);
    ASSERT_EQ(end_leaf(children[2 * i + 1], 0), split + 1) << "node " << i << ": its children's ranges meet";
    if (codes[first] == codes[last]) continue;  // equal codes: split by position
    const int bit = 31 - std::countl_zero(codes[first] ^ codes[last]);
    ASSERT_EQ((codes[split] >> bit) & 1u, 0u) << "node " << i << ": left child past the split bit";
    ASSERT_EQ((codes[split + 1] >> bit) & 1u, 1u) << "node " << i << ": right child before the split bit";
  }
}

TEST(DeviceBvh, KarrasNodesFormAValidTreeOverTheSortedLeaves) {
  std::mt19937 rng(43);
  for (std::uint32_t n : {2u, 3u, 7u, 100u, 1000u, 4097u})
    for (std::uint32_t distinct : {n, std::max(1u, n / 8), 1u}) {  // all distinct, many duplicates, all equal
      const KernelCase c = karras_case(rng, n, distinct);
      const auto out = run_on("cpu", c);
      ASSERT_EQ(out.size(), 3u);
      SCOPED_TRACE("n " + std::to_string(n) + ", distinct " + std::to_string(distinct));
      expect_valid_tree(words_of(c.bindings[0].data), words_of(out[1]), words_of(out[2]), n);
    }
}

// Every GPU backend writes the CPU reference's bits.
TEST_P(Agreement, DeviceBvhKernels) {
  std::mt19937 rng(47);
  for (const KernelCase& c : {morton_case(rng, 3001), karras_case(rng, 3001, 3001), karras_case(rng, 3001, 200)}) {
    const auto ref = run_on("cpu", c), gpu = run_on(GetParam(), c);
    ASSERT_EQ(ref.size(), gpu.size());
    for (std::size_t b = 0; b < ref.size(); ++b)
      EXPECT_EQ(0, std::memcmp(ref[b].data(), gpu[b].data(), ref[b].size() * 4))
          << kernel_name(c.kernel) << ": binding " << b << " differs from the CPU reference";
  }
}

struct BuiltBvh {
  std::vector<std::uint32_t> codes, indices, children, parents;
  std::vector<float> node_boxes;
};

// The whole build on one backend: boxes in, sorted codes, leaf order and
// the tree out.
BuiltBvh build_on(const std::string& backend, const std::vector<float>& boxes, std::uint32_t n) {
  BuiltBvh r;
  auto made = create_device({.backend = backend, .quiet = true});
  EXPECT_TRUE(made.ok()) << made.error().message();
  if (!made.ok()) return r;
  Device& device = **made;
  auto bvh = collision::make_device_bvh(device, n + 5);  // a little spare capacity
  EXPECT_TRUE(bvh.ok());
  if (!bvh.ok()) return r;
  EXPECT_TRUE(device.write_buffer(bvh->boxes, 0, boxes.data(), boxes.size() * 4).ok());
  FrameProgram program;
  EXPECT_TRUE(collision::append_device_bvh_build(program, *bvh, n, {-1, -1, -1}, {1, 1, 1}).ok());
  EXPECT_TRUE(collision::append_device_bvh_refit(program, *bvh, n).ok());
  auto prepared = device.create_program(program);
  EXPECT_TRUE(prepared.ok()) << (prepared.ok() ? "" : prepared.error().message());
  if (!prepared.ok()) return r;
  EXPECT_TRUE(device.run_program(*prepared).ok());
  const auto read = [&](BufferHandle b, std::size_t words) {
    std::vector<std::uint32_t> w(words);
    EXPECT_TRUE(device.read_buffer(b, 0, w.data(), words * 4).ok());
    return w;
  };
  r.codes = read(bvh->codes, n);
  r.indices = read(bvh->indices, n);
  r.children = read(bvh->children, 2 * (n - 1));
  r.parents = read(bvh->parents, 2 * n - 1);
  r.node_boxes.resize(6 * (n - 1));
  EXPECT_TRUE(device.read_buffer(bvh->node_boxes, 0, r.node_boxes.data(), r.node_boxes.size() * 4).ok());
  return r;
}

// The assembled build (Morton codes, radix sort, Karras nodes) and refit
// give a valid tree whose leaves are the primitives sorted by code and
// whose node boxes are exactly their leaves' unions; every backend gives
// the CPU's bits. Bad sizes and bounds are named errors.
TEST(DeviceBvh, BuildOnEveryBackendGivesOneValidTree) {
  std::mt19937 rng(53);
  const std::uint32_t n = 5000;
  const KernelCase m = morton_case(rng, n);  // the boxes (some centres outside the bounds)
  const std::vector<float>& boxes = m.bindings[0].data;
  const auto reference_codes = words_of(run_on("cpu", m)[1]);
  BuiltBvh cpu;
  for (const std::string& backend : backends()) {
    if (const std::string why = missing_device(backend); !why.empty()) {
      std::printf("[ skipped ] %s: %s\n", backend.c_str(), why.c_str());
      continue;
    }
    SCOPED_TRACE(backend);
    const BuiltBvh r = build_on(backend, boxes, n);
    ASSERT_EQ(r.codes.size(), n);
    // The leaves: a permutation of the primitives, sorted by code, stable.
    std::vector<std::uint32_t> seen(n, 0);
    for (std::uint32_t i = 0; i < n; ++i) {
      ASSERT_LT(r.indices[i], n);
      ++seen[r.indices[i]];
      ASSERT_EQ(r.codes[i], reference_codes[r.indices[i]]);
      if (i > 0) {
        ASSERT_LE(r.codes[i - 1], r.codes[i]);
        if (r.codes[i - 1] == r.codes[i]) {
          ASSERT_LT(r.indices[i - 1], r.indices[i]) << "the sort is stable";
        }
      }
    }
    for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(seen[i], 1u);
    expect_valid_tree(r.codes, r.children, r.parents, n);
    // Every node's box is exactly the union of its leaves' boxes (the
    // refit's 64 passes reached the root).
    std::vector<std::array<float, 6>> want(n - 1);
    std::vector<int> done(n - 1, 0);
    const auto box_of = [&](std::uint32_t c, std::array<float, 6>& b) -> bool {
      if (c & SINEW_BVH_LEAF) {
        for (int k = 0; k < 6; ++k) b[std::size_t(k)] = boxes[6 * std::size_t{r.indices[c & ~SINEW_BVH_LEAF]} + std::size_t(k)];
        return true;
      }
      if (!done[c]) return false;
      b = want[c];
      return true;
    };
    for (bool progress = true; progress;) {  // bottom-up on the host, in any order
      progress = false;
      for (std::uint32_t i = 0; i + 1 < n; ++i) {
        std::array<float, 6> a, b;
        if (done[i] || !box_of(r.children[2 * i], a) || !box_of(r.children[2 * i + 1], b)) continue;
        for (int k = 0; k < 3; ++k) want[i][std::size_t(k)] = std::min(a[std::size_t(k)], b[std::size_t(k)]);
        for (int k = 3; k < 6; ++k) want[i][std::size_t(k)] = std::max(a[std::size_t(k)], b[std::size_t(k)]);
        done[i] = 1;
        progress = true;
      }
    }
    for (std::uint32_t i = 0; i + 1 < n; ++i)
      for (int k = 0; k < 6; ++k)
        ASSERT_EQ(r.node_boxes[6 * std::size_t{i} + std::size_t(k)], want[i][std::size_t(k)]) << "node " << i << " word " << k;
    if (backend == "cpu") {
      cpu = r;
    } else {
      EXPECT_EQ(r.indices, cpu.indices);
      EXPECT_EQ(r.children, cpu.children);
      EXPECT_EQ(r.parents, cpu.parents);
      EXPECT_EQ(0, std::memcmp(r.node_boxes.data(), cpu.node_boxes.data(), r.node_boxes.size() * 4));
    }
  }
  auto device = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(device.ok());
  auto bvh = collision::make_device_bvh(**device, 10);
  ASSERT_TRUE(bvh.ok());
  FrameProgram program;
  EXPECT_FALSE(collision::append_device_bvh_build(program, *bvh, 11, {0, 0, 0}, {1, 1, 1}).ok());
  EXPECT_FALSE(collision::append_device_bvh_build(program, *bvh, 1, {0, 0, 0}, {1, 1, 1}).ok());
  EXPECT_FALSE(collision::append_device_bvh_build(program, *bvh, 5, {0, 0, 0}, {1, NAN, 1}).ok());
  EXPECT_FALSE(collision::append_device_bvh_build(program, *bvh, 5, {0, 2, 0}, {1, 1, 1}).ok());
  EXPECT_FALSE(collision::make_device_bvh(**device, 1).ok());
  EXPECT_FALSE(collision::append_device_bvh_refit(program, *bvh, 11).ok());
}

// ---------------------------------------------------------------- the traversals

using collision::Aabb;
using collision::Pair;

constexpr std::uint32_t kNone = SINEW_BVH_NONE;
constexpr std::uint32_t kSentinel = 0xDEADBEEFu;  // pairs-buffer words past the capacity must keep it
constexpr std::uint32_t kSpare = 64;              // pairs of sentinel room past the capacity

// The reference's skip for vertex ids of 3 per primitive, kNone unused.
struct SharesValidId {
  const std::vector<std::uint32_t>* ids;
  bool operator()(std::uint32_t i, std::uint32_t j) const {
    for (int s = 0; s < 3; ++s)
      for (int t = 0; t < 3; ++t) {
        const std::uint32_t a = (*ids)[3 * std::size_t{i} + std::size_t(s)], b = (*ids)[3 * std::size_t{j} + std::size_t(t)];
        if (a != kNone && a == b) return true;
      }
    return false;
  }
};

// What one traversal on a device gave.
struct DevicePairs {
  Status run;                          // the program's run (capacity_exceeded when over)
  Result<std::vector<Pair>> pairs{std::vector<Pair>{}};  // read_device_bvh_pairs
  std::vector<std::uint32_t> words;    // the whole pairs buffer: capacity + kSpare pairs
  std::uint32_t counter = 0;           // the device counter after the run
  double ms = 0.0;                     // wall time of the traversal's program [ms]
};

// Builds and refits a device BVH over `boxes` (one program), then runs the
// self traversal with `vertex_ids` (or, when `a_boxes` is given, the tree
// traversal of those boxes against it) in a second program.
DevicePairs pairs_on(Device& device, const std::vector<Aabb>& boxes, const std::vector<std::uint32_t>& vertex_ids,
                     std::uint32_t capacity, const std::vector<Aabb>* a_boxes = nullptr) {
  DevicePairs r;
  const auto n = std::uint32_t(boxes.size());
  const auto bvh = built_device_bvh(device, boxes);
  if (!bvh) return r;

  const std::size_t pair_words = 2 * (std::size_t{capacity} + kSpare);
  auto pairs = device.create_buffer(pair_words * 4, "pairs");
  auto counter = device.create_buffer(4 * 4, "pair counter");
  EXPECT_TRUE(pairs.ok() && counter.ok());
  if (!pairs.ok() || !counter.ok()) return r;
  const std::vector<std::uint32_t> sentinel(pair_words, kSentinel);
  EXPECT_TRUE(device.write_buffer(*pairs, 0, sentinel.data(), pair_words * 4).ok());
  const DeviceCount count{*counter, 2, capacity};  // a word inside the buffer, not the first
  FrameProgram traverse;
  if (a_boxes) {
    const std::vector<float> fa = flat(*a_boxes);
    auto a = device.create_buffer(std::max<std::size_t>(fa.size(), 1) * 4, "boxes of A");
    EXPECT_TRUE(a.ok());
    if (!a.ok()) return r;
    if (!fa.empty()) {
      EXPECT_TRUE(device.write_buffer(*a, 0, fa.data(), fa.size() * 4).ok());
    }
    EXPECT_TRUE(collision::append_device_bvh_tree_pairs(traverse, *a, std::uint32_t(a_boxes->size()), *bvh, n, *pairs, count).ok());
  } else {
    auto ids = device.create_buffer(vertex_ids.size() * 4, "vertex ids");
    EXPECT_TRUE(ids.ok());
    if (!ids.ok()) return r;
    EXPECT_TRUE(device.write_buffer(*ids, 0, vertex_ids.data(), vertex_ids.size() * 4).ok());
    EXPECT_TRUE(collision::append_device_bvh_self_pairs(traverse, *bvh, n, *ids, *pairs, count).ok());
  }
  auto prepared = device.create_program(traverse);
  EXPECT_TRUE(prepared.ok()) << (prepared.ok() ? "" : prepared.error().message());
  if (!prepared.ok()) return r;
  const auto start = std::chrono::steady_clock::now();
  r.run = device.run_program(*prepared);
  r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  r.pairs = collision::read_device_bvh_pairs(device, *pairs, count);
  r.words.resize(pair_words);
  EXPECT_TRUE(device.read_buffer(*pairs, 0, r.words.data(), pair_words * 4).ok());
  EXPECT_TRUE(device.read_buffer(*counter, 2 * 4, &r.counter, 4).ok());
  EXPECT_EQ(device.counters().size(), 1u);
  if (!device.counters().empty()) {
    EXPECT_EQ(device.counters()[0], r.counter) << "the declared counter";
  }
  return r;
}

std::unique_ptr<Device> device_for(const std::string& backend) {
  auto made = create_device({.backend = backend, .quiet = true});
  EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.error().message());
  return made.ok() ? std::move(*made) : nullptr;
}

std::vector<Aabb> boxes_of(const Surface& s, float inflate) {
  std::vector<Aabb> boxes;
  const Status status = collision::primitive_boxes(s.positions, s.triangles, 3, inflate, boxes);
  EXPECT_TRUE(status.ok()) << (status.ok() ? "" : status.error().message());
  return boxes;
}

// A mesh's boundary surface, read once per process (the liver takes a
// few seconds) and shared by the backends' instances.
const Surface& cached_surface(const std::string& file) {
  static std::map<std::string, Surface> surfaces;
  auto it = surfaces.find(file);
  if (it == surfaces.end()) it = surfaces.emplace(file, surface_of(file)).first;
  return it->second;
}

// Every test body runs on each backend; one with no device here is skipped.
class DeviceBvhPairs : public BackendTest {};

// bvh_self_pairs on the boundary surfaces of the meshes (triangle
// boxes inflated as in tests/bvh_test.cpp, triangles sharing a vertex
// skipped) finds exactly the reference BVH's pairs, which bvh_test.cpp
// proves equal to the brute force (checked here again on the armadillo).
TEST_P(DeviceBvhPairs, SelfPairsOnRealSurfacesEqualTheReference) {
  struct Case {
    const char* file;
    float inflate;  // of the mean edge
  };
  for (const Case c : {Case{"meshes/tet/armadillo_4k.node", 0.5f}, Case{"meshes/tet/kidney_57k.node", 0.5f},
                       Case{"meshes/tet/liver_382k.node", 0.25f}}) {
    SCOPED_TRACE(c.file);
    const Surface& s = cached_surface(c.file);
    ASSERT_FALSE(s.triangles.empty());
    const std::vector<Aabb> boxes = boxes_of(s, c.inflate * s.mean_edge);
    collision::Bvh tree;
    tree.build(boxes);
    std::vector<Pair> want;
    collision::self_overlapping_pairs(tree, collision::SharesVertex{s.triangles}, want);
    if (boxes.size() < 10000) {
      std::vector<Pair> brute;
      collision::brute_force_self_pairs(boxes, collision::SharesVertex{s.triangles}, brute);
      ASSERT_EQ(want, brute);
    }
    auto device = device_for(GetParam());
    ASSERT_TRUE(device);
    const DevicePairs got = pairs_on(*device, boxes, s.triangles, std::uint32_t(want.size()) + 100);
    ASSERT_TRUE(got.run.ok()) << got.run.error().message();
    ASSERT_TRUE(got.pairs.ok()) << got.pairs.error().message();
    EXPECT_EQ(got.counter, want.size());
    EXPECT_EQ(*got.pairs, want) << got.pairs->size() << " device pairs, " << want.size() << " reference";
    EXPECT_GT(want.size(), 0u);
    std::printf("[ device bvh ] %s, %s: %zu triangles, %zu self pairs, traversal %.1f ms\n", GetParam().c_str(),
                c.file, boxes.size(), want.size(), got.ms);
  }
}

// Moves `s` so that its bounding-box centre lies at `centre`.
void centre_at(Surface& s, const std::array<float, 3>& centre) {
  std::array<float, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t v = 0; v < s.positions.size() / 4; ++v)
    for (std::size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], s.positions[4 * v + k]);
      hi[k] = std::max(hi[k], s.positions[4 * v + k]);
    }
  for (std::size_t v = 0; v < s.positions.size() / 4; ++v)
    for (std::size_t k = 0; k < 3; ++k) s.positions[4 * v + k] += centre[k] - 0.5f * (lo[k] + hi[k]);
}

// bvh_tree_pairs: the kidney's surface moved onto the liver's (its centre
// on a vertex of the liver's surface, so the two surfaces cross), kidney
// triangles against the liver's tree and the liver's against the
// kidney's, equal the reference BVHs' pairs.
TEST_P(DeviceBvhPairs, TreePairsKidneyInLiverEqualTheReference) {
  const Surface& liver = cached_surface("meshes/tet/liver_382k.node");
  Surface kidney = cached_surface("meshes/tet/kidney_57k.node");
  ASSERT_FALSE(liver.triangles.empty());
  ASSERT_FALSE(kidney.triangles.empty());
  const std::uint32_t v = liver.triangles[0];
  centre_at(kidney, {liver.positions[4 * v], liver.positions[4 * v + 1], liver.positions[4 * v + 2]});
  const float inflate = 0.5f * liver.mean_edge;
  const std::vector<Aabb> a = boxes_of(kidney, inflate), b = boxes_of(liver, inflate);
  collision::Bvh ta, tb;
  ta.build(a);
  tb.build(b);
  std::vector<Pair> want;
  collision::overlapping_pairs(ta, tb, want);
  ASSERT_GT(want.size(), 1000u) << "the surfaces should cross";
  auto device = device_for(GetParam());
  ASSERT_TRUE(device);
  const DevicePairs got = pairs_on(*device, b, {}, std::uint32_t(want.size()), &a);
  ASSERT_TRUE(got.run.ok()) << got.run.error().message();
  ASSERT_TRUE(got.pairs.ok()) << got.pairs.error().message();
  EXPECT_EQ(*got.pairs, want);
  // The other way round: the liver's triangles against the kidney's tree.
  const DevicePairs back = pairs_on(*device, a, {}, std::uint32_t(want.size()), &b);
  ASSERT_TRUE(back.pairs.ok()) << back.pairs.error().message();
  std::vector<Pair> swapped;
  for (const auto& [i, j] : want) swapped.push_back({j, i});
  std::sort(swapped.begin(), swapped.end());
  EXPECT_EQ(*back.pairs, swapped);
  std::printf("[ device bvh ] %s, kidney x liver: %zu x %zu triangles, %zu pairs, traversal %.1f ms (kidney items), "
              "%.1f ms (liver items)\n",
              GetParam().c_str(), a.size(), b.size(), want.size(), got.ms, back.ms);
}

// A capacity below the pair count: the run reports capacity_exceeded, the
// read-back names the exact count and the capacity, exactly `capacity`
// distinct pairs of the true set were written and not a word past them.
TEST_P(DeviceBvhPairs, CapacityBelowThePairCountIsAnErrorWithTheExactCount) {
  const Surface& s = cached_surface("meshes/tet/armadillo_4k.node");
  ASSERT_FALSE(s.triangles.empty());
  const std::vector<Aabb> boxes = boxes_of(s, 0.5f * s.mean_edge);
  std::vector<Pair> want;
  collision::brute_force_self_pairs(boxes, collision::SharesVertex{s.triangles}, want);
  ASSERT_GT(want.size(), 100u);
  auto device = device_for(GetParam());
  ASSERT_TRUE(device);
  for (const std::uint32_t capacity : {std::uint32_t(want.size() / 3), std::uint32_t(want.size() - 1), 0u}) {
    SCOPED_TRACE("capacity " + std::to_string(capacity));
    const DevicePairs got = pairs_on(*device, boxes, s.triangles, capacity);
    ASSERT_FALSE(got.run.ok());
    EXPECT_EQ(got.run.error().code(), ErrorCode::capacity_exceeded) << got.run.error().message();
    EXPECT_EQ(got.counter, want.size()) << "the counter counts past the capacity";
    ASSERT_FALSE(got.pairs.ok());
    EXPECT_EQ(got.pairs.error().code(), ErrorCode::capacity_exceeded);
    const std::string& message = got.pairs.error().message();
    EXPECT_NE(message.find(std::to_string(want.size()) + " pairs"), std::string::npos) << message;
    EXPECT_NE(message.find("capacity of " + std::to_string(capacity)), std::string::npos) << message;
    std::vector<Pair> kept;
    for (std::uint32_t k = 0; k < capacity; ++k) kept.push_back({got.words[2 * k], got.words[2 * k + 1]});
    std::sort(kept.begin(), kept.end());
    EXPECT_EQ(std::adjacent_find(kept.begin(), kept.end()), kept.end()) << "each pair once";
    for (const Pair& pair : kept) ASSERT_TRUE(std::binary_search(want.begin(), want.end(), pair));
    for (std::size_t w = 2 * std::size_t{capacity}; w < got.words.size(); ++w)
      ASSERT_EQ(got.words[w], kSentinel) << "word " << w << " past the capacity was written";
  }
  // The tree traversal too.
  const std::vector<Aabb> half(boxes.begin(), boxes.begin() + std::ptrdiff_t(boxes.size() / 2));
  std::vector<Pair> cross;
  collision::brute_force_pairs(half, boxes, cross);
  const DevicePairs got = pairs_on(*device, boxes, {}, std::uint32_t(cross.size() / 2), &half);
  ASSERT_FALSE(got.pairs.ok());
  EXPECT_EQ(got.pairs.error().code(), ErrorCode::capacity_exceeded);
  EXPECT_NE(got.pairs.error().message().find(std::to_string(cross.size()) + " pairs"), std::string::npos);
  EXPECT_EQ(got.counter, cross.size());
  for (std::size_t w = 2 * (cross.size() / 2); w < got.words.size(); ++w) ASSERT_EQ(got.words[w], kSentinel);
}

// Degenerate inputs: all boxes equal (every pair, or none where they share
// a vertex), two boxes (touching: a pair; a float step apart: none),
// zero-size boxes, duplicates and mixed points, segments and triangles
// against the brute force; the tree traversal of equal boxes finds every
// (a, b), and boxes of A missing B's root none.
TEST_P(DeviceBvhPairs, DegenerateInputsEqualTheBruteForce) {
  auto device = device_for(GetParam());
  ASSERT_TRUE(device);
  const Aabb unit{{0, 0, 0}, {1, 1, 1}};
  // All equal, no vertex ids: every pair once.
  for (const std::uint32_t n : {2u, 3u, 100u}) {
    const std::vector<Aabb> boxes(n, unit);
    const DevicePairs got = pairs_on(*device, boxes, std::vector<std::uint32_t>(3 * n, kNone), n * (n - 1) / 2);
    ASSERT_TRUE(got.pairs.ok()) << got.pairs.error().message();
    ASSERT_EQ(got.pairs->size(), n * (n - 1) / 2) << n << " equal boxes";
    for (std::size_t k = 1; k < got.pairs->size(); ++k) ASSERT_LT((*got.pairs)[k - 1], (*got.pairs)[k]);
    for (const auto& [i, j] : *got.pairs) ASSERT_LT(i, j);
  }
  // All equal, every primitive a segment sharing vertex 7: no pair.
  {
    std::vector<std::uint32_t> ids;
    for (std::uint32_t i = 0; i < 50; ++i) ids.insert(ids.end(), {7u, 100u + i, kNone});
    const DevicePairs got = pairs_on(*device, std::vector<Aabb>(50, unit), ids, 10);
    ASSERT_TRUE(got.pairs.ok());
    EXPECT_TRUE(got.pairs->empty());
  }
  // Two boxes: touching faces overlap (closed intervals), a float step apart not.
  const Aabb right_touch{{1, 0, 0}, {2, 1, 1}};
  const Aabb right_apart{{std::nextafter(1.0f, 2.0f), 0, 0}, {2, 1, 1}};
  const std::vector<std::uint32_t> points = {0u, kNone, kNone, 1u, kNone, kNone};
  auto touching = pairs_on(*device, {unit, right_touch}, points, 4);
  ASSERT_TRUE(touching.pairs.ok());
  EXPECT_EQ(*touching.pairs, (std::vector<Pair>{{0, 1}}));
  auto apart = pairs_on(*device, {unit, right_apart}, points, 4);
  ASSERT_TRUE(apart.pairs.ok());
  EXPECT_TRUE(apart.pairs->empty());
  auto shared = pairs_on(*device, {unit, right_touch}, {0u, 1u, 2u, 5u, 2u, 6u}, 4);
  ASSERT_TRUE(shared.pairs.ok());
  EXPECT_TRUE(shared.pairs->empty()) << "triangles sharing vertex 2";
  // Random boxes with zero-size, coincident and duplicate ones, and
  // points, segments and triangles with random vertex ids.
  std::mt19937 rng(59);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int round = 0; round < 4; ++round) {
    const std::uint32_t n = 2 + rng() % 900;
    std::vector<Aabb> boxes(n);
    std::vector<std::uint32_t> ids(3 * n, kNone);
    for (std::uint32_t i = 0; i < n; ++i) {
      const int kind = int(rng() % 5);
      for (std::size_t k = 0; k < 3; ++k) {
        const float c = kind == 0 ? 0.5f : u(rng), h = kind == 1 ? 0.0f : 0.05f * u(rng);
        boxes[i].lo[k] = c - h;
        boxes[i].hi[k] = c + h;
      }
      if (kind == 2) boxes[i] = boxes[0];
      const std::uint32_t arity = 1 + rng() % 3;
      for (std::uint32_t c = 0; c < arity; ++c) ids[3 * i + c] = std::uint32_t(rng() % (2 * n));
    }
    std::vector<Pair> want;
    collision::brute_force_self_pairs(boxes, SharesValidId{&ids}, want);
    const DevicePairs got = pairs_on(*device, boxes, ids, std::uint32_t(want.size()));
    ASSERT_TRUE(got.pairs.ok()) << got.pairs.error().message();
    ASSERT_EQ(*got.pairs, want) << "round " << round << ", " << n << " boxes";
    const std::vector<Aabb> a(boxes.begin(), boxes.begin() + std::ptrdiff_t(std::min(n, 300u)));
    std::vector<Pair> cross;
    collision::brute_force_pairs(a, boxes, cross);
    const DevicePairs tree = pairs_on(*device, boxes, {}, std::uint32_t(cross.size()), &a);
    ASSERT_TRUE(tree.pairs.ok()) << tree.pairs.error().message();
    ASSERT_EQ(*tree.pairs, cross) << "tree pairs, round " << round;
  }
  // Tree pairs: 5 equal boxes against a tree of 2 and of 7 equal ones.
  for (const std::uint32_t m : {2u, 7u}) {
    const std::vector<Aabb> a(5, unit);
    const DevicePairs got = pairs_on(*device, std::vector<Aabb>(m, unit), {}, 5 * m, &a);
    ASSERT_TRUE(got.pairs.ok());
    EXPECT_EQ(got.pairs->size(), 5 * m);
  }
  const std::vector<Aabb> far(3, Aabb{{5, 5, 5}, {6, 6, 6}});
  const DevicePairs none = pairs_on(*device, {unit, right_touch}, {}, 4, &far);
  ASSERT_TRUE(none.pairs.ok());
  EXPECT_TRUE(none.pairs->empty());
  const std::vector<Aabb> empty;
  const DevicePairs no_items = pairs_on(*device, {unit, right_touch}, {}, 4, &empty);
  ASSERT_TRUE(no_items.pairs.ok());
  EXPECT_TRUE(no_items.pairs->empty());
}

INSTANTIATE_TEST_SUITE_P(Backends, DeviceBvhPairs, ::testing::ValuesIn(backends()), backend_name);

TEST(DeviceBvh, PairsBadArgumentsAreErrors) {
  auto device = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(device.ok());
  auto bvh = collision::make_device_bvh(**device, 10);
  ASSERT_TRUE(bvh.ok());
  auto buffer = (*device)->create_buffer(64, "words");
  ASSERT_TRUE(buffer.ok());
  FrameProgram program;
  const DeviceCount count{*buffer, 0, 4};
  EXPECT_FALSE(collision::append_device_bvh_self_pairs(program, *bvh, 11, *buffer, *buffer, count).ok());
  EXPECT_FALSE(collision::append_device_bvh_self_pairs(program, *bvh, 1, *buffer, *buffer, count).ok());
  EXPECT_FALSE(collision::append_device_bvh_self_pairs(program, *bvh, 5, BufferHandle{}, *buffer, count).ok());
  EXPECT_FALSE(collision::append_device_bvh_tree_pairs(program, *buffer, 3, *bvh, 11, *buffer, count).ok());
  EXPECT_FALSE(collision::append_device_bvh_tree_pairs(program, *buffer, 3, *bvh, 1, *buffer, count).ok());
  EXPECT_FALSE(collision::append_device_bvh_tree_pairs(program, *buffer, 3, *bvh, 5, *buffer, {}).ok());
  EXPECT_EQ(program.commands().size(), 0u) << "nothing appended on an error";
}

}  // namespace
}  // namespace sinew::test
