// device_ccd_test.cpp — continuous collision queries in a kernel
// (src/ccd/device_ccd.h, kernels/shared/ccd_params.h): on every backend,
// zero false negatives on all 7,279 hand-crafted benchmark queries (the
// single-precision kernel with its own error bound), a time never later
// than the first touch on motions with closed-form touch times, and bad
// input named. False positives are printed beside the double-precision
// reference's (sinew/ccd.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "ccd/benchmark_queries.h"
#include "ccd/device_ccd.h"
#include "test_support.h"

namespace sinew::test {
namespace {

using ccd::DeviceQuery;
using ccd::Point;

class DeviceCcd : public BackendTest {};

// The benchmark's hand-crafted queries (read once), as device queries.
struct Handcrafted {
  std::vector<ccd::BenchmarkQuery> queries;
  std::vector<DeviceQuery> device;
};
const Handcrafted& handcrafted() {
  static const Handcrafted set = [] {
    Handcrafted h;
    auto read = ccd::read_benchmark_queries(data_path("ccd/handcrafted"));
    EXPECT_TRUE(read.ok()) << (read.ok() ? "" : read.error().message());
    if (read.ok()) h.queries = std::move(*read);
    for (const auto& q : h.queries) h.device.push_back({q.vertex_face, q.points});
    return h;
  }();
  return set;
}

TEST_P(DeviceCcd, NoFalseNegativeOnTheHandcraftedBenchmark) {
  const auto* queries = &handcrafted().queries;
  const std::vector<DeviceQuery>& mine = handcrafted().device;
  ASSERT_EQ(queries->size(), 7279u);
  auto device = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  const auto hits = ccd::device_queries(**device, mine);
  ASSERT_TRUE(hits.ok()) << hits.error().message();
  ASSERT_EQ(hits->size(), queries->size());
  std::size_t negatives = 0, false_positives = 0, reference_fp = 0, gave_up = 0;
  for (std::size_t k = 0; k < queries->size(); ++k) {
    const auto& q = (*queries)[k];
    const auto& hit = (*hits)[k];
    if (q.truth) {
      ASSERT_TRUE(hit.touch) << "a false negative in " << q.file << " (query " << k << ")";
    } else {
      ++negatives;
      false_positives += hit.touch;
      const auto reference = ccd::run_query(q);
      ASSERT_TRUE(reference.ok());
      reference_fp += reference->touch;
    }
    ASSERT_GE(hit.time, 0.0);
    ASSERT_LE(hit.time, 1.0);
    gave_up += hit.gave_up;
  }
  std::printf("[ device ccd ] %s: 0 false negatives; %zu false positives of %zu negatives (double reference: %zu), "
              "%zu gave up\n",
              GetParam().c_str(), false_positives, negatives, reference_fp, gave_up);
}

// A vertex falling onto a triangle and an edge onto a crossing edge, at
// closed-form times: the kernel's time is never later.
TEST_P(DeviceCcd, TimeIsNeverLaterThanTheFirstTouch) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.05, 0.95), spread(-0.4, 0.4);
  std::vector<DeviceQuery> queries;
  std::vector<double> times;
  for (int n = 0; n < 1000; ++n) {
    const double t_star = u(rng), speed = 0.5 + 2.0 * u(rng), x = spread(rng), y = spread(rng);
    const Point a{-1.0, -1.0, 0.0}, b{2.0, -1.0, 0.0}, c{-1.0, 2.0, 0.0};
    const Point p0{x, y, speed * t_star}, p1{x, y, speed * (t_star - 1.0)};
    queries.push_back({true, {p0, a, b, c, p1, a, b, c}});
    const Point e0{-1.0, y, speed * t_star}, e1{1.0, y, speed * t_star};
    const Point e0_end{-1.0, y, speed * (t_star - 1.0)}, e1_end{1.0, y, speed * (t_star - 1.0)};
    const Point f0{x, -1.0, 0.0}, f1{x, 1.0, 0.0};
    queries.push_back({false, {e0, e1, f0, f1, e0_end, e1_end, f0, f1}});
    times.push_back(t_star);
    times.push_back(t_star);
  }
  auto device = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  const auto hits = ccd::device_queries(**device, queries);
  ASSERT_TRUE(hits.ok()) << hits.error().message();
  for (std::size_t k = 0; k < queries.size(); ++k) {
    ASSERT_TRUE((*hits)[k].touch) << "query " << k;
    // Never later than the touch of the caller's double geometry (the
    // kernel's bound covers the rounding of its inputs to float).
    ASSERT_LE((*hits)[k].time, times[k] + 1e-9) << "query " << k << ": later than the touch";
    ASSERT_GE((*hits)[k].time, times[k] - 1e-3) << "query " << k;
  }
}

// The finest resolution (tolerance 1e-9 m, clamped to the float kernel's
// 2^-23 of a step): 25 queries need more than 65,535 boxes. On lavapipe,
// whose loop cap (65,535 iterations per invocation) cuts those searches,
// they report a touch (given up), never a miss; elsewhere they run on or
// reach max_boxes. Either way: 0 false negatives.
TEST_P(DeviceCcd, SearchesCutShortStayConservative) {
  const auto* queries = &handcrafted().queries;
  const std::vector<DeviceQuery>& mine = handcrafted().device;
  ASSERT_EQ(queries->size(), 7279u);
  auto device = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  ccd::Settings fine;
  fine.tolerance = 1e-9;
  const auto hits = ccd::device_queries(**device, mine, fine);
  ASSERT_TRUE(hits.ok()) << hits.error().message();
  std::size_t gave_up = 0, long_searches = 0;
  for (std::size_t k = 0; k < queries->size(); ++k) {
    if ((*queries)[k].truth) {
      ASSERT_TRUE((*hits)[k].touch) << "a false negative at the finest resolution: query " << k;
    }
    gave_up += (*hits)[k].gave_up;
    long_searches += (*hits)[k].boxes > 65535 || (*hits)[k].gave_up;
  }
  EXPECT_GT(long_searches, 0u) << "the case this test is for";
  std::printf("[ device ccd ] %s, tolerance 1e-9: %zu searches longer than 65,535 boxes or given up, %zu gave up\n",
              GetParam().c_str(), long_searches, gave_up);
}

TEST_P(DeviceCcd, BadInputIsNamed) {
  auto device = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  DeviceQuery q;
  q.points[5] = {0.0, 1e20, 0.0};
  const auto big = ccd::device_queries(**device, std::vector<DeviceQuery>{q});
  ASSERT_FALSE(big.ok());
  EXPECT_NE(big.error().message().find("within 1e15"), std::string::npos) << big.error().message();
  q.points[5] = {0.0, NAN, 0.0};
  EXPECT_FALSE(ccd::device_queries(**device, std::vector<DeviceQuery>{q}).ok());
  ccd::Settings s;
  s.tolerance = -1.0;
  EXPECT_FALSE(ccd::device_queries(**device, std::vector<DeviceQuery>{DeviceQuery{}}, s).ok());
  const auto none = ccd::device_queries(**device, std::vector<DeviceQuery>{});
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty());
}

INSTANTIATE_TEST_SUITE_P(Backends, DeviceCcd, ::testing::ValuesIn(backends()), backend_name);

}  // namespace
}  // namespace sinew::test
