// read_tetgen / read_gmsh / read_vtk / read_tet_mesh on the real meshes in
// data/meshes/tet and on small files written here (Gmsh 2.2, 4.0
// and 4.1 with sparse shuffled tags and mixed element types; TetGen
// 1-based with attributes, markers and comments; 10-node tets; legacy VTK
// ASCII and big-endian BINARY, and malformed VTK files).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "mesh_test_helpers.h"
#include "sinew/mesh.h"

namespace {

namespace fs = std::filesystem;
using sinew::TetMesh;
using sinew::Vec3d;

const fs::path kTetDir = fs::path(SINEW_DATA_DIR) / "meshes" / "tet";

fs::path tmp_dir() { return sinew::mesh_test::tmp_dir("mesh_readers"); }

using sinew::mesh_test::cross;
using sinew::mesh_test::dot;
using sinew::mesh_test::signed_volume;
using sinew::mesh_test::sub;

double tet_volume_sum(const TetMesh& m) {
  double v = 0.0;
  for (const auto& t : m.tets) v += signed_volume(m, t);
  return v;
}

// Divergence theorem around the centroid of the surface's vertices, which
// keeps the terms small for meshes far from the origin.
double enclosed_volume(const sinew::TriMesh& s) {
  Vec3d c{0, 0, 0};
  for (const Vec3d& p : s.vertices) {
    for (std::size_t a = 0; a < 3; ++a) c[a] += p[a] / static_cast<double>(s.vertices.size());
  }
  double v = 0.0;
  for (const auto& t : s.triangles) {
    v += dot(sub(s.vertices[t[0]], c), cross(sub(s.vertices[t[1]], c), sub(s.vertices[t[2]], c))) / 6.0;
  }
  return v;
}

// Every undirected edge in exactly two triangles, traversed once each way.
::testing::AssertionResult closed_and_consistent(const sinew::TriMesh& s) {
  std::unordered_map<std::uint64_t, int> directed;
  auto key = [](std::uint32_t a, std::uint32_t b) { return (std::uint64_t{a} << 32) | b; };
  for (const auto& t : s.triangles) {
    for (std::size_t e = 0; e < 3; ++e) ++directed[key(t[e], t[(e + 1) % 3])];
  }
  for (const auto& [k, count] : directed) {
    const auto a = static_cast<std::uint32_t>(k >> 32), b = static_cast<std::uint32_t>(k);
    const auto reverse = directed.find(key(b, a));
    if (count != 1 || reverse == directed.end() || reverse->second != 1) {
      return ::testing::AssertionFailure()
             << "boundary edge " << a << "-" << b << " is not shared by exactly two "
             << "consistently wound triangles";
    }
  }
  return ::testing::AssertionSuccess();
}

// The facts every real mesh must satisfy; returns the tet volume sum.
double expect_sound(const TetMesh& m, const std::string& name) {
  EXPECT_TRUE(sinew::check_tet_mesh(m, name).ok());
  const sinew::TriMesh surface = sinew::extract_boundary_surface(m);
  EXPECT_FALSE(surface.triangles.empty()) << name;
  EXPECT_TRUE(closed_and_consistent(surface)) << name;
  const double volume = tet_volume_sum(m);
  EXPECT_GT(volume, 0.0) << name;
  EXPECT_NEAR(enclosed_volume(surface), volume, 1e-6 * volume) << name;
  return volume;
}

template <class F>
double seconds(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(MeshReaders, Armadillo4kTetGen) {
  const auto mesh = sinew::read_tetgen(kTetDir / "armadillo_4k.node");
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  EXPECT_EQ(mesh->vertices.size(), 1180u);  // .node header
  EXPECT_EQ(mesh->tets.size(), 3717u);      // .ele header
  expect_sound(*mesh, "armadillo_4k");

  // The stem, the .ele path and read_tet_mesh name the same mesh.
  for (const fs::path& p : {kTetDir / "armadillo_4k", kTetDir / "armadillo_4k.ele"}) {
    const auto direct = sinew::read_tetgen(p);
    ASSERT_TRUE(direct.ok()) << direct.error().message();
    EXPECT_EQ(direct->tets, mesh->tets);
    EXPECT_EQ(direct->vertices, mesh->vertices);
  }
  const auto dispatched = sinew::read_tet_mesh(kTetDir / "armadillo_4k.ele");
  ASSERT_TRUE(dispatched.ok()) << dispatched.error().message();
  EXPECT_EQ(dispatched->tets, mesh->tets);
}

TEST(MeshReaders, Armadillo13kGmsh41) {
  sinew::Result<TetMesh> mesh = sinew::Error(sinew::ErrorCode::internal, "not read");
  const double t = seconds([&] { mesh = sinew::read_tet_mesh(kTetDir / "Armadillo13K.msh"); });
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  std::cout << "[ timing   ] Armadillo13K.msh read in " << t * 1e3 << " ms\n";
  RecordProperty("read_ms", std::to_string(t * 1e3));
  EXPECT_EQ(mesh->tets.size(), 54985u);      // README and $Elements header
  EXPECT_LE(mesh->vertices.size(), 13230u);  // $Nodes header; unused nodes are dropped
  std::vector<char> used(mesh->vertices.size(), 0);
  for (const auto& tet : mesh->tets) {
    for (std::uint32_t v : tet) used[v] = 1;
  }
  EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](char u) { return u != 0; }));
  expect_sound(*mesh, "Armadillo13K");
}

