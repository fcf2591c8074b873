// device_bvh_test.cpp — the kernels that build a BVH on the device
// (kernels/shared/bvh_params.h, Karras HPG 2012): the Morton codes equal
// codes interleaved bit by bit here, the internal nodes form a valid binary
// tree over the sorted leaves (every node reached once, each covering a
// contiguous range split where its keys first differ), with duplicate
// codes too; every GPU backend gives the CPU reference's bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <functional>
#include <random>
#include <vector>

#include "agreement_support.h"
#include "bvh_params.h"
#include "collision/device_bvh.h"
#include "program/primitives.h"
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

}  // namespace
}  // namespace sinew::test
