// mesh_bounded_work_test.cpp — hostile surfaces and STL headers cost
// bounded time and memory and end in named errors (issue 39): an open
// triangle soup is judged by its edges alone, a pile of overlapping closed
// shells stops at the crossing search's pair bound, and an STL header
// claiming 2^32 - 1 triangles is refused before anything is allocated.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "sinew/mesh.h"

namespace sinew {
namespace {

// `count` triangles with corners uniform in the unit cube, none sharing a
// vertex: every edge open, and their boxes overlap by the million.
TriMesh triangle_soup(std::uint32_t count) {
  std::mt19937 rng(39);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  TriMesh soup;
  for (std::uint32_t t = 0; t < count; ++t) {
    for (int v = 0; v < 3; ++v) soup.vertices.push_back({u(rng), u(rng), u(rng)});
    soup.triangles.push_back({3 * t, 3 * t + 1, 3 * t + 2});
  }
  return soup;
}

// `count` closed tetrahedra (outward faces), each shifted by a little: every
// edge on two opposite triangles, and every triangle's box overlapping
// nearly every other's.
TriMesh piled_tetrahedra(std::uint32_t count) {
  std::mt19937 rng(39);
  std::uniform_real_distribution<double> u(0.0, 0.01);
  TriMesh pile;
  for (std::uint32_t t = 0; t < count; ++t) {
    const double dx = u(rng), dy = u(rng), dz = u(rng);
    const std::uint32_t f = 4 * t;
    pile.vertices.push_back({dx, dy, dz});
    pile.vertices.push_back({1 + dx, dy, dz});
    pile.vertices.push_back({dx, 1 + dy, dz});
    pile.vertices.push_back({dx, dy, 1 + dz});
    pile.triangles.push_back({f, f + 2, f + 1});
    pile.triangles.push_back({f, f + 1, f + 3});
    pile.triangles.push_back({f, f + 3, f + 2});
    pile.triangles.push_back({f + 1, f + 2, f + 3});
  }
  return pile;
}

TEST(MeshBoundedWork, AnOpenSoupIsJudgedByItsEdgesAlone) {
  // Before: every overlapping pair of a 20,000-triangle soup stored and
  // tested (42.6 s, 2.1 GB); now the open edges decide.
  const Result<SurfaceReport> report = check_closed_surface(triangle_soup(20000));
  ASSERT_TRUE(report.ok()) << report.error().message();
  EXPECT_EQ(report->open_edges, 60000u);
  EXPECT_FALSE(report->crossings_tested);
  EXPECT_EQ(report->intersecting_pairs, 0u);
  EXPECT_FALSE(report->closed());
}

// Found by fuzz_gmsh: two tets on the same four vertices share all their
// faces, so their boundary has no triangle; the crossing search then read
// the root of a tree of no boxes.
TEST(MeshBoundedWork, ASurfaceWithoutTrianglesIsNotClosed) {
  TetMesh twins;
  twins.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  twins.tets = {{0, 1, 2, 3}, {1, 0, 3, 2}};
  ASSERT_TRUE(check_tet_mesh(twins).ok());
  const TriMesh boundary = extract_boundary_surface(twins);
  EXPECT_TRUE(boundary.triangles.empty());
  for (const TriMesh& empty : {boundary, TriMesh{}}) {
    const Result<SurfaceReport> report = check_closed_surface(empty);
    ASSERT_TRUE(report.ok()) << report.error().message();
    EXPECT_FALSE(report->crossings_tested);
    EXPECT_FALSE(report->closed());
  }
}

TEST(MeshBoundedWork, OneClosedTetrahedronIsSearchedAndClosed) {
  const Result<SurfaceReport> report = check_closed_surface(piled_tetrahedra(1));
  ASSERT_TRUE(report.ok()) << report.error().message();
  EXPECT_TRUE(report->crossings_tested);
  EXPECT_TRUE(report->closed());
}

TEST(MeshBoundedWork, PiledClosedShellsStopAtThePairBound) {
  // 8,000 triangles, ~32 million overlapping pairs sharing no vertex: more
  // than the bound (2^20 here), so a named error, not a search.
  const Result<SurfaceReport> report = check_closed_surface(piled_tetrahedra(2000));
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.error().code(), ErrorCode::capacity_exceeded);
  EXPECT_NE(report.error().message().find("pairs of overlapping triangles"), std::string::npos)
      << report.error().message();
}

TEST(MeshBoundedWork, AnStlHeaderClaimingMoreTrianglesThanIndicesCanNumberIsNamed) {
  // A sparse file exactly as large as 2^32 - 1 triangles take (215 GB, no
  // disk space): the size check passes; before, reading it threw bad_alloc.
  std::filesystem::create_directories(SINEW_TEST_TMP_DIR);
  const auto path = std::filesystem::path(SINEW_TEST_TMP_DIR) / "claims_4g_triangles.stl";
  const std::uint32_t count = 0xffffffffu;
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    char header[80] = {};
    out.write(header, 80);
    out.write(reinterpret_cast<const char*>(&count), 4);
  }
  std::error_code ec;
  std::filesystem::resize_file(path, 84 + 50 * std::uint64_t{count}, ec);
  if (ec) GTEST_SKIP() << "cannot make a sparse file here: " << ec.message();
  const Result<TriMesh> mesh = read_stl(path);
  std::filesystem::remove(path, ec);
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.error().code(), ErrorCode::bad_input_file);
  EXPECT_NE(mesh.error().message().find("32-bit indices"), std::string::npos) << mesh.error().message();
}

}  // namespace
}  // namespace sinew