TEST(MeshReaders, Kidney57kIsAKidneySizedOrganInMillimetres) {
  auto mesh = sinew::read_tetgen(kTetDir / "kidney_57k");
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  EXPECT_EQ(mesh->vertices.size(), 14147u);  // .node header
  EXPECT_EQ(mesh->tets.size(), 57071u);      // README and .ele header
  expect_sound(*mesh, "kidney_57k");
  sinew::scale_mesh(*mesh, 1e-3);
  // An adult kidney holds roughly 100-300 ml; the file is in mm.
  const double litres = tet_volume_sum(*mesh) * 1e3;
  EXPECT_GT(litres, 0.05);
  EXPECT_LT(litres, 0.4);
}

// A graded mesh: its smallest tets (1.2e-5 mm^3) are tiny next to the organ
// but well shaped (volume / longest edge^3 >= 5e-4), so they pass the
// per-tet flatness test of check_tet_mesh.
TEST(MeshReaders, Liver382kIsALiverSizedOrganInMillimetres) {
  sinew::Result<TetMesh> mesh = sinew::Error(sinew::ErrorCode::internal, "not read");
  const double t = seconds([&] { mesh = sinew::read_tetgen(kTetDir / "liver_382k.node"); });
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  std::cout << "[ timing   ] liver_382k read in " << t * 1e3 << " ms\n";
  RecordProperty("read_ms", std::to_string(t * 1e3));
  EXPECT_EQ(mesh->vertices.size(), 88066u);  // .node header
  EXPECT_EQ(mesh->tets.size(), 382510u);     // README and .ele header
  expect_sound(*mesh, "liver_382k");
  sinew::scale_mesh(*mesh, 1e-3);
  // An adult liver is about 1-2.5 litres.
  const double litres = tet_volume_sum(*mesh) * 1e3;
  EXPECT_GT(litres, 0.6);
  EXPECT_LT(litres, 3.0);
}

// ------------------------------------------------------------ round trips

sinew::TetMesh small_grid(sinew::TetsPerCell split) {
  sinew::TetGridDesc d;
  d.nx = 3;
  d.ny = 2;
  d.nz = 2;
  d.origin = {0.1, -2.0 / 3.0, 1e-3};
  d.cell_size = {1.0 / 3.0, 0.7, 0.01};
  d.split = split;
  auto mesh = sinew::make_tet_grid(d);
  EXPECT_TRUE(mesh.ok());
  return *mesh;
}

