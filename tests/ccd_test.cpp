// ccd_test.cpp — continuous collision detection (sinew/ccd.h): zero false
// negatives on every query of the CCD benchmark's hand-crafted set (Wang
// et al. 2021; 7,279 queries with exact answers, data/ccd/handcrafted), a
// time never later than the first touch on motions whose touch time is
// known in closed form, the minimum separation honoured, and bad input
// named. False positives are counted and printed, not asserted (they are
// allowed; the benchmark reports them).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <cstdio>
#include <random>
#include <string>

#include "ccd/benchmark_queries.h"
#include "sinew/ccd.h"
#include "test_support.h"

namespace sinew::ccd {
namespace {

TEST(Ccd, NoFalseNegativeOnTheHandcraftedBenchmark) {
  const auto queries = read_benchmark_queries(test::data_path("ccd/handcrafted"));
  ASSERT_TRUE(queries.ok()) << queries.error().message();
  ASSERT_EQ(queries->size(), 7279u) << "data/ccd/handcrafted/FORMAT.md counts 7,279 queries";
  std::size_t positives = 0, negatives = 0, false_positives = 0, gave_up = 0;
  for (const BenchmarkQuery& q : *queries) {
    const auto hit = run_query(q);
    ASSERT_TRUE(hit.ok()) << q.file << ": " << hit.error().message();
    if (q.truth) {
      ++positives;
      ASSERT_TRUE(hit->touch) << "a false negative in " << q.file;
    } else {
      ++negatives;
      false_positives += hit->touch;
    }
    gave_up += hit->gave_up;
  }
  EXPECT_EQ(positives, 435u);
  std::printf("[ ccd ] %zu queries: 0 false negatives of %zu touches, %zu false positives of %zu (%.2f%%), %zu gave up\n",
              queries->size(), positives, false_positives, negatives, 100.0 * double(false_positives) / double(negatives),
              gave_up);
}

// A vertex falling onto a still triangle, and two edges crossing at a
// known time: the time returned lies within the tolerance's reach before
// the true one, never after; a miss by more than the tolerance is a miss.
TEST(Ccd, TimeIsNeverLaterThanTheFirstTouch) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.05, 0.95), spread(-1.0, 1.0);
  const Settings settings;  // tolerance 1e-6 m
  for (int n = 0; n < 2000; ++n) {
    // Triangle in z = 0 around the origin; the vertex above a point of it
    // falls at speed `speed` and reaches it at t* = height / speed.
    const std::array<Point, 2> a{Point{-1.0, -1.0, 0.0}, Point{-1.0, -1.0, 0.0}};
    const std::array<Point, 2> b{Point{2.0, -1.0, 0.0}, Point{2.0, -1.0, 0.0}};
    const std::array<Point, 2> c{Point{-1.0, 2.0, 0.0}, Point{-1.0, 2.0, 0.0}};
    const double t_star = u(rng), speed = 0.5 + 2.0 * u(rng);
    const double x = 0.4 * spread(rng), y = 0.4 * spread(rng);
    const std::array<Point, 2> p{Point{x, y, speed * t_star}, Point{x, y, speed * (t_star - 1.0)}};
    const auto hit = vertex_face(p, a, b, c, settings);
    ASSERT_TRUE(hit.ok()) << hit.error().message();
    ASSERT_TRUE(hit->touch) << "case " << n;
    ASSERT_LE(hit->time, t_star) << "case " << n << ": later than the touch";
    // Within the resolution: the tolerance (1e-6 m) over the speed, and a box.
    ASSERT_GE(hit->time, t_star - 1e-5) << "case " << n << ": far too early";
    // Edges: a horizontal edge in z = h(t) falling onto a crossing one in z = 0.
    const std::array<Point, 2> e0{Point{-1.0, y, speed * t_star}, Point{-1.0, y, speed * (t_star - 1.0)}};
    const std::array<Point, 2> e1{Point{1.0, y, speed * t_star}, Point{1.0, y, speed * (t_star - 1.0)}};
    const std::array<Point, 2> f0{Point{x, -1.0, 0.0}, Point{x, -1.0, 0.0}};
    const std::array<Point, 2> f1{Point{x, 1.0, 0.0}, Point{x, 1.0, 0.0}};
    const auto cross = edge_edge(e0, e1, f0, f1, settings);
    ASSERT_TRUE(cross.ok()) << cross.error().message();
    ASSERT_TRUE(cross->touch) << "case " << n;
    ASSERT_LE(cross->time, t_star) << "case " << n << ": later than the touch";
    ASSERT_GE(cross->time, t_star - 1e-5) << "case " << n;
    // Falling 1.06 mm beside the triangle's long edge (x + y = 1): no touch.
    const double outside = 1.0 - y + 0.0015;
    const std::array<Point, 2> beside{Point{outside, y, speed * t_star}, Point{outside, y, speed * (t_star - 1.0)}};
    const auto miss = vertex_face(beside, a, b, c, settings);
    ASSERT_TRUE(miss.ok());
    EXPECT_FALSE(miss->touch && !miss->gave_up) << "case " << n << ": 1 mm beside the triangle";
  }
}

