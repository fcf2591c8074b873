// extract_boundary_surface against a brute-force face count on a real mesh;
// write_vtu read back by the tests' own binary VTU reader (vtu_reader.h),
// write_pvd as text.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "mesh_test_helpers.h"
#include "sinew/mesh.h"
#include "vtu_reader.h"

namespace {

namespace fs = std::filesystem;
using sinew::TetMesh;
using sinew::Vec3d;
using Face = std::array<std::uint32_t, 3>;

fs::path tmp_dir() { return sinew::mesh_test::tmp_dir("mesh_boundary_vtu"); }

using sinew::mesh_test::cross;
using sinew::mesh_test::dot;
using sinew::mesh_test::sub;

Face sorted(Face f) {
  std::sort(f.begin(), f.end());
  return f;
}

// ------------------------------------------------------------ boundary

TEST(BoundarySurface, MatchesBruteForceOnArmadilloAndPointsAwayFromItsTet) {
  const auto mesh = sinew::read_tetgen(fs::path(SINEW_DATA_DIR) / "meshes" / "tet" / "armadillo_4k");
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  // Brute force: count every face by its sorted key; remember the fourth vertex.
  std::map<Face, int> count;
  std::map<Face, std::uint32_t> opposite;
  for (const auto& t : mesh->tets) {
    for (std::size_t skip = 0; skip < 4; ++skip) {
      Face f{};
      std::size_t n = 0;
      for (std::size_t k = 0; k < 4; ++k) {
        if (k != skip) f[n++] = t[k];
      }
      const Face key = sorted(f);
      ++count[key];
      opposite[key] = t[skip];
    }
  }
  std::set<Face> expected;
  for (const auto& [key, c] : count) {
    if (c == 1) expected.insert(key);
  }
  const sinew::TriMesh surface = sinew::extract_boundary_surface(*mesh);
  std::set<Face> got;
  for (const Face& f : surface.triangles) {
    EXPECT_TRUE(got.insert(sorted(f)).second) << "triangle listed twice";
    const Vec3d& a = surface.vertices[f[0]];
    const Vec3d normal = cross(sub(surface.vertices[f[1]], a), sub(surface.vertices[f[2]], a));
    EXPECT_LT(dot(normal, sub(mesh->vertices[opposite[sorted(f)]], a)), 0.0) << "inward triangle";
  }
  EXPECT_EQ(got, expected);
  EXPECT_EQ(surface.vertices, mesh->vertices);  // shares indices with the tet mesh
}

TEST(BoundarySurface, FacesSharedByTwoTetsAreInterior) {
  // Two positive tets glued on face (1, 2, 3): 6 boundary faces, not 8.
  TetMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  m.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}};
  ASSERT_TRUE(sinew::check_tet_mesh(m).ok());
  const auto s = sinew::extract_boundary_surface(m);
  EXPECT_EQ(s.triangles.size(), 6u);
  for (const Face& f : s.triangles) EXPECT_NE(sorted(f), (Face{1, 2, 3}));
}