std::string exact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string xyz(const Vec3d& p) { return exact(p[0]) + " " + exact(p[1]) + " " + exact(p[2]); }

// Sparse, shuffled node tags plus extra nodes that no tet uses.
struct TaggedMesh {
  const TetMesh* mesh = nullptr;
  std::vector<std::uint64_t> tag;  // per vertex
  std::vector<Vec3d> extra;        // unused nodes
  std::vector<std::uint64_t> extra_tag;
  std::vector<std::size_t> order;  // the order nodes are written in
};

TaggedMesh tag_nodes(const TetMesh& m, std::uint64_t stride, std::uint64_t extra_base) {
  TaggedMesh t;
  t.mesh = &m;
  std::vector<std::uint64_t> perm(m.vertices.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::mt19937 rng(1234);
  std::shuffle(perm.begin(), perm.end(), rng);
  for (std::size_t v = 0; v < m.vertices.size(); ++v) t.tag.push_back(7 + stride * perm[v]);
  t.extra = {{9.0, 9.0, 9.0}, {-9.0, 1.0, 2.0}, {0.5, 0.5, 40.0}};
  t.extra_tag = {extra_base, extra_base + 17, extra_base + 5};
  t.order.resize(m.vertices.size());
  std::iota(t.order.begin(), t.order.end(), 0);
  std::shuffle(t.order.begin(), t.order.end(), rng);
  return t;
}

std::string tet_tags(const TaggedMesh& t, std::size_t tet) {
  const auto& q = t.mesh->tets[tet];
  return std::to_string(t.tag[q[0]]) + " " + std::to_string(t.tag[q[1]]) + " " + std::to_string(t.tag[q[2]]) +
         " " + std::to_string(t.tag[q[3]]);
}

std::string tri_tags(const TaggedMesh& t, std::size_t tet) {
  const auto& q = t.mesh->tets[tet];
  return std::to_string(t.tag[q[0]]) + " " + std::to_string(t.tag[q[2]]) + " " + std::to_string(t.tag[q[1]]);
}

// Gmsh 4.1 or 4.0: three node blocks (unused points; a parametric surface
// block; a volume block) and element blocks mixing points, triangles and tets.
std::string gmsh4(const TaggedMesh& t, bool v41) {
  const TetMesh& m = *t.mesh;
  const std::size_t half = t.order.size() / 2, tets_half = m.tets.size() / 2;
  std::ostringstream s;
  s << "$MeshFormat\n" << (v41 ? "4.1" : "4.0") << " 0 8\n$EndMeshFormat\n";
  s << "$Entities\n1 0 1 1\n1 0 0 0 0\n2 0 0 0 1 1 1 0 0\n3 0 0 0 1 1 1 0 0\n$EndEntities\n";
  const std::size_t total = t.order.size() + t.extra.size();
  s << "$Nodes\n3 " << total;
  if (v41) s << " 1 " << t.extra_tag[1];
  s << "\n";
  auto block = [&](int dim, int parametric, const std::vector<std::uint64_t>& tags,
                   const std::vector<Vec3d>& pos) {
    s << (v41 ? dim : 1) << " " << (v41 ? 1 : dim) << " " << parametric << " " << tags.size() << "\n";
    auto coords = [&](std::size_t i) {
      s << xyz(pos[i]);
      for (int k = 0; k < dim * parametric; ++k) s << " 0.25";
      s << "\n";
    };
    if (v41) {
      for (std::uint64_t tag : tags) s << tag << "\n";
      for (std::size_t i = 0; i < pos.size(); ++i) coords(i);
    } else {
      for (std::size_t i = 0; i < pos.size(); ++i) {
        s << tags[i] << " ";
        coords(i);
      }
    }
  };
  block(0, 0, t.extra_tag, t.extra);
  std::vector<std::uint64_t> tags_a, tags_b;
  std::vector<Vec3d> pos_a, pos_b;
  for (std::size_t i = 0; i < t.order.size(); ++i) {
    (i < half ? tags_a : tags_b).push_back(t.tag[t.order[i]]);
    (i < half ? pos_a : pos_b).push_back(m.vertices[t.order[i]]);
  }
  block(2, 1, tags_a, pos_a);
  block(3, 0, tags_b, pos_b);
  s << "$EndNodes\n$Elements\n";
  const std::size_t elements = 2 + m.tets.size() + 3;
  s << "4 " << elements;
  if (v41) s << " 1 " << elements;
  s << "\n";
  std::size_t tag = 1;
  auto header = [&](int dim, int type, std::size_t n) {
    s << (v41 ? dim : 1) << " " << (v41 ? 1 : dim) << " " << type << " " << n << "\n";
  };
  header(0, 15, 2);
  s << tag++ << " " << t.extra_tag[0] << "\n";
  s << tag++ << " " << t.tag[0] << "\n";
  header(3, 4, tets_half);
  for (std::size_t i = 0; i < tets_half; ++i) s << tag++ << " " << tet_tags(t, i) << "\n";
  header(2, 2, 3);
  for (std::size_t i = 0; i < 3; ++i) s << tag++ << " " << tri_tags(t, i) << "\n";
  header(3, 4, m.tets.size() - tets_half);
  for (std::size_t i = tets_half; i < m.tets.size(); ++i) s << tag++ << " " << tet_tags(t, i) << "\n";
  s << "$EndElements\n";
  return s.str();
}

// Gmsh 2.2 with $PhysicalNames and elements of several types interleaved.
std::string gmsh2(const TaggedMesh& t) {
  const TetMesh& m = *t.mesh;
  std::ostringstream s;
  s << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  s << "$PhysicalNames\n2\n2 5 \"skin\"\n3 6 \"tissue $Nodes\"\n$EndPhysicalNames\n";
  s << "$Nodes\n" << t.order.size() + t.extra.size() << "\n";
  for (std::size_t i = 0; i < t.extra.size(); ++i) s << t.extra_tag[i] << " " << xyz(t.extra[i]) << "\n";
  for (std::size_t v : t.order) s << t.tag[v] << " " << xyz(m.vertices[v]) << "\n";
  s << "$EndNodes\n$Elements\n" << m.tets.size() + 4 << "\n";
  std::size_t tag = 100;
  s << tag++ << " 15 2 0 1 " << t.extra_tag[2] << "\n";
  for (std::size_t i = 0; i < m.tets.size(); ++i) {
    if (i == 1) s << tag++ << " 2 2 5 2 " << tri_tags(t, 0) << "\n";
    if (i == 2)
      s << tag++ << " 1 3 0 2 -1 " << t.tag[0] << " " << t.tag[1] << "\n";  // line, ghost partition tag
    s << tag++ << " 4 2 6 3 " << tet_tags(t, i) << "\n";
  }
  s << tag++ << " 2 2 5 2 " << tri_tags(t, 3) << "\n";
  s << "$EndElements\n$NodeData\n1\n\"T\"\n1\n0.0\n3\n0\n1\n1\n" << t.tag[0] << " 1.5\n$EndNodeData\n";
  return s.str();
}

void write_file(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

// Same tets, in the same order, over the same positions (indices may differ).
void expect_same_geometry(const TetMesh& read, const TetMesh& original) {
  ASSERT_EQ(read.tets.size(), original.tets.size());
  ASSERT_EQ(read.vertices.size(), original.vertices.size());  // unused nodes dropped
  std::vector<std::int64_t> to_original(read.vertices.size(), -1);
  for (std::size_t t = 0; t < read.tets.size(); ++t) {
    for (std::size_t k = 0; k < 4; ++k) {
      const std::uint32_t r = read.tets[t][k], o = original.tets[t][k];
      ASSERT_EQ(read.vertices[r], original.vertices[o]) << "tet " << t << " corner " << k;
      // The renumbering must be a bijection, not just position-equal.
      if (to_original[r] < 0) to_original[r] = o;
      ASSERT_EQ(to_original[r], static_cast<std::int64_t>(o));
    }
  }
}

TEST(MeshReaders, Gmsh41RoundTripWithSparseTagsAndMixedElements) {
  const TetMesh grid = small_grid(sinew::TetsPerCell::five);
  const TaggedMesh tagged = tag_nodes(grid, 1000, 5'000'000'000ull);  // very sparse: sorted lookup
  const fs::path p = tmp_dir() / "grid_v41.msh";
  write_file(p, gmsh4(tagged, true));
  const auto mesh = sinew::read_gmsh(p);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  expect_same_geometry(*mesh, grid);
}

TEST(MeshReaders, Gmsh40RoundTrip) {
  const TetMesh grid = small_grid(sinew::TetsPerCell::six);
  const TaggedMesh tagged = tag_nodes(grid, 2, 1000);  // dense enough for the direct table
  const fs::path p = tmp_dir() / "grid_v40.msh";
  write_file(p, gmsh4(tagged, false));
  const auto mesh = sinew::read_tet_mesh(p);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  expect_same_geometry(*mesh, grid);
}

TEST(MeshReaders, Gmsh22RoundTrip) {
  const TetMesh grid = small_grid(sinew::TetsPerCell::five);
  const TaggedMesh tagged = tag_nodes(grid, 3, 900);
  const fs::path p = tmp_dir() / "grid_v22.msh";
  write_file(p, gmsh2(tagged));
  const auto mesh = sinew::read_gmsh(p);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  expect_same_geometry(*mesh, grid);
}

// 1-based TetGen files with attributes, boundary markers, comments, blank
// lines and CRLF line ends.
TEST(MeshReaders, TetGenOneBasedRoundTrip) {
  const TetMesh grid = small_grid(sinew::TetsPerCell::six);
  const fs::path stem = tmp_dir() / "grid_1based";
  std::ostringstream node, ele;
  node << "# written by mesh_readers_test\n" << grid.vertices.size() << "  3  1  1\r\n\n";
  for (std::size_t v = 0; v < grid.vertices.size(); ++v) {
    node << "  " << v + 1 << "  " << xyz(grid.vertices[v]) << "  " << 0.5 * static_cast<double>(v) << "  "
         << v % 2 << "   # node\r\n";
  }
  node << "# end\n";
  ele << grid.tets.size() << " 4 1\n";
  for (std::size_t t = 0; t < grid.tets.size(); ++t) {
    const auto& q = grid.tets[t];
    ele << t + 1 << "\t" << q[0] + 1 << " " << q[1] + 1 << " " << q[2] + 1 << " " << q[3] + 1 << " -2\n";
  }
  write_file(fs::path(stem.string() + ".node"), node.str());
  write_file(fs::path(stem.string() + ".ele"), ele.str());
  const auto mesh = sinew::read_tetgen(stem);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  EXPECT_EQ(mesh->vertices, grid.vertices);
  EXPECT_EQ(mesh->tets, grid.tets);
}

// 10-node tets: the corners are the first four nodes; the edge nodes stay
// in the vertex array so indices match the file.
TEST(MeshReaders, TetGenTenNodeTetsKeepCorners) {
  const TetMesh grid = small_grid(sinew::TetsPerCell::five);
  std::vector<Vec3d> nodes = grid.vertices;
  std::ostringstream ele;
  ele << grid.tets.size() << " 10 0\n";
  for (std::size_t t = 0; t < grid.tets.size(); ++t) {
    const auto& q = grid.tets[t];
    ele << t << " " << q[0] << " " << q[1] << " " << q[2] << " " << q[3];
    for (int e = 0; e < 6; ++e) {
      static constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}};
      const Vec3d& a = grid.vertices[q[static_cast<std::size_t>(kEdge[e][0])]];
      const Vec3d& b = grid.vertices[q[static_cast<std::size_t>(kEdge[e][1])]];
      ele << " " << nodes.size();
      nodes.push_back({(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
    }
    ele << "\n";
  }
  std::ostringstream node;
  node << nodes.size() << " 3 0 0\n";
  for (std::size_t v = 0; v < nodes.size(); ++v) node << v << " " << xyz(nodes[v]) << "\n";
  const fs::path stem = tmp_dir() / "grid_tet10";
  write_file(fs::path(stem.string() + ".node"), node.str());
  write_file(fs::path(stem.string() + ".ele"), ele.str());
  const auto mesh = sinew::read_tet_mesh(fs::path(stem.string() + ".node"));
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  EXPECT_EQ(mesh->tets, grid.tets);
  EXPECT_EQ(mesh->vertices, nodes);
  EXPECT_NEAR(tet_volume_sum(*mesh), tet_volume_sum(grid), 1e-12);
}

// ------------------------------------------------------------ legacy VTK

// meshio's export of a gallbladder: BINARY, 367 float points, 2,519 cells
// (1,063 tets, 1,456 surface triangles), POINT_DATA and CELL_DATA fields.
// Point 314, the file's largest x (-1.102), is in no cell at all and is
// dropped, so the mesh's box ends at x = -3.677.
TEST(VtkReader, GallbladderBinaryFromMeshio) {
  const fs::path path = kTetDir / "gallbladder_volumetric.vtk";
  const auto mesh = sinew::read_tet_mesh(path);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  EXPECT_EQ(mesh->tets.size(), 1063u);
  EXPECT_EQ(mesh->vertices.size(), 366u);  // one of the 367 points is in no tet
  EXPECT_TRUE(sinew::check_tet_mesh(*mesh, "gallbladder").ok());
  expect_sound(*mesh, "gallbladder");
  Vec3d lo = mesh->vertices[0], hi = mesh->vertices[0];
  for (const Vec3d& p : mesh->vertices) {
    for (std::size_t a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  // Millimetres, as in the file.
  EXPECT_NEAR(lo[0], -83.505, 0.01);
  EXPECT_NEAR(hi[0], -3.677, 0.01);
  EXPECT_NEAR(lo[1], -22.385, 0.01);
  EXPECT_NEAR(hi[1], 29.292, 0.01);
  EXPECT_NEAR(lo[2], -47.515, 0.01);
  EXPECT_NEAR(hi[2], 0.659, 0.01);
  const auto direct = sinew::read_vtk(path);
  ASSERT_TRUE(direct.ok()) << direct.error().message();
  EXPECT_EQ(direct->tets, mesh->tets);
  EXPECT_EQ(direct->vertices, mesh->vertices);
}

// The parts of a small unstructured grid: two tets sharing the face 1 2 3,
// a triangle between them and point 4, which no cell uses.
struct VtkParts {
  std::string dataset = "UNSTRUCTURED_GRID";
  std::vector<Vec3d> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {9, 9, 9}, {1, 1, 1}};
  std::vector<std::vector<std::int32_t>> cells = {{0, 1, 2, 3}, {0, 1, 2}, {1, 2, 3, 5}};
  std::vector<std::int32_t> types = {10, 5, 10};
  std::int64_t cells_size = -1;  // CELLS size: -1 for the right one
};

std::int64_t cells_size(const VtkParts& v) {
  if (v.cells_size >= 0) return v.cells_size;
  std::int64_t size = 0;
  for (const auto& c : v.cells) size += 1 + static_cast<std::int64_t>(c.size());
  return size;
}

std::string vtk_ascii(const VtkParts& v) {
  std::ostringstream s;
  s << "# vtk DataFile Version 4.2\nsmall test mesh\nASCII\nDATASET " << v.dataset << "\n";
  s << "POINTS " << v.points.size() << " double\n";
  for (const Vec3d& p : v.points) s << xyz(p) << "\n";
  s << "\nCELLS " << v.cells.size() << " " << cells_size(v) << "\n";
  for (const auto& c : v.cells) {
    s << c.size();
    for (std::int32_t i : c) s << " " << i;
    s << "\n";
  }
  s << "CELL_TYPES " << v.types.size() << "\n";
  for (std::int32_t t : v.types) s << t << "\n";
  s << "CELL_DATA " << v.types.size() << "\nSCALARS id int 1\nLOOKUP_TABLE default\n";
  for (std::size_t i = 0; i < v.types.size(); ++i) s << i << "\n";
  return s.str();
}

void put_big_endian(std::string& s, std::uint64_t bits, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) s.push_back(static_cast<char>((bits >> (8 * i)) & 0xffu));
}

void put_int32(std::string& s, std::int32_t v) { put_big_endian(s, std::bit_cast<std::uint32_t>(v), 4); }

// As meshio writes it: big-endian blocks, each followed by a '\n'.
std::string vtk_binary(const VtkParts& v, bool doubles) {
  std::string s = "# vtk DataFile Version 4.2\nsmall test mesh\nBINARY\nDATASET " + v.dataset + "\n";
  s += "POINTS " + std::to_string(v.points.size()) + (doubles ? " double\n" : " float\n");
  for (const Vec3d& p : v.points) {
    for (double x : p) {
      if (doubles) {
        put_big_endian(s, std::bit_cast<std::uint64_t>(x), 8);
      } else {
        put_big_endian(s, std::bit_cast<std::uint32_t>(static_cast<float>(x)), 4);
      }
    }
  }
  s += "\nCELLS " + std::to_string(v.cells.size()) + " " + std::to_string(cells_size(v)) + "\n";
  for (const auto& c : v.cells) {
    put_int32(s, static_cast<std::int32_t>(c.size()));
    for (std::int32_t i : c) put_int32(s, i);
  }
  s += "\nCELL_TYPES " + std::to_string(v.types.size()) + "\n";
  for (std::int32_t t : v.types) put_int32(s, t);
  s += "\nCELL_DATA " + std::to_string(v.types.size()) + "\nFIELD FieldData 1\nid 1 " +
       std::to_string(v.types.size()) + " int\n";
  for (std::size_t i = 0; i < v.types.size(); ++i) put_int32(s, static_cast<std::int32_t>(i));
  return s + "\n";
}

// Two tets, the triangle dropped, point 4 dropped and 5 renumbered to 4.
void expect_two_tets(const TetMesh& m) {
  const std::vector<Vec3d> vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  const std::vector<std::array<std::uint32_t, 4>> tets = {{0, 1, 2, 3}, {1, 2, 3, 4}};
  EXPECT_EQ(m.vertices, vertices);
  EXPECT_EQ(m.tets, tets);
  EXPECT_TRUE(sinew::check_tet_mesh(m, "two tets").ok());
}

TEST(VtkReader, AsciiKeepsTetsDropsOtherCellsAndUnusedPoints) {
  const fs::path p = tmp_dir() / "two_tets_ascii.vtk";
  write_file(p, vtk_ascii(VtkParts{}));
  const auto mesh = sinew::read_vtk(p);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  expect_two_tets(*mesh);
}

TEST(VtkReader, BinaryBigEndianReadsLikeAscii) {
  for (bool doubles : {false, true}) {
    const fs::path p = tmp_dir() / (doubles ? "two_tets_binary_double.vtk" : "two_tets_binary_float.vtk");
    write_file(p, vtk_binary(VtkParts{}, doubles));
    const auto mesh = sinew::read_tet_mesh(p);
    ASSERT_TRUE(mesh.ok()) << mesh.error().message();
    expect_two_tets(*mesh);
  }
}

// Reads `content` as `name` and expects an error naming the file and
// holding `what`.
void expect_vtk_error(const std::string& name, const std::string& content, const std::string& what) {
  const fs::path p = tmp_dir() / name;
  write_file(p, content);
  const auto mesh = sinew::read_vtk(p);
  ASSERT_FALSE(mesh.ok()) << name << " was read";
  const std::string& message = mesh.error().message();
  EXPECT_EQ(mesh.error().code(), sinew::ErrorCode::bad_input_file) << message;
  EXPECT_NE(message.find(p.string()), std::string::npos) << message;
  EXPECT_NE(message.find(what), std::string::npos) << "expected '" << what << "' in: " << message;
}

TEST(VtkReader, MalformedFilesNameTheProblem) {
  const std::string binary = vtk_binary(VtkParts{}, false);
  const std::size_t points_data = binary.find("float\n") + 6;
  expect_vtk_error("truncated_points.vtk", binary.substr(0, points_data + 10), "POINTS: binary data truncated");
  expect_vtk_error("truncated_cells.vtk", binary.substr(0, binary.find("\nCELLS") + 30),
                   "CELLS: binary data truncated");

  VtkParts types_mismatch;
  types_mismatch.types.pop_back();
  expect_vtk_error("types_mismatch.vtk", vtk_ascii(types_mismatch),
                   "CELL_TYPES holds 2 cell types, but CELLS");

  VtkParts wrong_size;  // the cells take 14 values
  wrong_size.cells_size = 15;
  expect_vtk_error("size_too_large.vtk", vtk_binary(wrong_size, false),
                   "CELLS: its size is 15, but its 3 cells take 14");
  expect_vtk_error("size_too_large_ascii.vtk", vtk_ascii(wrong_size),
                   "CELLS: expected value 15 of 15, found 'CELL_TYPES' (fewer values than its header announces)");
  wrong_size.cells_size = 13;
  expect_vtk_error("size_too_small.vtk", vtk_ascii(wrong_size), "cell 2 has 4 points, which run past its size 13");

  VtkParts out_of_range;
  out_of_range.cells[2][3] = 6;
  expect_vtk_error("out_of_range.vtk", vtk_ascii(out_of_range),
                   "cell 2 refers to point 6, but POINTS holds 6 points");
  VtkParts negative = out_of_range;
  negative.cells[2][3] = -1;
  expect_vtk_error("negative_index.vtk", vtk_binary(negative, true), "cell 2 refers to point -1");

  VtkParts three_point_tet;
  three_point_tet.types[1] = 10;
  expect_vtk_error("three_point_tet.vtk", vtk_ascii(three_point_tet),
                   "cell 1 has type 10 (VTK_TETRA) but 3 points, not 4");

  VtkParts no_tets;
  no_tets.cells = {{0, 1, 2}};
  no_tets.types = {5};
  expect_vtk_error("no_tets.vtk", vtk_ascii(no_tets), "no tetrahedra");

  VtkParts polydata;
  polydata.dataset = "POLYDATA";
  expect_vtk_error("polydata.vtk", vtk_ascii(polydata), "the dataset is 'POLYDATA'");

  VtkParts inverted;
  inverted.cells[2] = {1, 3, 2, 5};
  expect_vtk_error("inverted.vtk", vtk_ascii(inverted), "is inverted");

  std::string nan = vtk_ascii(VtkParts{});
  nan.replace(nan.find("\n9 9 9\n") + 1, 1, "nan");
  expect_vtk_error("nan.vtk", nan, "non-finite coordinate 'nan'");

  const std::string ascii = vtk_ascii(VtkParts{});
  expect_vtk_error("no_cell_types.vtk", ascii.substr(0, ascii.find("CELL_TYPES")), "without a CELL_TYPES section");
  expect_vtk_error("not_vtk.vtk", "solid cube\n", "not a legacy VTK file");
  expect_vtk_error("empty.vtk", "", "not a legacy VTK file");
}

TEST(VtkReader, MissingFile) {
  const fs::path p = tmp_dir() / "no_such_mesh.vtk";
  const auto mesh = sinew::read_tet_mesh(p);
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.error().code(), sinew::ErrorCode::bad_input_file);
  EXPECT_NE(mesh.error().message().find(p.string()), std::string::npos) << mesh.error().message();
  EXPECT_NE(mesh.error().message().find("does not exist"), std::string::npos) << mesh.error().message();
}

}  // namespace