// Touches at a corner or an edge of the primitives (parameters 0 or 1),
// where a box's corners land on the touching point: the time is the touch's
// within the resolution, not the start of a box that is close only at its
// end (found in review: these came back at t = 0).
TEST(Ccd, TouchesAtCornersAndEdgesKeepTheirTime) {
  const std::array<Point, 2> a{Point{0, 0, 0}, Point{0, 0, 0}}, b{Point{1, 0, 0}, Point{1, 0, 0}},
      c{Point{0, 1, 0}, Point{0, 1, 0}};
  struct Fall {
    Point from, to;
    double t_star;
  };
  for (const Fall& f : {Fall{{0, 0, 1}, {0, 0, 0}, 1.0}, Fall{{0, 0, 1}, {0, 0, -1}, 0.5},
                        Fall{{1, 0, 1}, {1, 0, -3}, 0.25}, Fall{{0.25, 0.25, 1}, {0.25, 0.25, -1}, 0.5}}) {
    const auto hit = vertex_face({f.from, f.to}, a, b, c);
    ASSERT_TRUE(hit.ok());
    ASSERT_TRUE(hit->touch);
    EXPECT_LE(hit->time, f.t_star);
    EXPECT_GE(hit->time, f.t_star - 1e-5) << "falling from z = " << f.from[2];
  }
  // An edge falling onto a crossing edge's end, and onto its middle, at t = 1.
  const std::array<Point, 2> g0{Point{0, -1, 0}, Point{0, -1, 0}}, g1{Point{0, 0, 0}, Point{0, 0, 0}};
  const auto end_on = edge_edge({Point{0, 0, 1}, Point{0, 0, 0}}, {Point{1, 0, 1}, Point{1, 0, 0}}, g0, g1);
  ASSERT_TRUE(end_on.ok() && end_on->touch);
  EXPECT_GE(end_on->time, 1.0 - 1e-5);
  const std::array<Point, 2> h0{Point{0, -1, 0}, Point{0, -1, 0}}, h1{Point{0, 1, 0}, Point{0, 1, 0}};
  const auto middle = edge_edge({Point{-1, 0, 1}, Point{-1, 0, 0}}, {Point{1, 0, 1}, Point{1, 0, 0}}, h0, h1);
  ASSERT_TRUE(middle.ok() && middle->touch);
  EXPECT_GE(middle->time, 1.0 - 1e-5);
}