// ------------------------------------------------------------------ VTU

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t occurrences(std::string_view text, std::string_view what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string_view::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

struct GridData {
  TetMesh mesh;
  std::vector<float> xyz, temperature, velocity;
};

GridData grid_data() {
  sinew::TetGridDesc d;
  d.nx = 3;
  d.ny = 2;
  d.nz = 2;
  d.origin = {0.1, -1.0 / 3.0, 1e-5};
  d.cell_size = {1.0 / 3.0, 0.7, 1.0 / 7.0};
  d.split = sinew::TetsPerCell::five;
  GridData g;
  g.mesh = *sinew::make_tet_grid(d);
  for (const Vec3d& p : g.mesh.vertices) {
    for (double c : p) g.xyz.push_back(static_cast<float>(c));
    g.temperature.push_back(static_cast<float>(p[0] * p[1] + 1.0 / 3.0));
    for (double c : p) g.velocity.push_back(static_cast<float>(c * c * 1e-7 - 2.0 / 3.0));
  }
  return g;
}

TEST(Vtu, WritesPointsCellsAndFieldsThatReadBackExactly) {
  const GridData g = grid_data();
  const std::vector<sinew::VertexField> fields{{"temperature", 1, g.temperature},
                                               {"velocity", 3, g.velocity}};
  const fs::path p = tmp_dir() / "grid.vtu";
  const sinew::Status s = sinew::write_vtu(p, g.xyz, 3, g.mesh.tets, fields);
  ASSERT_TRUE(s.ok()) << s.error().message();
  const auto vtu = sinew::vtu_test::read_vtu(p);
  const std::string& xml = vtu.xml;
  EXPECT_EQ(xml.rfind("<?xml", 0), 0u);
  EXPECT_NE(xml.find("type=\"UnstructuredGrid\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfPoints=\"" + std::to_string(g.mesh.vertices.size()) + "\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfCells=\"" + std::to_string(g.mesh.tets.size()) + "\""), std::string::npos);
  EXPECT_EQ(occurrences(xml, "<DataArray"), 6u);  // 2 fields, points, 3 cell arrays

  // Floats must survive the text round trip bit for bit.
  EXPECT_EQ(vtu.positions.as<float>(), g.xyz);
  EXPECT_EQ(vtu.point_data.at("temperature").as<float>(), g.temperature);
  EXPECT_EQ(vtu.point_data.at("velocity").as<float>(), g.velocity);

  const auto connectivity = vtu.connectivity.as<std::int64_t>();
  ASSERT_EQ(connectivity.size(), 4 * g.mesh.tets.size());
  for (std::size_t t = 0; t < g.mesh.tets.size(); ++t) {
    for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(connectivity[4 * t + k], g.mesh.tets[t][k]);
  }
  const auto offsets = vtu.offsets.as<std::int64_t>();
  ASSERT_EQ(offsets.size(), g.mesh.tets.size());
  for (std::size_t t = 0; t < offsets.size(); ++t)
    EXPECT_EQ(offsets[t], static_cast<std::int64_t>(4 * (t + 1)));
  const auto types = vtu.types.as<int>();
  ASSERT_EQ(types.size(), g.mesh.tets.size());
  EXPECT_TRUE(std::all_of(types.begin(), types.end(), [](int t) { return t == 10; }));  // VTK_TETRA
}

// A thread or needle: line cells (VTK_LINE, 2 vertices each); a segment
// past the vertices is named.
TEST(Vtu, WritesLineCells) {
  const std::vector<float> xyzw{0.0f, 0.0f, 0.0f, 1.0f, 0.001f, 0.0f, 0.0f, 1.0f, 0.002f, 0.5f, 0.0f, 1.0f};
  const std::vector<std::array<std::uint32_t, 2>> segments{{0, 1}, {1, 2}};
  const fs::path p = tmp_dir() / "thread.vtu";
  const sinew::Status s = sinew::write_vtu_lines(p, xyzw, 4, segments);
  ASSERT_TRUE(s.ok()) << s.error().message();
  const auto vtu = sinew::vtu_test::read_vtu(p);
  const std::string& xml = vtu.xml;
  EXPECT_NE(xml.find("NumberOfPoints=\"3\" NumberOfCells=\"2\""), std::string::npos);
  EXPECT_EQ(vtu.positions.as<float>(),
            (std::vector<float>{0.0f, 0.0f, 0.0f, 0.001f, 0.0f, 0.0f, 0.002f, 0.5f, 0.0f}));
  EXPECT_EQ(vtu.connectivity.as<std::int64_t>(), (std::vector<std::int64_t>{0, 1, 1, 2}));
  EXPECT_EQ(vtu.offsets.as<std::int64_t>(), (std::vector<std::int64_t>{2, 4}));
  EXPECT_EQ(vtu.types.as<int>(), (std::vector<int>{3, 3}));  // VTK_LINE
  const std::vector<std::array<std::uint32_t, 2>> past{{0, 1}, {2, 3}};
  const sinew::Status bad = sinew::write_vtu_lines(p, xyzw, 4, past);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("segment 1 refers to vertex 3"), std::string::npos) << bad.error().message();
}

// A surface (a level set's, for display): triangle cells (VTK_TRIANGLE, 3
// vertices each) from 3-float positions; a triangle past the vertices is named.
TEST(Vtu, WritesTriangleCells) {
  const std::vector<float> xyz{0.0f, 0.0f, 0.0f, 0.001f, 0.0f, 0.0f, 0.0f, 0.001f, 0.0f, 0.0f, 0.0f, 0.001f};
  const std::vector<std::array<std::uint32_t, 3>> triangles{{0, 2, 1}, {0, 1, 3}};
  const fs::path p = tmp_dir() / "surface.vtu";
  const sinew::Status s = sinew::write_vtu_triangles(p, xyz, 3, triangles);
  ASSERT_TRUE(s.ok()) << s.error().message();
  const auto vtu = sinew::vtu_test::read_vtu(p);
  const std::string& xml = vtu.xml;
  EXPECT_NE(xml.find("NumberOfPoints=\"4\" NumberOfCells=\"2\""), std::string::npos);
  EXPECT_EQ(vtu.connectivity.as<std::int64_t>(),
            (std::vector<std::int64_t>{0, 2, 1, 0, 1, 3}));
  EXPECT_EQ(vtu.offsets.as<std::int64_t>(), (std::vector<std::int64_t>{3, 6}));
  EXPECT_EQ(vtu.types.as<int>(), (std::vector<int>{5, 5}));  // VTK_TRIANGLE
  const std::vector<std::array<std::uint32_t, 3>> past{{0, 1, 2}, {1, 2, 4}};
  const sinew::Status bad = sinew::write_vtu_triangles(p, xyz, 3, past);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message().find("triangle 1 refers to vertex 4"), std::string::npos) << bad.error().message();
}

