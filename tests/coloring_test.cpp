// Colouring: every constraint gets exactly one colour and no two
// constraints of one colour share a movable particle, on random graphs and
// on real meshes; pinned particles create no conflicts; colours are balanced.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "coloring/greedy_coloring.h"
#include "sinew/mesh.h"
#include "test_support.h"

namespace sinew {
namespace {

// Independent check, written without the library's validator: for each
// colour, collect the movable particles of its constraints; a repeat is a conflict.
void expect_valid(const Coloring& col, const std::vector<std::uint32_t>& particles, std::uint32_t arity,
                  const std::vector<std::uint8_t>& movable) {
  const std::size_t n = particles.size() / arity;
  ASSERT_EQ(col.color_of.size(), n);
  std::vector<std::set<std::uint32_t>> used(col.color_count());
  std::vector<std::uint32_t> sizes(col.color_count(), 0);
  for (std::size_t c = 0; c < n; ++c) {
    ASSERT_LT(col.color_of[c], col.color_count());
    ++sizes[col.color_of[c]];
    for (std::uint32_t k = 0; k < arity; ++k) {
      const std::uint32_t p = particles[c * arity + k];
      if (!movable[p]) continue;
      EXPECT_TRUE(used[col.color_of[c]].insert(p).second)
          << "constraint " << c << " shares movable particle " << p << " within colour " << col.color_of[c];
    }
  }
  EXPECT_EQ(sizes, col.color_sizes);
  EXPECT_TRUE(coloring_is_valid(col, particles, arity, movable));
}

std::vector<std::uint32_t> tet_particles(const TetMesh& mesh) {
  std::vector<std::uint32_t> p;
  for (const auto& t : mesh.tets) p.insert(p.end(), t.begin(), t.end());
  return p;
}

TEST(Coloring, RandomConstraintsAreValidAndDeterministic) {
  std::mt19937 rng(std::random_device{}());
  for (std::uint32_t arity : {2u, 3u, 4u}) {
    const std::uint32_t particles = 500, constraints = 3000;
    std::uniform_int_distribution<std::uint32_t> pick(0, particles - 1);
    std::vector<std::uint32_t> idx;
    for (std::uint32_t c = 0; c < constraints; ++c) {
      std::set<std::uint32_t> s;
      while (s.size() < arity) s.insert(pick(rng));
      std::vector<std::uint32_t> v(s.begin(), s.end());
      std::shuffle(v.begin(), v.end(), rng);
      idx.insert(idx.end(), v.begin(), v.end());
    }
    std::vector<std::uint8_t> movable(particles);
    for (auto& m : movable) m = (pick(rng) % 10) != 0;  // ~10% pinned
    const Coloring a = color_constraints(idx, arity, movable);
    expect_valid(a, idx, arity, movable);
    const Coloring b = color_constraints(idx, arity, movable);
    EXPECT_EQ(a.color_of, b.color_of) << "colouring must be deterministic";
  }
}

TEST(Coloring, RealMeshesAreValidAndBalanced) {
  auto armadillo = read_tetgen(test::data_path("meshes/tet/armadillo_4k.node"));
  ASSERT_TRUE(armadillo.ok()) << armadillo.error().message();
  const TetMesh meshes[] = {*armadillo, test::box_mesh(10, 10, 10, 0.1)};
  for (const TetMesh& mesh : meshes) {
    const auto idx = tet_particles(mesh);
    const std::vector<std::uint8_t> movable(mesh.vertices.size(), 1);
    const Coloring col = color_constraints(idx, 4, movable);
    expect_valid(col, idx, 4, movable);
    // At least as many colours as tets sharing one vertex (a clique).
    std::vector<std::uint32_t> valence(mesh.vertices.size(), 0);
    for (std::uint32_t p : idx) ++valence[p];
    const std::uint32_t max_valence = *std::max_element(valence.begin(), valence.end());
    EXPECT_GE(col.color_count(), max_valence);
    EXPECT_LE(col.color_count(), 2 * max_valence) << "greedy colouring should stay near the clique bound";
    // Balanced: no colour holds more than twice the mean.
    const double mean = static_cast<double>(mesh.tets.size()) / col.color_count();
    for (std::uint32_t size : col.color_sizes) EXPECT_LE(size, 2.0 * mean);
  }
}

TEST(Coloring, PinnedParticlesCreateNoConflict) {
  // A star: 50 edges all sharing particle 0. Movable hub: 50 colours;
  // pinned hub: the edges are independent and need one colour.
  std::vector<std::uint32_t> idx;
  for (std::uint32_t k = 1; k <= 50; ++k) idx.insert(idx.end(), {0u, k});
  std::vector<std::uint8_t> movable(51, 1);
  EXPECT_EQ(color_constraints(idx, 2, movable).color_count(), 50u);
  movable[0] = 0;
  const Coloring pinned = color_constraints(idx, 2, movable);
  EXPECT_EQ(pinned.color_count(), 1u);
  expect_valid(pinned, idx, 2, movable);
}

TEST(Coloring, ValidatorRejectsAConflict) {
  const std::vector<std::uint32_t> idx{0, 1, 1, 2};
  const std::vector<std::uint8_t> movable(3, 1);
  Coloring bad;
  bad.color_of = {0, 0};
  bad.color_sizes = {2};
  EXPECT_FALSE(coloring_is_valid(bad, idx, 2, movable));
}

}  // namespace
}  // namespace sinew
