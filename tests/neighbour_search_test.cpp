// neighbour_search_test.cpp — the fixed-radius neighbour search (issue 15,
// part 1; sinew/neighbours.h) against brute force: on every backend the
// neighbour sets equal a brute-force float loop exactly, on uniform random
// points, a cluster inside one cell (everyone neighbours everyone), a
// lattice whose points sit on cell boundaries and exactly one radius apart
// (excluded: "closer than"), and points spread over many times the hash's
// period (buckets shared by far-apart cells); the lists are the CPU
// backend's word for word; lists that outgrow their slots grow and run
// again; bad input is named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "sinew/neighbours.h"
#include "test_support.h"

namespace sinew::test {
namespace {

using Points = std::vector<std::array<float, 3>>;

// Every i's neighbours, ascending: j != i with the float distance squared,
// in the search's order of operations, below float(r)^2.
std::vector<std::vector<std::uint32_t>> brute_force(const Points& x, double radius) {
  const float r2 = float(radius) * float(radius);
  std::vector<std::vector<std::uint32_t>> out(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = 0; j < x.size(); ++j) {
      if (i == j) continue;
      const float ex = x[j][0] - x[i][0], ey = x[j][1] - x[i][1], ez = x[j][2] - x[i][2];
      const float d2 = ex * ex + ey * ey + ez * ez;
      if (d2 < r2) out[i].push_back(std::uint32_t(j));
    }
  return out;
}

std::vector<std::vector<std::uint32_t>> sets_of(const NeighbourLists& lists) {
  std::vector<std::vector<std::uint32_t>> out(lists.offsets.size() - 1);
  for (std::size_t i = 0; i + 1 < lists.offsets.size(); ++i) {
    out[i].assign(lists.neighbours.begin() + lists.offsets[i], lists.neighbours.begin() + lists.offsets[i + 1]);
    std::sort(out[i].begin(), out[i].end());
  }
  return out;
}

struct Case {
  const char* name;
  Points points;
  double radius;
  bool isolated = false;  // no point has a neighbour
};

std::vector<Case> cases() {
  std::vector<Case> all;
  std::mt19937 rng(15);
  {  // uniform: 4,000 points in a 2 cm cube, about 25 neighbours each
    std::uniform_real_distribution<float> u(-0.01f, 0.01f);
    Points p(4000);
    for (auto& x : p) x = {u(rng), u(rng), u(rng)};
    all.push_back({"uniform", p, 0.0023});
  }
  {  // clustered: 300 points inside a quarter of one cell
    std::uniform_real_distribution<float> u(0.0101f, 0.0104f);
    Points p(300);
    for (auto& x : p) x = {u(rng), u(rng), u(rng)};
    all.push_back({"clustered", p, 0.002});
  }
  {  // a lattice of spacing = radius about the origin: on cell boundaries, exactly one radius apart
    Points p;
    const float h = 0.25f;  // exact in float, and so are its multiples and squares
    for (int i = -6; i <= 6; ++i)
      for (int j = -6; j <= 6; ++j)
        for (int k = -6; k <= 6; ++k) p.push_back({i * h, j * h, k * h});
    all.push_back({"lattice at the radius", p, 0.25, true});
    all.push_back({"lattice within the radius", p, 0.2500001});
  }
  {  // spread over +-5,000 radii: far more cells than buckets (cells far apart share buckets)
    std::uniform_real_distribution<float> u(-5.0f, 5.0f), near(-0.002f, 0.002f);
    Points p;
    for (int c = 0; c < 100; ++c) {
      const std::array<float, 3> centre{u(rng), u(rng), u(rng)};
      for (int k = 0; k < 20; ++k) p.push_back({centre[0] + near(rng), centre[1] + near(rng), centre[2] + near(rng)});
    }
    all.push_back({"spread out", p, 0.001});
  }
  return all;
}

class NeighbourSearchTest : public BackendTest {};

TEST_P(NeighbourSearchTest, NeighbourSetsEqualBruteForce) {
  for (const Case& c : cases()) {
    auto search = NeighbourSearch::create({.radius = c.radius, .capacity = std::uint32_t(c.points.size()),
                                           .device = {.backend = GetParam(), .quiet = true}});
    ASSERT_TRUE(search.ok()) << search.error().message();
    NeighbourLists lists;
    SINEW_ASSERT_OK(search->find(c.points, lists));
    ASSERT_EQ(lists.offsets.size(), c.points.size() + 1) << c.name;
    const auto expected = brute_force(c.points, c.radius);
    std::size_t pairs = 0, differ = 0;
    const auto found = sets_of(lists);
    for (std::size_t i = 0; i < expected.size(); ++i) {
      pairs += expected[i].size();
      differ += found[i] != expected[i];
    }
    std::printf("[ measured ] %s, %s: %zu points, %zu neighbour pairs, %zu lists differ from brute force\n",
                GetParam().c_str(), c.name, c.points.size(), pairs, differ);
    EXPECT_EQ(differ, 0u) << c.name;
    EXPECT_EQ(lists.neighbours.size(), pairs) << c.name;
    if (c.isolated) EXPECT_EQ(pairs, 0u) << c.name << ": one radius apart is not closer";
    else EXPECT_GT(pairs, 0u) << c.name;
  }
}

TEST_P(NeighbourSearchTest, ListsAreTheCpuBackendsWordForWord) {
  // The scalar CPU reference's lists; on "cpu", its AVX2 query's must equal them.
  const Case c = cases().front();
  NeighbourLists reference, lists;
  for (const bool reference_run : {true, false}) {
    const DeviceOptions device = reference_run ? DeviceOptions{.backend = "cpu", .cpu_simd = false, .quiet = true}
                                               : DeviceOptions{.backend = GetParam(), .quiet = true};
    auto search = NeighbourSearch::create({.radius = c.radius, .capacity = std::uint32_t(c.points.size()), .device = device});
    ASSERT_TRUE(search.ok()) << search.error().message();
    SINEW_ASSERT_OK(search->find(c.points, reference_run ? reference : lists));
  }
  EXPECT_EQ(lists.offsets, reference.offsets);
  EXPECT_EQ(lists.neighbours, reference.neighbours);
}

TEST_P(NeighbourSearchTest, ListsThatOutgrowTheirSlotsGrowAndRunAgain) {
  // 10 slots for about 50,000 pairs: the first run counts them, the slots
  // grow to that, the second run writes them; a second search needs no growth.
  const Case c = cases().front();
  auto search = NeighbourSearch::create({.radius = c.radius, .capacity = std::uint32_t(c.points.size()),
                                         .pair_capacity = 10, .device = {.backend = GetParam(), .quiet = true}});
  ASSERT_TRUE(search.ok()) << search.error().message();
  NeighbourLists lists;
  SINEW_ASSERT_OK(search->find(c.points, lists));
  EXPECT_EQ(search->regrown(), 1u);
  EXPECT_EQ(sets_of(lists), brute_force(c.points, c.radius));
  Points fewer(c.points.begin(), c.points.begin() + 1000);
  SINEW_ASSERT_OK(search->find(fewer, lists));
  EXPECT_EQ(search->regrown(), 1u);
  EXPECT_EQ(sets_of(lists), brute_force(fewer, c.radius)) << "fewer points than the capacity";
  SINEW_ASSERT_OK(search->find({}, lists));
  EXPECT_EQ(lists.offsets, std::vector<std::uint32_t>{0u});
}

INSTANTIATE_TEST_SUITE_P(Backends, NeighbourSearchTest, ::testing::ValuesIn(backends()), backend_name);

TEST(NeighbourSearch, BadInputIsNamed) {
  const auto error = [](const NeighbourSettings& s) {
    auto made = NeighbourSearch::create(s);
    return made.ok() ? std::string() : made.error().message();
  };
  EXPECT_NE(error({.radius = 0.0, .capacity = 10, .device = {.backend = "cpu"}}).find("radius"), std::string::npos);
  EXPECT_NE(error({.radius = NAN, .capacity = 10, .device = {.backend = "cpu"}}).find("radius"), std::string::npos);
  EXPECT_NE(error({.radius = 1e-3, .capacity = 0, .device = {.backend = "cpu"}}).find("capacity"), std::string::npos);
  auto search = NeighbourSearch::create({.radius = 1e-3, .capacity = 2, .device = {.backend = "cpu"}});
  ASSERT_TRUE(search.ok());
  NeighbourLists lists;
  const auto message = [&](const Points& p) {
    const Status s = search->find(p, lists);
    return s.ok() ? std::string() : s.error().message();
  };
  EXPECT_NE(message({{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}).find("3 points, more than its capacity 2"), std::string::npos);
  EXPECT_NE(message({{0, 0, 0}, {0, NAN, 0}}).find("point 1 has coordinate nan"), std::string::npos)
      << message({{0, 0, 0}, {0, NAN, 0}});
  EXPECT_NE(message({{0, 0, 100.0f}}).find("point 0 has coordinate 100"), std::string::npos)
      << "beyond 2^16 cells of 1 mm";
}

}  // namespace
}  // namespace sinew::test