// The minimum separation: a vertex that stops 1 mm above a triangle touches
// within 2 mm, not within 0.5 mm.
TEST(Ccd, MinimumSeparationCountsNearMissesAsTouches) {
  const std::array<Point, 2> a{Point{0, 0, 0}, Point{0, 0, 0}}, b{Point{1, 0, 0}, Point{1, 0, 0}},
      c{Point{0, 1, 0}, Point{0, 1, 0}};
  const std::array<Point, 2> p{Point{0.2, 0.2, 0.5}, Point{0.2, 0.2, 0.001}};
  Settings near;
  near.min_separation = 0.002;
  const auto touch = vertex_face(p, a, b, c, near);
  ASSERT_TRUE(touch.ok());
  EXPECT_TRUE(touch->touch);
  EXPECT_LE(touch->time, (0.5 - 0.002) / (0.5 - 0.001));  // when it came within 2 mm
  Settings far;
  far.min_separation = 0.0005;
  const auto miss = vertex_face(p, a, b, c, far);
  ASSERT_TRUE(miss.ok());
  EXPECT_FALSE(miss->touch);
}

TEST(Ccd, BadInputIsNamed) {
  const std::array<Point, 2> ok{Point{0, 0, 0}, Point{0, 0, 1}};
  std::array<Point, 2> bad = ok;
  bad[1][2] = NAN;
  const auto message = [](const Result<Hit>& r) { return r.ok() ? std::string() : r.error().message(); };
  EXPECT_NE(message(vertex_face(bad, ok, ok, ok)).find("point 0 has coordinate"), std::string::npos);
  bad[1][2] = 1e200;
  EXPECT_NE(message(edge_edge(ok, ok, ok, bad)).find("within 1e100"), std::string::npos);
  Settings s;
  s.tolerance = 0.0;
  EXPECT_NE(message(vertex_face(ok, ok, ok, ok, s)).find("tolerance must be finite and > 0"), std::string::npos);
  s = Settings{};
  s.min_separation = -1.0;
  EXPECT_NE(message(vertex_face(ok, ok, ok, ok, s)).find("minimum separation"), std::string::npos);
  s = Settings{};
  s.max_boxes = 0;
  EXPECT_NE(message(vertex_face(ok, ok, ok, ok, s)).find("max_boxes"), std::string::npos);
}

TEST(Ccd, MalformedQueryFilesAreNamed) {
  const auto missing = read_benchmark_queries(test::data_path("ccd/no-such-folder"));
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code(), ErrorCode::bad_input_file);
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() / "sinew_ccd_bad_queries";
  fs::remove_all(root);
  fs::create_directories(root / "scene" / "vertex-face");
  const auto with = [&](const std::string& rows) {
    std::ofstream(root / "scene" / "vertex-face" / "data_0_0.csv") << rows;
    return read_benchmark_queries(root);
  };
  std::string good;
  for (int r = 0; r < 8; ++r) good += "1,2,3,4,-5,8,1\n";
  const auto fine = with(good);
  ASSERT_TRUE(fine.ok()) << fine.error().message();
  ASSERT_EQ(fine->size(), 1u);
  EXPECT_EQ((*fine)[0].points[3][0], 0.5);
  EXPECT_EQ((*fine)[0].points[3][2], -0.625);
  const auto message = [](const Result<std::vector<BenchmarkQuery>>& r) {
    return r.ok() ? std::string() : r.error().message();
  };
  EXPECT_NE(message(with("1,3,0,1,0,1,0\n")).find("row 1: denominator '3' is not a positive power of two"),
            std::string::npos);
  EXPECT_NE(message(with("1,2,0,1,0\n")).find("5 columns, not 7"), std::string::npos);
  EXPECT_NE(message(with(good.substr(0, good.size() / 2))).find("not a multiple of 8"), std::string::npos);
  EXPECT_NE(message(with("1,2,3,4,-5,8,1\n1,2,3,4,-5,8,0\n")).find("truth bit differs"), std::string::npos);
  EXPECT_NE(message(with("18014398509481985,1,0,1,0,1,0\n")).find("more than 53 bits"), std::string::npos);
  fs::remove_all(root);
}

}  // namespace
}  // namespace sinew::ccd