// Particles: one vertex cell (VTK_VERTEX) each, with their fields; a field
// of the wrong size is named.
TEST(Vtu, WritesPointCellsWithFields) {
  const std::vector<float> xyz{0.0f, 0.0f, 0.0f, 0.001f, 0.0f, 0.0f, 0.0f, 0.002f, 0.0f};
  const std::vector<float> density{1000.0f, 1001.0f, 999.5f};
  const std::vector<float> velocity{0.0f, -1.0f, 0.0f, 0.5f, 0.0f, 0.0f, 0.0f, 0.0f, 0.25f};
  const sinew::VertexField fields[] = {{"density", 1, density}, {"velocity", 3, velocity}};
  const fs::path p = tmp_dir() / "particles.vtu";
  const sinew::Status s = sinew::write_vtu_points(p, xyz, 3, fields);
  ASSERT_TRUE(s.ok()) << s.error().message();
  const auto vtu = sinew::vtu_test::read_vtu(p);
  const std::string& xml = vtu.xml;
  EXPECT_NE(xml.find("NumberOfPoints=\"3\" NumberOfCells=\"3\""), std::string::npos);
  EXPECT_EQ(vtu.connectivity.as<std::int64_t>(), (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_EQ(vtu.types.as<int>(), (std::vector<int>{1, 1, 1}));  // VTK_VERTEX
  EXPECT_EQ(vtu.point_data.at("density").as<float>(), density);
  EXPECT_EQ(vtu.point_data.at("velocity").as<float>(), velocity);
  const std::vector<float> short_density{1000.0f};
  const sinew::VertexField bad[] = {{"density", 1, short_density}};
  const sinew::Status wrong = sinew::write_vtu_points(p, xyz, 3, bad);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().message().find("density"), std::string::npos) << wrong.error().message();
}

TEST(Vtu, StrideFourSkipsW) {
  const GridData g = grid_data();
  std::vector<float> xyzw;
  for (std::size_t i = 0; i < g.xyz.size(); i += 3) {
    xyzw.insert(xyzw.end(), {g.xyz[i], g.xyz[i + 1], g.xyz[i + 2], 12345.0f});
  }
  const fs::path p = tmp_dir() / "stride4.vtu";
  ASSERT_TRUE(sinew::write_vtu(p, xyzw, 4, g.mesh.tets).ok());
  const auto vtu = sinew::vtu_test::read_vtu(p);
  EXPECT_EQ(vtu.positions.as<float>(), g.xyz);
}

TEST(Vtu, CreatesParentFoldersAndEscapesNames) {
  const GridData g = grid_data();
  fs::remove_all(tmp_dir() / "made");
  const fs::path p = tmp_dir() / "made" / "on" / "demand.vtu";
  const std::vector<sinew::VertexField> fields{{"a<b & \"c\"", 1, g.temperature}};
  const sinew::Status s = sinew::write_vtu(p, g.xyz, 3, g.mesh.tets, fields);
  ASSERT_TRUE(s.ok()) << s.error().message();
  EXPECT_NE(read_text(p).find("Name=\"a&lt;b &amp; &quot;c&quot;\""), std::string::npos);
}

::testing::AssertionResult fails_naming(const sinew::Status& s, std::vector<std::string> fragments) {
  if (s.ok()) return ::testing::AssertionFailure() << "write succeeded";
  for (const std::string& f : fragments) {
    if (s.error().message().find(f) == std::string::npos) {
      return ::testing::AssertionFailure() << "'" << f << "' not in: " << s.error().message();
    }
  }
  return ::testing::AssertionSuccess();
}

TEST(Vtu, RejectsBadInputNamingTheProblem) {
  const GridData g = grid_data();
  const fs::path p = tmp_dir() / "bad.vtu";
  EXPECT_TRUE(fails_naming(sinew::write_vtu(p, g.xyz, 5, g.mesh.tets), {"bad.vtu", "stride"}));
  EXPECT_TRUE(fails_naming(sinew::write_vtu(p, g.xyz, 2, g.mesh.tets), {"bad.vtu", "stride"}));
  const std::span<const float> ragged(g.xyz.data(), g.xyz.size() - 1);
  EXPECT_TRUE(fails_naming(sinew::write_vtu(p, ragged, 3, g.mesh.tets), {"bad.vtu", "multiple"}));
  const std::vector<sinew::VertexField> two{{"pair", 2, g.temperature}};
  EXPECT_TRUE(
      fails_naming(sinew::write_vtu(p, g.xyz, 3, g.mesh.tets, two), {"bad.vtu", "'pair'", "components"}));
  const std::span<const float> short_values(g.velocity.data(), g.velocity.size() - 3);
  const std::vector<sinew::VertexField> short_field{{"velocity", 3, short_values}};
  EXPECT_TRUE(
      fails_naming(sinew::write_vtu(p, g.xyz, 3, g.mesh.tets, short_field), {"bad.vtu", "'velocity'"}));
  const std::vector<sinew::VertexField> vector_as_scalar{{"speed", 1, g.velocity}};
  EXPECT_TRUE(fails_naming(sinew::write_vtu(p, g.xyz, 3, g.mesh.tets, vector_as_scalar), {"'speed'"}));
  std::vector<std::array<std::uint32_t, 4>> tets = g.mesh.tets;
  tets.back()[2] = static_cast<std::uint32_t>(g.mesh.vertices.size());
  EXPECT_TRUE(fails_naming(sinew::write_vtu(p, g.xyz, 3, tets),
                           {"bad.vtu", "tet " + std::to_string(tets.size() - 1)}));
  // A folder where the file should go cannot be opened as a file.
  fs::create_directories(tmp_dir() / "a_folder.vtu");
  EXPECT_TRUE(
      fails_naming(sinew::write_vtu(tmp_dir() / "a_folder.vtu", g.xyz, 3, g.mesh.tets), {"a_folder.vtu"}));
  // A parent that is a file cannot be created.
  std::ofstream(tmp_dir() / "plain_file") << "x";
  EXPECT_TRUE(fails_naming(sinew::write_vtu(tmp_dir() / "plain_file" / "x.vtu", g.xyz, 3, g.mesh.tets),
                           {"plain_file"}));
}

TEST(Pvd, ListsFilesRelativeToItsFolderWithTimes) {
  const GridData g = grid_data();
  const fs::path dir = tmp_dir() / "series";
  fs::remove_all(dir);
  const std::vector<fs::path> files{dir / "frames" / "f0.vtu", dir / "frames" / "f1.vtu",
                                    tmp_dir() / "outside.vtu"};
  for (const fs::path& f : files) ASSERT_TRUE(sinew::write_vtu(f, g.xyz, 3, g.mesh.tets).ok());
  const std::vector<double> times{0.0, 1.0 / 60.0, 0.5};
  const sinew::Status s = sinew::write_pvd(dir / "run.pvd", files, times);
  ASSERT_TRUE(s.ok()) << s.error().message();
  const std::string xml = read_text(dir / "run.pvd");
  EXPECT_NE(xml.find("type=\"Collection\""), std::string::npos);
  EXPECT_NE(xml.find("file=\"frames/f0.vtu\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("file=\"frames/f1.vtu\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("file=\"../outside.vtu\""), std::string::npos) << xml;
  // Each listed file, resolved against the .pvd's folder, exists.
  std::vector<double> read_times;
  for (std::size_t at = xml.find("timestep=\""); at != std::string::npos;
       at = xml.find("timestep=\"", at + 1)) {
    const std::size_t begin = at + 10;
    double t = 0.0;
    std::from_chars(xml.data() + begin, xml.data() + xml.find('"', begin), t);
    read_times.push_back(t);
    const std::size_t file_at = xml.find("file=\"", at) + 6;
    EXPECT_TRUE(fs::exists(dir / xml.substr(file_at, xml.find('"', file_at) - file_at)));
  }
  EXPECT_EQ(read_times, times);
  EXPECT_TRUE(fails_naming(sinew::write_pvd(dir / "bad.pvd", files, std::vector<double>{0.0}), {"bad.pvd"}));
}

}  // namespace
