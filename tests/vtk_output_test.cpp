// vtk_output_test.cpp — the binary VTK output (sinew/vtk_output.h) read back
// by the tests' own reader (vtu_reader.h): the same points, cells and
// fields, bytes that repeat, errors that name the problem, and SceneOutput
// writing every body kind, collider shape, tool and needle of a scene.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sinew/scene_file.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"
#include "vtu_reader.h"

namespace {

namespace fs = std::filesystem;
using sinew::VtkCellType;

fs::path tmp_dir(const std::string& name) {
  const fs::path d = fs::path(SINEW_TEST_TMP_DIR) / "vtk_output" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Every cell type the writer uses, over more points than one zlib block
// holds (so the arrays have several blocks and a partial last one).
struct MixedGrid {
  std::vector<float> xyzw, temperature, flow, cell_value;
  std::vector<std::uint32_t> connectivity, offsets;
  std::vector<VtkCellType> types;
  MixedGrid() {
    const std::uint32_t n = 5000;
    for (std::uint32_t i = 0; i < n; ++i) {
      xyzw.insert(xyzw.end(), {std::sin(0.1f * i), 1e-3f * i, std::cos(0.37f * i) / 3.0f, 99.0f});
      temperature.push_back(36.6f + 1e-4f * i);
      flow.insert(flow.end(), {1.0f / (i + 1), -2.0f, 3e-7f * i});
    }
    const auto add = [&](VtkCellType type, std::initializer_list<std::uint32_t> points) {
      connectivity.insert(connectivity.end(), points);
      offsets.push_back(static_cast<std::uint32_t>(connectivity.size()));
      types.push_back(type);
      cell_value.push_back(static_cast<float>(types.size()) * 0.5f);
    };
    for (std::uint32_t i = 0; i + 4 < n; i += 4) add(VtkCellType::tetra, {i, i + 1, i + 2, i + 3});
    add(VtkCellType::triangle, {0, 5, 9});
    add(VtkCellType::empty, {});
    add(VtkCellType::line, {7, 8});
    add(VtkCellType::poly_line, {1, 2, 3, 4, 5});
    add(VtkCellType::vertex, {n - 1});
  }
  sinew::VtkGrid grid(std::span<const sinew::VertexField> point_fields,
                      std::span<const sinew::VertexField> cell_fields) const {
    return {.positions = xyzw, .stride = 4, .connectivity = connectivity, .offsets = offsets, .types = types,
            .point_fields = point_fields, .cell_fields = cell_fields};
  }
};

TEST(VtkOutput, GridReadsBackWithTheSamePointsCellsAndFields) {
  const MixedGrid m;
  const sinew::VertexField point_fields[] = {{"temperature", 1, m.temperature}, {"flow", 3, m.flow}};
  const sinew::VertexField cell_fields[] = {{"value", 1, m.cell_value}};
  const fs::path p = tmp_dir("grid") / "mixed.vtu";
  const sinew::Status s = sinew::write_vtu(p, m.grid(point_fields, cell_fields));
  ASSERT_TRUE(s.ok()) << s.error().message();
  const auto vtu = sinew::vtu_test::read_vtu(p);
  ASSERT_EQ(vtu.points, m.xyzw.size() / 4);
  ASSERT_EQ(vtu.cells, m.types.size());
  std::vector<float> xyz;
  for (std::size_t i = 0; i < m.xyzw.size(); i += 4) xyz.insert(xyz.end(), {m.xyzw[i], m.xyzw[i + 1], m.xyzw[i + 2]});
  EXPECT_EQ(vtu.positions.as<float>(), xyz);  // bit for bit; w skipped
  EXPECT_EQ(vtu.positions.components, 3);
  EXPECT_EQ(vtu.connectivity.as<std::uint32_t>(), m.connectivity);
  EXPECT_EQ(vtu.offsets.as<std::uint32_t>(), m.offsets);
  std::vector<int> types;
  for (VtkCellType t : m.types) types.push_back(static_cast<int>(t));
  EXPECT_EQ(vtu.types.as<int>(), types);
  EXPECT_EQ(vtu.point_data.at("temperature").as<float>(), m.temperature);
  EXPECT_EQ(vtu.point_data.at("flow").as<float>(), m.flow);
  EXPECT_EQ(vtu.point_data.at("flow").components, 3);
  EXPECT_EQ(vtu.cell_data.at("value").as<float>(), m.cell_value);
  // The same input gives the same bytes.
  const fs::path again = p.parent_path() / "again.vtu";
  ASSERT_TRUE(sinew::write_vtu(again, m.grid(point_fields, cell_fields)).ok());
  EXPECT_EQ(bytes_of(p), bytes_of(again));
}

::testing::AssertionResult fails_naming(const sinew::Status& s, const std::string& fragment) {
  if (s.ok()) return ::testing::AssertionFailure() << "write succeeded";
  if (s.error().message().find(fragment) == std::string::npos)
    return ::testing::AssertionFailure() << "'" << fragment << "' not in: " << s.error().message();
  return ::testing::AssertionSuccess();
}

TEST(VtkOutput, BadGridsAreRefusedNamingTheProblem) {
  MixedGrid m;
  const fs::path p = tmp_dir("bad") / "bad.vtu";
  m.types.pop_back();
  EXPECT_TRUE(fails_naming(sinew::write_vtu(p, m.grid({}, {})), "cell types"));
  m = MixedGrid();
  m.connectivity[3] = 5000;
  EXPECT_TRUE(fails_naming(sinew::write_vtu(p, m.grid({}, {})), "refers to point 5000"));
  m = MixedGrid();
  std::swap(m.offsets[0], m.offsets[1]);
  EXPECT_TRUE(fails_naming(sinew::write_vtu(p, m.grid({}, {})), "cell 1 ends"));
  m = MixedGrid();
  const sinew::VertexField short_cells[] = {{"value", 1, std::span<const float>(m.cell_value).first(3)}};
  EXPECT_TRUE(fails_naming(sinew::write_vtu(p, m.grid({}, short_cells)), "'value'"));
  EXPECT_FALSE(fs::exists(p));
  const sinew::VtkBlock unnamed[] = {{"", p}};
  EXPECT_TRUE(fails_naming(sinew::write_vtm(p.parent_path() / "x.vtm", unnamed), "empty name"));
}

// A scene with every body kind, every drawn collider shape, a tool and a
// needle: suturing's pad, thread and needle, plus a membrane, colliders and
// a capsule tool away from them.
sinew::SceneFile every_kind() {
  auto file = sinew::load_scene_file(fs::path(SINEW_SOURCE_DIR) / "scenes" / "suturing.json");
  EXPECT_TRUE(file) << file.error().message();
  sinew::SceneDesc& scene = file->scene;
  sinew::TriBodyDesc sheet;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) sheet.mesh.vertices.push_back({1.0 + 0.01 * i, 0.5, 0.01 * j});
  for (std::uint32_t j = 0; j < 2; ++j)
    for (std::uint32_t i = 0; i < 2; ++i) {
      const std::uint32_t a = 3 * j + i;
      sheet.mesh.triangles.push_back({a, a + 3, a + 1});
      sheet.mesh.triangles.push_back({a + 1, a + 3, a + 4});
    }
  sheet.pinned = {0, 2};
  scene.tri_bodies.push_back(sheet);
  for (sinew::ColliderShape shape : {sinew::ColliderShape::plane, sinew::ColliderShape::sphere,
                                     sinew::ColliderShape::capsule, sinew::ColliderShape::box,
                                     sinew::ColliderShape::cylinder}) {
    sinew::ColliderDesc c;
    c.shape = shape;
    c.radius = 0.01, c.half_height = 0.02, c.half_extents = {0.01, 0.01, 0.01};
    c.position = shape == sinew::ColliderShape::plane ? sinew::Vec3d{0.0, -1.0, 0.0}
                                                      : sinew::Vec3d{-1.0, 1.0, double(scene.colliders.size())};
    scene.colliders.push_back(c);
  }
  sinew::ToolDesc tool;
  tool.position = {2.0, 2.0, 2.0};
  tool.gravity = false;
  scene.tools.push_back(tool);
  return std::move(*file);
}

TEST(VtkOutput, SceneOutputWritesEveryBodyToolAndCollider) {
  const sinew::SceneFile file = every_kind();
  auto sim = sinew::Simulation::create(file.scene, {.backend = "cpu"});
  ASSERT_TRUE(sim) << sim.error().message();
  const fs::path dir = tmp_dir("scene");
  auto output = sinew::SceneOutput::create(file.scene, dir, {.bodies = file.bodies});
  ASSERT_TRUE(output) << output.error().message();
  ASSERT_TRUE(output->write(*sim, 0).ok());
  ASSERT_TRUE(sim->step().ok());
  output->add_polyline("blade", std::vector<std::array<double, 3>>{{0, 0, 0}, {0.01, 0, 0}});
  const sinew::Status s = output->write(*sim, 1);
  ASSERT_TRUE(s.ok()) << s.error().message();

  const std::string vtm = bytes_of(dir / "scene_1.vtm");
  for (const std::string block : {"pad", "thread", "tri0", "collider0", "collider1", "collider2", "collider3",
                                  "collider4", "tool0", "needle0", "blade"}) {
    EXPECT_NE(vtm.find("name=\"" + block + "\" file=\"" + block + "_1.vtu\""), std::string::npos) << block;
    EXPECT_TRUE(fs::exists(dir / (block + "_1.vtu"))) << block;
  }
  EXPECT_FALSE(fs::exists(dir / "blade_0.vtu"));  // added for frame 1 only
  const std::string pvd = bytes_of(dir / "scene.pvd");
  EXPECT_NE(pvd.find("file=\"scene_0.vtm\""), std::string::npos);
  EXPECT_NE(pvd.find("file=\"scene_1.vtm\""), std::string::npos);

  // The pad: the simulation's positions and velocities, the displacement
  // from the rest shape, a live flag and a strain per tet.
  std::vector<float> x, v;
  ASSERT_TRUE(sim->read_positions(x).ok());
  ASSERT_TRUE(sim->read_velocities(v).ok());
  const auto pad = sinew::vtu_test::read_vtu(dir / "pad_1.vtu");
  const sinew::TetMesh& mesh = file.scene.tet_bodies[0].mesh;
  const std::size_t first = sim->info().tet_body_first_particle[0];
  ASSERT_EQ(pad.points, mesh.vertices.size());
  ASSERT_EQ(pad.cells, mesh.tets.size());
  const auto xyz = pad.positions.as<float>();
  const auto displacement = pad.point_data.at("displacement").as<float>();
  const auto velocity = pad.point_data.at("velocity").as<float>();
  for (std::size_t p = 0; p < pad.points; ++p)
    for (std::size_t k = 0; k < 3; ++k) {
      ASSERT_EQ(xyz[3 * p + k], x[4 * (first + p) + k]);
      ASSERT_EQ(velocity[3 * p + k], v[4 * (first + p) + k]);
      ASSERT_NEAR(displacement[3 * p + k], x[4 * (first + p) + k] - mesh.vertices[p][k], 1e-7);
    }
  EXPECT_EQ(pad.cell_data.at("alive").as<float>(), std::vector<float>(mesh.tets.size(), 1.0f));
  EXPECT_EQ(pad.cell_data.at("green_strain").values.size(), mesh.tets.size());
  for (double e : pad.cell_data.at("green_strain").values) EXPECT_GE(e, 0.0);
  // The thread as lines, the membrane as triangles, the needle as one poly line.
  EXPECT_EQ(sinew::vtu_test::read_vtu(dir / "thread_1.vtu").types.values.front(), 3);
  EXPECT_EQ(sinew::vtu_test::read_vtu(dir / "tri0_1.vtu").cells, 8u);
  const auto needle = sinew::vtu_test::read_vtu(dir / "needle0_1.vtu");
  EXPECT_EQ(needle.cells, 1u);
  EXPECT_EQ(needle.types.values.front(), 4);
  EXPECT_EQ(needle.points, file.scene.needles[0].curve.size());
  EXPECT_TRUE(needle.point_data.count("contact_force"));
  const auto tool = sinew::vtu_test::read_vtu(dir / "tool0_1.vtu");
  EXPECT_GT(tool.cells, 0u);
  EXPECT_TRUE(tool.point_data.count("contact_force"));
  // Each collider where its pose puts it: the sphere's points at its radius.
  const auto sphere = sinew::vtu_test::read_vtu(dir / "collider1_1.vtu");
  const auto& c1 = file.scene.colliders[1];
  const auto sp = sphere.positions.as<double>();
  for (std::size_t p = 0; p < sphere.points; ++p) {
    const double d = std::hypot(sp[3 * p] - c1.position[0], sp[3 * p + 1] - c1.position[1], sp[3 * p + 2] - c1.position[2]);
    EXPECT_NEAR(d, c1.radius, 1e-6);
  }
}

TEST(VtkOutput, SceneOutputRefusesClashingNames) {
  const sinew::SceneFile file = every_kind();
  const fs::path dir = tmp_dir("names");
  auto clash = sinew::SceneOutput::create(file.scene, dir,
                                          {.bodies = {{.kind = sinew::BodyKind::tet, .name = "collider0"}}});
  ASSERT_FALSE(clash);
  EXPECT_NE(clash.error().message().find("collider0"), std::string::npos);
  auto twice = sinew::SceneOutput::create(
      file.scene, dir, {.bodies = {{.kind = sinew::BodyKind::tet, .name = "a"}, {.kind = sinew::BodyKind::line, .name = "a"}}});
  ASSERT_FALSE(twice);
  EXPECT_NE(twice.error().message().find("'a'"), std::string::npos);
  auto past = sinew::SceneOutput::create(file.scene, dir, {.bodies = {{.kind = sinew::BodyKind::tet, .index = 5, .name = "x"}}});
  ASSERT_FALSE(past);
  EXPECT_NE(past.error().message().find("tet5"), std::string::npos);
}

}  // namespace
