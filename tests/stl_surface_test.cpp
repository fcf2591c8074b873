// stl_surface_test.cpp — binary STL surfaces and whether they bound a solid
// (issue 14, part 1): the data's four organ and bone surfaces read with
// their triangle counts and are closed; a cube's faults (a hole, a flipped
// triangle, a second cube through it, a sliver) are each counted; bad files
// are named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "sinew/mesh.h"

namespace sinew {
namespace {

// The 12 triangles of the cube [lo, lo + size]^3, wound counter-clockwise
// seen from outside, appended to `mesh`.
void add_cube(TriMesh& mesh, const Vec3d& lo, double size) {
  const auto first = static_cast<std::uint32_t>(mesh.vertices.size());
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) mesh.vertices.push_back({lo[0] + i * size, lo[1] + j * size, lo[2] + k * size});
  // Corner (i, j, k) is first + i + 2 j + 4 k; each face as two triangles.
  const std::uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    mesh.triangles.push_back({first + f[0], first + f[1], first + f[2]});
    mesh.triangles.push_back({first + f[0], first + f[2], first + f[3]});
  }
}

std::filesystem::path temp(const std::string& name) {
  std::filesystem::create_directories(SINEW_TEST_TMP_DIR);
  return std::filesystem::path(SINEW_TEST_TMP_DIR) / name;
}

// Writes `triangles` triangles of the given corners as a binary STL, or
// with a wrong count in the header (`count`).
void write_stl(const std::filesystem::path& path, const std::vector<std::array<float, 9>>& triangles,
               std::uint32_t count) {
  std::ofstream out(path, std::ios::binary);
  char header[80] = {};
  out.write(header, 80);
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : triangles) {
    const float normal[3] = {0.0f, 0.0f, 0.0f};
    out.write(reinterpret_cast<const char*>(normal), 12);
    out.write(reinterpret_cast<const char*>(t.data()), 36);
    const std::uint16_t attributes = 0;
    out.write(reinterpret_cast<const char*>(&attributes), 2);
  }
}

TEST(Stl, TheDataSurfacesAreReadWeldedAndClosed) {
  struct Expected {
    const char* file;
    std::size_t triangles;
  };
  // Triangle counts from data/README.md.
  for (const Expected& e : {Expected{"Liver.stl", 30726}, Expected{"Kidney_left.stl", 6570},
                            Expected{"Stomach.stl", 9724}, Expected{"VHF_Left_Bone_Tibia_smooth.stl", 59456}}) {
    auto mesh = read_stl(std::string(SINEW_DATA_DIR) + "/meshes/surface/" + e.file);
    ASSERT_TRUE(mesh.ok()) << mesh.error().message();
    EXPECT_EQ(mesh->triangles.size(), e.triangles) << e.file;
    const SurfaceReport r = check_closed_surface(*mesh).value();
    std::printf("%s: %zu vertices, %zu triangles; %llu open, %llu non-manifold, %llu misoriented edges, %llu "
                "degenerate triangles, %llu crossing pairs\n",
                e.file, mesh->vertices.size(), mesh->triangles.size(), (unsigned long long)r.open_edges,
                (unsigned long long)r.nonmanifold_edges, (unsigned long long)r.misoriented_edges,
                (unsigned long long)r.degenerate_triangles, (unsigned long long)r.intersecting_pairs);
    // A closed surface of genus 0 has V - E + F = 2 with E = 3F/2: V = F/2 + 2.
    EXPECT_EQ(mesh->vertices.size(), e.triangles / 2 + 2) << e.file << ": the welded vertices";
    EXPECT_TRUE(r.closed()) << e.file;
  }
}

