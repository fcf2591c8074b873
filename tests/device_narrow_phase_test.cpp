// device_narrow_phase_test.cpp — the narrow phase in a kernel
// (collision/device_narrow_phase.h, kernels/shared/narrow_phase_params.h):
// on every backend, the device BVH's self pairs of a bending organ surface
// become on the device exactly the contacts the host reference
// (collision::triangle_contacts) makes of the same pairs, bit for bit;
// overflowing the contact capacity is an error with the exact count; a
// zero-area triangle in a pair is named; bad arguments are errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "collision/aabb.h"
#include "collision/device_bvh.h"
#include "collision/device_narrow_phase.h"
#include "collision/narrow_phase.h"
#include "device_bvh_support.h"
#include "surface_support.h"
#include "test_support.h"

namespace sinew::test {
namespace {

using collision::Aabb;
using collision::Contact;
using collision::Pair;

const Surface& cached_surface(const std::string& file) {
  static std::map<std::string, Surface> surfaces;
  auto it = surfaces.find(file);
  if (it == surfaces.end()) it = surfaces.emplace(file, surface_of(file)).first;
  return it->second;
}

// What one run of traversal + narrow phase on a device gave.
struct DeviceRun {
  Status run;
  Result<std::vector<Pair>> pairs{std::vector<Pair>{}};
  Result<std::vector<Contact>> contacts{std::vector<Contact>{}};
  double ms = 0.0;  // the traversal + narrow phase program [ms]
};

// Builds a device BVH over the triangles' boxes at `x` grown by `inflate`,
// then runs the self traversal and the narrow phase in one program.
// [in] given_boxes: the triangles' boxes when not those of x (a test of
// positions the narrow phase reads but the broad phase did not).
DeviceRun run_on(Device& device, const std::vector<float>& x, const std::vector<std::uint32_t>& triangles,
                 float inflate, float thickness, std::uint32_t pair_capacity, std::uint32_t contact_capacity,
                 const std::vector<Aabb>* given_boxes = nullptr) {
  DeviceRun r;
  std::vector<Aabb> boxes;
  if (given_boxes) boxes = *given_boxes;
  else EXPECT_TRUE(collision::primitive_boxes(x, triangles, 3, inflate, boxes).ok());
  const auto n = std::uint32_t(boxes.size());
  const auto bvh = built_device_bvh(device, boxes);
  if (!bvh) return r;

  auto positions = device.create_buffer(x.size() * 4, "positions");
  auto ids = device.create_buffer(triangles.size() * 4, "vertex ids");
  auto pairs = device.create_buffer(std::size_t{pair_capacity} * 8, "pairs");
  auto counts = device.create_buffer(4 * 4, "counts");
  EXPECT_TRUE(positions.ok() && ids.ok() && pairs.ok() && counts.ok());
  if (!positions.ok() || !ids.ok() || !pairs.ok() || !counts.ok()) return r;
  EXPECT_TRUE(device.write_buffer(*positions, 0, x.data(), x.size() * 4).ok());
  EXPECT_TRUE(device.write_buffer(*ids, 0, triangles.data(), triangles.size() * 4).ok());
  auto on_device = collision::make_device_triangles(device, triangles);
  EXPECT_TRUE(on_device.ok()) << (on_device.ok() ? "" : on_device.error().message());
  auto out = collision::make_device_contacts(device, contact_capacity, *counts, 1);
  EXPECT_TRUE(out.ok());
  if (!on_device.ok() || !out.ok()) return r;
  const DeviceCount pair_count{*counts, 0, pair_capacity};
  FrameProgram detect;
  EXPECT_TRUE(collision::append_device_bvh_self_pairs(detect, *bvh, n, *ids, *pairs, pair_count).ok());
  const Status appended =
      collision::append_device_triangle_contacts(detect, *positions, *on_device, *pairs, pair_count, *out, thickness);
  EXPECT_TRUE(appended.ok()) << (appended.ok() ? "" : appended.error().message());
  auto prepared = device.create_program(detect);
  EXPECT_TRUE(prepared.ok()) << (prepared.ok() ? "" : prepared.error().message());
  if (!prepared.ok()) return r;
  const auto start = std::chrono::steady_clock::now();
  r.run = device.run_program(*prepared);
  r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  r.pairs = collision::read_device_bvh_pairs(device, *pairs, pair_count);
  r.contacts = collision::read_device_contacts(device, *out, pair_count);
  return r;
}

bool same_bits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

// Every field equal, the floats bit for bit; [out] the first difference.
bool same_contacts(const std::vector<Contact>& a, const std::vector<Contact>& b, std::string& why) {
  if (a.size() != b.size()) {
    why = std::to_string(a.size()) + " contacts against " + std::to_string(b.size());
    return false;
  }
  for (std::size_t k = 0; k < a.size(); ++k) {
    bool same = a[k].kind == b[k].kind && a[k].v == b[k].v && same_bits(a[k].distance, b[k].distance);
    for (int i = 0; i < 4; ++i) same = same && same_bits(a[k].w[i], b[k].w[i]);
    for (int i = 0; i < 3; ++i) same = same && same_bits(a[k].normal[i], b[k].normal[i]);
    if (!same) {
      why = "contact " + std::to_string(k) + " (particles " + std::to_string(a[k].v[0]) + ", " +
            std::to_string(a[k].v[1]) + ", " + std::to_string(a[k].v[2]) + ", " + std::to_string(a[k].v[3]) +
            ") differs: distance " + std::to_string(a[k].distance) + " against " + std::to_string(b[k].distance);
      return false;
    }
  }
  return true;
}

class DeviceNarrowPhase : public BackendTest {};

// The armadillo's and the kidney's surfaces, bent so that folds come within
// the thickness, at a thickness of a third of the mean edge: the device's
// contacts of the device's pairs are the host reference's contacts of the
// same pairs, bit for bit, and those pairs are the host BVH's.
TEST_P(DeviceNarrowPhase, ContactsOfTheDevicePairsEqualTheHostReference) {
  for (const char* file : {"meshes/tet/armadillo_4k.node", "meshes/tet/kidney_57k.node"}) {
    SCOPED_TRACE(file);
    const Surface& s = cached_surface(file);
    ASSERT_FALSE(s.triangles.empty());
    const std::vector<float> x = bent(s, 3.0f * s.mean_edge, 3);
    const float thickness = s.mean_edge / 3.0f;
    auto device = create_device({.backend = GetParam(), .quiet = true});
    ASSERT_TRUE(device.ok()) << device.error().message();
    const DeviceRun got = run_on(**device, x, s.triangles, 0.5f * thickness, thickness, 1u << 18, 1u << 17);
    ASSERT_TRUE(got.run.ok()) << got.run.error().message();
    ASSERT_TRUE(got.pairs.ok()) << got.pairs.error().message();
    ASSERT_TRUE(got.contacts.ok()) << got.contacts.error().message();
    // The pairs: the host BVH's.
    std::vector<Aabb> boxes;
    ASSERT_TRUE(collision::primitive_boxes(x, s.triangles, 3, 0.5f * thickness, boxes).ok());
    collision::Bvh tree;
    tree.build(boxes);
    std::vector<Pair> want_pairs;
    collision::self_overlapping_pairs(tree, collision::SharesVertex{s.triangles}, want_pairs);
    ASSERT_EQ(*got.pairs, want_pairs);
    std::vector<Contact> want;
    ASSERT_TRUE(collision::triangle_contacts(x, s.triangles, want_pairs, thickness, want).ok());
    std::size_t edges = 0;
    for (const Contact& c : want) edges += c.kind == Contact::Kind::edge_edge;
    EXPECT_GT(want.size() - edges, 10u) << "the bend should bring vertices within the thickness of triangles";
    EXPECT_GT(edges, 10u) << "and edges within it of edges";
    std::string why;
    EXPECT_TRUE(same_contacts(*got.contacts, want, why)) << why;
    std::printf("[ device narrow ] %s, %s: %zu pairs, %zu contacts (%zu edge-edge), traversal + narrow phase %.1f ms\n",
                GetParam().c_str(), file, want_pairs.size(), want.size(), edges, got.ms);
  }
}

// A contact capacity below the count: the run fails with capacity_exceeded,
// and the read-back names the number there was.
TEST_P(DeviceNarrowPhase, ContactCapacityBelowTheCountIsAnErrorWithTheCount) {
  const Surface& s = cached_surface("meshes/tet/armadillo_4k.node");
  ASSERT_FALSE(s.triangles.empty());
  const std::vector<float> x = bent(s, 3.0f * s.mean_edge, 3);
  const float thickness = s.mean_edge / 3.0f;
  std::vector<Aabb> boxes;
  ASSERT_TRUE(collision::primitive_boxes(x, s.triangles, 3, 0.5f * thickness, boxes).ok());
  collision::Bvh tree;
  tree.build(boxes);
  std::vector<Pair> pairs;
  collision::self_overlapping_pairs(tree, collision::SharesVertex{s.triangles}, pairs);
  std::vector<Contact> want;
  ASSERT_TRUE(collision::triangle_contacts(x, s.triangles, pairs, thickness, want).ok());
  ASSERT_GT(want.size(), 20u);
  auto device = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  const DeviceRun got = run_on(**device, x, s.triangles, 0.5f * thickness, thickness, 1u << 18, 10);
  ASSERT_FALSE(got.run.ok());
  EXPECT_EQ(got.run.error().code(), ErrorCode::capacity_exceeded);
  ASSERT_FALSE(got.contacts.ok());
  EXPECT_EQ(got.contacts.error().code(), ErrorCode::capacity_exceeded);
  // Duplicates (a feature tested from several pairs) count too: at least
  // as many as the reference keeps.
  EXPECT_NE(got.contacts.error().message().find("contacts made, more than the capacity of 10"), std::string::npos)
      << got.contacts.error().message();
}

// A triangle collapsed to a segment, in a candidate pair: no contact of it,
// and the read-back names how many pairs held one (the host reference's
// error, narrow_phase.h).
TEST_P(DeviceNarrowPhase, AZeroAreaTriangleInAPairIsNamed) {
  // Two triangles side by side, the second collapsed onto a line over the first.
  const std::vector<std::uint32_t> triangles = {0, 1, 2, 3, 4, 5};
  const std::vector<float> x = {0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0,  //
                                0, 0, 0.01f, 0, 0.5f, 0.5f, 0.01f, 0, 1, 1, 0.01f, 0};
  auto device = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  const DeviceRun got = run_on(**device, x, triangles, 0.05f, 0.1f, 16, 16);
  ASSERT_TRUE(got.run.ok()) << got.run.error().message();
  ASSERT_TRUE(got.pairs.ok());
  EXPECT_EQ(got.pairs->size(), 1u);
  ASSERT_FALSE(got.contacts.ok());
  EXPECT_EQ(got.contacts.error().code(), ErrorCode::bad_parameter);
  EXPECT_NE(got.contacts.error().message().find("1 candidate pairs hold a zero-area triangle or a non-finite corner"), std::string::npos)
      << got.contacts.error().message();
  std::vector<Contact> host;
  const Status reference = collision::triangle_contacts(x, triangles, *got.pairs, 0.1f, host);
  EXPECT_FALSE(reference.ok()) << "the host reference names it too";
}

// 20,000 pairs of 1 cm triangles 10 m from the origin, a vertex of the
// second 1.000-1.004 thicknesses (0.1 mm) above the first: the float
// rounding of the closest points (~1e-6 m there) is a hundredth of the
// thickness, and the host's separating-axis reject (kernels/math/
// triangle_separation.h) drops some pairs whose computed distance is
// under it. The kernel runs the same reject, so it keeps the same
// contacts (found in review: without it, 12% of such pairs made a contact
// on the device only). Pairs written by the host, no traversal.
TEST_P(DeviceNarrowPhase, NearThicknessPairsFarFromTheOriginEqualTheHostReference) {
  const float offset = 10.0f, thickness = 1e-4f;
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> signed_unit(-1.0f, 1.0f), unit(0.0f, 1.0f);
  std::vector<float> x;
  std::vector<std::uint32_t> triangles, pair_words;
  std::vector<Pair> pairs;
  while (pairs.size() < 20000) {
    float a[3][3];
    for (auto& corner : a)
      for (float& c : corner) c = offset + 0.01f * signed_unit(rng);
    double u[3], w[3], n[3];
    for (int c = 0; c < 3; ++c) u[c] = double(a[1][c]) - a[0][c], w[c] = double(a[2][c]) - a[0][c];
    n[0] = u[1] * w[2] - u[2] * w[1], n[1] = u[2] * w[0] - u[0] * w[2], n[2] = u[0] * w[1] - u[1] * w[0];
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (length < 1e-5) continue;  // a sliver: no clear normal
    for (double& c : n) c /= length;
    double s = unit(rng), t = unit(rng);
    if (s + t > 1.0) s = 1.0 - s, t = 1.0 - t;
    const double above = thickness * (1.0 + 0.004 * unit(rng));
    float b[3][3];
    for (int c = 0; c < 3; ++c) {
      const double base = a[0][c] + s * u[c] + t * w[c];
      b[0][c] = float(base + above * n[c]);
      b[1][c] = float(base + 0.01 * n[c] + 0.005 * signed_unit(rng));
      b[2][c] = float(base + 0.01 * n[c] + 0.005 * signed_unit(rng));
    }
    const auto first = std::uint32_t(x.size() / 4);
    for (const auto* corner : {&a[0], &a[1], &a[2], &b[0], &b[1], &b[2]})
      x.insert(x.end(), {(*corner)[0], (*corner)[1], (*corner)[2], 0.0f});
    for (std::uint32_t k = 0; k < 6; ++k) triangles.push_back(first + k);
    const auto t0 = std::uint32_t(triangles.size() / 3 - 2);
    pairs.push_back({t0, t0 + 1});
    pair_words.insert(pair_words.end(), {t0, t0 + 1});
  }
  std::vector<Contact> want;
  ASSERT_TRUE(collision::triangle_contacts(x, triangles, pairs, thickness, want).ok());
  EXPECT_GT(want.size(), 1000u);
  auto made = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(made.ok()) << made.error().message();
  Device& device = **made;
  auto positions = device.create_buffer(x.size() * 4, "positions");
  auto pair_buffer = device.create_buffer(pair_words.size() * 4, "pairs");
  auto counts = device.create_buffer(16, "counts");
  ASSERT_TRUE(positions.ok() && pair_buffer.ok() && counts.ok());
  ASSERT_TRUE(device.write_buffer(*positions, 0, x.data(), x.size() * 4).ok());
  ASSERT_TRUE(device.write_buffer(*pair_buffer, 0, pair_words.data(), pair_words.size() * 4).ok());
  const std::uint32_t found = std::uint32_t(pairs.size());
  ASSERT_TRUE(device.write_buffer(*counts, 0, &found, 4).ok());
  auto on_device = collision::make_device_triangles(device, triangles);
  auto out = collision::make_device_contacts(device, 1u << 16, *counts, 1);
  ASSERT_TRUE(on_device.ok() && out.ok());
  const DeviceCount pair_count{*counts, 0, found};
  FrameProgram program;
  program.counter("pairs written by the host", *counts, 0, found);
  ASSERT_TRUE(
      collision::append_device_triangle_contacts(program, *positions, *on_device, *pair_buffer, pair_count, *out, thickness)
          .ok());
  auto prepared = device.create_program(program);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message();
  ASSERT_TRUE(device.run_program(*prepared).ok());
  const auto got = collision::read_device_contacts(device, *out, pair_count);
  ASSERT_TRUE(got.ok()) << got.error().message();
  std::string why;
  EXPECT_TRUE(same_contacts(*got, want, why)) << why;
}

// Two strips whose middle edges overlap on one line (touching, parallel):
// the candidate pairs around those edges all test them, and the contact
// they make is the same whichever pair comes first (its fallback normal is
// the second edge's owner's face, not the pair's), on the host in either
// pair order and on the device in any scheduling (found in review).
TEST_P(DeviceNarrowPhase, TouchingParallelEdgesGiveOneContactWhicheverPairFindsIt) {
  // T0 = (0, 1, 2) and T1 = (1, 0, 3) share edge (0, 1) in z = 0; T2 = (4, 5, 6)
  // and T3 = (5, 4, 7) share edge (4, 5), on the same line, standing in x = const.
  const std::vector<std::uint32_t> triangles = {0, 1, 2, 1, 0, 3, 4, 5, 6, 5, 4, 7};
  const std::vector<float> x = {0.0f,  0.0f, 0.0f, 0.0f, 1.0f,  0.0f,  0.0f, 0.0f,  // 0, 1
                                0.5f,  1.0f, 0.0f, 0.0f, 0.5f,  -1.0f, 0.0f, 0.0f,  // 2, 3
                                0.25f, 0.0f, 0.0f, 0.0f, 0.75f, 0.0f,  0.0f, 0.0f,  // 4, 5
                                0.5f,  0.0f, 1.0f, 0.0f, 0.5f,  0.0f,  -1.0f, 0.0f};  // 6, 7
  std::vector<Contact> forward, backward;
  ASSERT_TRUE(collision::triangle_contacts(x, triangles, std::vector<Pair>{{0, 2}, {0, 3}, {1, 2}, {1, 3}}, 0.1f,
                                           forward).ok());
  ASSERT_TRUE(collision::triangle_contacts(x, triangles, std::vector<Pair>{{1, 3}, {1, 2}, {0, 3}, {0, 2}}, 0.1f,
                                           backward).ok());
  std::string why;
  EXPECT_TRUE(same_contacts(forward, backward, why)) << why;
  bool touching = false;
  for (const Contact& c : forward)
    touching = touching || (c.kind == Contact::Kind::edge_edge && c.distance == 0.0f);
  EXPECT_TRUE(touching) << "the overlapping edges touch";
  auto device = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  const DeviceRun got = run_on(**device, x, triangles, 0.05f, 0.1f, 64, 64);
  ASSERT_TRUE(got.run.ok()) << got.run.error().message();
  ASSERT_TRUE(got.contacts.ok()) << got.contacts.error().message();
  std::vector<Contact> host;
  ASSERT_TRUE(collision::triangle_contacts(x, triangles, *got.pairs, 0.1f, host).ok());
  EXPECT_TRUE(same_contacts(*got.contacts, host, why)) << why;
}

// More pairs than the traversal's capacity: the run fails, and the
// read-back says the contacts of the pairs past it were never made.
TEST_P(DeviceNarrowPhase, PairOverflowIsAnErrorAtReadBack) {
  const Surface& s = cached_surface("meshes/tet/armadillo_4k.node");
  ASSERT_FALSE(s.triangles.empty());
  const std::vector<float> x = bent(s, 3.0f * s.mean_edge, 3);
  auto device = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  const DeviceRun got = run_on(**device, x, s.triangles, s.mean_edge / 6.0f, s.mean_edge / 3.0f, 100, 1u << 17);
  ASSERT_FALSE(got.run.ok());
  EXPECT_EQ(got.run.error().code(), ErrorCode::capacity_exceeded);
  ASSERT_FALSE(got.contacts.ok());
  EXPECT_EQ(got.contacts.error().code(), ErrorCode::capacity_exceeded);
  EXPECT_NE(got.contacts.error().message().find("more than the capacity of 100"), std::string::npos)
      << got.contacts.error().message();
}

// A NaN corner: the pair is counted as bad (the host reference names it),
// never a NaN contact.
TEST_P(DeviceNarrowPhase, ANonFiniteCornerIsCountedNotTurnedIntoAContact) {
  const std::vector<std::uint32_t> triangles = {0, 1, 2, 3, 4, 5};
  std::vector<float> x = {0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0,  //
                          0, 0, 0.01f, 0, 1, 0, 0.01f, 0, 0, 1, 0.01f, 0};
  auto device = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  // The boxes (and so the pair) come from the finite positions; the
  // narrow phase then reads a NaN in the second triangle.
  std::vector<Aabb> boxes;
  ASSERT_TRUE(collision::primitive_boxes(x, triangles, 3, 0.05f, boxes).ok());
  x[4 * 4 + 1] = NAN;
  const DeviceRun got = run_on(**device, x, triangles, 0.05f, 0.1f, 16, 16, &boxes);
  ASSERT_TRUE(got.run.ok()) << got.run.error().message();
  ASSERT_TRUE(got.pairs.ok());
  EXPECT_EQ(got.pairs->size(), 1u);
  ASSERT_FALSE(got.contacts.ok());
  EXPECT_NE(got.contacts.error().message().find("non-finite corner"), std::string::npos)
      << got.contacts.error().message();
}

INSTANTIATE_TEST_SUITE_P(Backends, DeviceNarrowPhase, ::testing::ValuesIn(backends()), backend_name);

TEST(DeviceNarrowPhaseArguments, BadArgumentsAreErrors) {
  auto device = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(device.ok());
  EXPECT_FALSE(collision::make_device_triangles(**device, std::vector<std::uint32_t>{}).ok());
  EXPECT_FALSE(collision::make_device_triangles(**device, std::vector<std::uint32_t>{0, 1}).ok());
  auto triangles = collision::make_device_triangles(**device, std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2});
  ASSERT_TRUE(triangles.ok());
  auto counts = (*device)->create_buffer(16, "counts");
  auto other = (*device)->create_buffer(16, "other counts");
  auto buffer = (*device)->create_buffer(64, "buffer");
  ASSERT_TRUE(counts.ok() && other.ok() && buffer.ok());
  EXPECT_FALSE(collision::make_device_contacts(**device, 0, *counts, 1).ok());
  auto out = collision::make_device_contacts(**device, 8, *counts, 1);
  ASSERT_TRUE(out.ok());
  const DeviceCount pair_count{*counts, 0, 4};
  FrameProgram program;
  program.counter("pairs", *counts, 0, 4);
  const auto message = [](const Status& s) { return s.ok() ? std::string() : s.error().message(); };
  Status s = collision::append_device_triangle_contacts(program, *buffer, *triangles, *buffer, pair_count, *out, 0.0f);
  EXPECT_NE(message(s).find("thickness must be finite and > 0"), std::string::npos) << message(s);
  s = collision::append_device_triangle_contacts(program, *buffer, *triangles, *buffer, pair_count, *out, NAN);
  EXPECT_NE(message(s).find("thickness must be finite and > 0"), std::string::npos) << message(s);
  s = collision::append_device_triangle_contacts(program, *buffer, *triangles, *buffer, DeviceCount{*other, 0, 4}, *out,
                                                 0.1f);
  EXPECT_NE(message(s).find("pair count must be in the contacts' counts buffer"), std::string::npos) << message(s);
  s = collision::append_device_triangle_contacts(program, *buffer, *triangles, *buffer, DeviceCount{*counts, 3, 4},
                                                 *out, 0.1f);
  EXPECT_NE(message(s).find("declared the pair count (word 3) a counter"), std::string::npos) << message(s);
  s = collision::append_device_triangle_contacts(program, BufferHandle{}, *triangles, *buffer, pair_count, *out, 0.1f);
  EXPECT_NE(message(s).find("must be valid"), std::string::npos) << message(s);
  s = collision::append_device_triangle_contacts(program, *buffer, *triangles, *buffer, DeviceCount{*counts, 0, 8},
                                                 *out, 0.1f);
  EXPECT_NE(message(s).find("declared with capacity 4, not 8"), std::string::npos) << message(s);
  auto clashing = collision::make_device_contacts(**device, 8, *counts, 0);  // its contact word is the pair word
  ASSERT_TRUE(clashing.ok());
  s = collision::append_device_triangle_contacts(program, *buffer, *triangles, *buffer, pair_count, *clashing, 0.1f);
  EXPECT_NE(message(s).find("three different words"), std::string::npos) << message(s);
  EXPECT_FALSE(collision::make_device_contacts(**device, (1u << 27) + 1, *counts, 1).ok());
  EXPECT_TRUE(collision::append_device_triangle_contacts(program, *buffer, *triangles, *buffer, pair_count, *out, 0.1f)
                  .ok());
}

}  // namespace
}  // namespace sinew::test