TEST(Stl, ACubeWrittenAndReadBackIsTheSameCube) {
  TriMesh cube;
  add_cube(cube, {-1.0, 0.0, 2.0}, 0.5);
  std::vector<std::array<float, 9>> triangles;
  for (const auto& t : cube.triangles) {
    std::array<float, 9> corners{};
    for (int v = 0; v < 3; ++v)
      for (int k = 0; k < 3; ++k) corners[3 * v + k] = float(cube.vertices[t[v]][k]);
    triangles.push_back(corners);
  }
  write_stl(temp("cube.stl"), triangles, 12);
  auto read = read_stl(temp("cube.stl"));
  ASSERT_TRUE(read.ok()) << read.error().message();
  ASSERT_EQ(read->triangles.size(), 12u);
  ASSERT_EQ(read->vertices.size(), 8u);
  for (std::size_t t = 0; t < 12; ++t)
    for (int v = 0; v < 3; ++v)
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(read->vertices[read->triangles[t][v]][k], cube.vertices[cube.triangles[t][v]][k]);
  EXPECT_TRUE(check_closed_surface(*read)->closed());
}

TEST(Stl, EachFaultOfASurfaceIsCounted) {
  TriMesh cube;
  add_cube(cube, {0.0, 0.0, 0.0}, 1.0);
  ASSERT_TRUE(check_closed_surface(cube)->closed());

  TriMesh holed = cube;
  holed.triangles.pop_back();
  EXPECT_EQ(check_closed_surface(holed)->open_edges, 3u);

  TriMesh flipped = cube;
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_EQ(check_closed_surface(flipped)->misoriented_edges, 3u);

  TriMesh two = cube;
  add_cube(two, {0.5, 0.5, 0.5}, 1.0);  // through the first
  const SurfaceReport crossed = check_closed_surface(two).value();
  EXPECT_GT(crossed.intersecting_pairs, 0u);
  EXPECT_EQ(crossed.open_edges, 0u);

  TriMesh apart = cube;
  add_cube(apart, {3.0, 0.0, 0.0}, 1.0);  // beside it: two closed surfaces
  EXPECT_TRUE(check_closed_surface(apart)->closed());

  TriMesh sliver = cube;
  sliver.vertices.push_back(sliver.vertices[0]);
  sliver.triangles.push_back({0, 1, static_cast<std::uint32_t>(sliver.vertices.size() - 1)});
  EXPECT_EQ(check_closed_surface(sliver)->degenerate_triangles, 1u);

  TriMesh fin = cube;  // a third triangle on an edge
  fin.vertices.push_back({0.5, -1.0, 0.0});
  fin.triangles.push_back({0, 1, static_cast<std::uint32_t>(fin.vertices.size() - 1)});
  EXPECT_GE(check_closed_surface(fin)->nonmanifold_edges, 1u);
}

TEST(Stl, BadFilesAreNamed) {
  const auto error_of = [](const std::filesystem::path& path) {
    auto mesh = read_stl(path);
    EXPECT_FALSE(mesh.ok());
    if (mesh.ok()) return std::string();
    EXPECT_EQ(mesh.error().code(), ErrorCode::bad_input_file);
    return mesh.error().message();
  };
  EXPECT_NE(error_of(temp("no_such.stl")).find("no_such.stl"), std::string::npos);
  {
    std::ofstream out(temp("ascii.stl"));
    out << "solid cube\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n"
           "      vertex 0 1 0\n    endloop\n  endfacet\nendsolid cube\n";
  }
  EXPECT_NE(error_of(temp("ascii.stl")).find("ASCII STL"), std::string::npos) << error_of(temp("ascii.stl"));
  const std::array<float, 9> one{0, 0, 0, 1, 0, 0, 0, 1, 0};
  write_stl(temp("short.stl"), {one}, 2);
  EXPECT_NE(error_of(temp("short.stl")).find("says 2 triangles"), std::string::npos) << error_of(temp("short.stl"));
  write_stl(temp("empty.stl"), {}, 0);
  EXPECT_NE(error_of(temp("empty.stl")).find("no triangles"), std::string::npos) << error_of(temp("empty.stl"));
  std::array<float, 9> bad = one;
  bad[4] = NAN;
  write_stl(temp("nan.stl"), {bad}, 1);
  EXPECT_NE(error_of(temp("nan.stl")).find("triangle 0, vertex 1"), std::string::npos) << error_of(temp("nan.stl"));
  {
    std::ofstream out(temp("tiny.stl"), std::ios::binary);
    out << "abc";
  }
  EXPECT_NE(error_of(temp("tiny.stl")).find("too short"), std::string::npos) << error_of(temp("tiny.stl"));
}

}  // namespace
}  // namespace sinew
