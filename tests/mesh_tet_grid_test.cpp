// make_tet_grid: counts, orientation, volume, conformity and a closed,
// outward-wound boundary surface for both cell splits; bad parameters.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "mesh_test_helpers.h"
#include "sinew/mesh.h"

namespace {

using sinew::TetGridDesc;
using sinew::TetMesh;
using sinew::TetsPerCell;
using sinew::Vec3d;
using Face = std::array<std::uint32_t, 3>;

using sinew::mesh_test::cross;
using sinew::mesh_test::dot;
using sinew::mesh_test::sub;
using sinew::mesh_test::signed_volume;

// Volume enclosed by a closed triangle surface (divergence theorem); positive
// only when the triangles wind counter-clockwise seen from outside.
double enclosed_volume(const sinew::TriMesh& s) {
  double v = 0.0;
  for (const auto& t : s.triangles)
    v += dot(s.vertices[t[0]], cross(s.vertices[t[1]], s.vertices[t[2]])) / 6.0;
  return v;
}

// Closed and consistently wound: every directed edge occurs once and its
// reverse occurs once, so every undirected edge is in exactly two triangles.
::testing::AssertionResult closed_and_consistent(const sinew::TriMesh& s) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : s.triangles) {
    for (int e = 0; e < 3; ++e)
      ++directed[{t[static_cast<std::size_t>(e)], t[static_cast<std::size_t>((e + 1) % 3)]}];
  }
  for (const auto& [edge, count] : directed) {
    const auto reverse = directed.find({edge.second, edge.first});
    if (count != 1 || reverse == directed.end() || reverse->second != 1) {
      return ::testing::AssertionFailure() << "edge " << edge.first << "-" << edge.second << " used " << count
                                           << " times in this direction";
    }
  }
  return ::testing::AssertionSuccess();
}

Face sorted_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  Face f{a, b, c};
  std::sort(f.begin(), f.end());
  return f;
}

std::map<Face, int> face_use(const TetMesh& m) {
  std::map<Face, int> use;
  for (const auto& t : m.tets) {
    ++use[sorted_face(t[0], t[1], t[2])];
    ++use[sorted_face(t[0], t[1], t[3])];
    ++use[sorted_face(t[0], t[2], t[3])];
    ++use[sorted_face(t[1], t[2], t[3])];
  }
  return use;
}

// True when all three vertices lie on one face plane of the grid's box.
bool on_box_boundary(const TetMesh& m, const Face& f, const TetGridDesc& d) {
  for (std::size_t a = 0; a < 3; ++a) {
    const double lo = d.origin[a];
    const double hi = d.origin[a] + (a == 0 ? d.nx : a == 1 ? d.ny : d.nz) * d.cell_size[a];
    for (double plane : {lo, hi}) {
      if (std::all_of(f.begin(), f.end(), [&](std::uint32_t v) { return m.vertices[v][a] == plane; }))
        return true;
    }
  }
  return false;
}

TetGridDesc desc(int nx, int ny, int nz, TetsPerCell split) {
  TetGridDesc d;
  d.nx = nx;
  d.ny = ny;
  d.nz = nz;
  d.origin = {-0.3, 1.25, 7.0};
  d.cell_size = {0.1, 0.25, 0.05};
  d.split = split;
  return d;
}

double box_volume(const TetGridDesc& d) {
  return d.nx * d.cell_size[0] * d.ny * d.cell_size[1] * d.nz * d.cell_size[2];
}

class TetGridSplits : public ::testing::TestWithParam<TetsPerCell> {};

TEST_P(TetGridSplits, CountsAndVertexLayout) {
  const TetGridDesc d = desc(3, 4, 5, GetParam());
  const auto mesh = sinew::make_tet_grid(d);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  const int per_cell = GetParam() == TetsPerCell::five ? 5 : 6;
  EXPECT_EQ(mesh->vertices.size(), 4u * 5u * 6u);
  EXPECT_EQ(mesh->tets.size(), static_cast<std::size_t>(per_cell * 3 * 4 * 5));
  for (int k = 0; k <= d.nz; ++k) {
    for (int j = 0; j <= d.ny; ++j) {
      for (int i = 0; i <= d.nx; ++i) {
        const Vec3d& p = mesh->vertices[static_cast<std::size_t>(i + (d.nx + 1) * (j + (d.ny + 1) * k))];
        EXPECT_NEAR(p[0], d.origin[0] + i * d.cell_size[0], 1e-12);
        EXPECT_NEAR(p[1], d.origin[1] + j * d.cell_size[1], 1e-12);
        EXPECT_NEAR(p[2], d.origin[2] + k * d.cell_size[2], 1e-12);
      }
    }
  }
}

TEST_P(TetGridSplits, PositiveTetsFillTheBox) {
  const TetGridDesc d = desc(3, 4, 5, GetParam());
  const auto mesh = sinew::make_tet_grid(d);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  const double cell = d.cell_size[0] * d.cell_size[1] * d.cell_size[2];
  double total = 0.0;
  for (const auto& t : mesh->tets) {
    const double v = signed_volume(*mesh, t);
    ASSERT_GT(v, 0.0);
    // Kuhn tets are each a sixth of the cell; the five-tet split has one
    // central tet of a third and four corner tets of a sixth.
    const bool sixth = std::abs(v - cell / 6) < 1e-9 * cell;
    const bool third = std::abs(v - cell / 3) < 1e-9 * cell;
    EXPECT_TRUE(sixth || (GetParam() == TetsPerCell::five && third)) << "tet volume " << v / cell << " cells";
    total += v;
  }
  EXPECT_NEAR(total, box_volume(d), 1e-9 * box_volume(d));
  EXPECT_TRUE(sinew::check_tet_mesh(*mesh, "grid").ok());
}

TEST_P(TetGridSplits, FacesConformAcrossCells) {
  for (const auto& [nx, ny, nz] :
       {std::array{1, 1, 1}, std::array{3, 4, 5}, std::array{2, 2, 2}, std::array{5, 1, 2}}) {
    const TetGridDesc d = desc(nx, ny, nz, GetParam());
    const auto mesh = sinew::make_tet_grid(d);
    ASSERT_TRUE(mesh.ok()) << mesh.error().message();
    std::size_t boundary = 0;
    for (const auto& [face, count] : face_use(*mesh)) {
      // Non-conforming cells would leave interior faces used once.
      if (on_box_boundary(*mesh, face, d)) {
        EXPECT_EQ(count, 1);
        ++boundary;
      } else {
        EXPECT_EQ(count, 2) << "interior face " << face[0] << " " << face[1] << " " << face[2];
      }
    }
    EXPECT_EQ(boundary, static_cast<std::size_t>(2 * (nx * ny + ny * nz + nx * nz) * 2));
  }
}

TEST_P(TetGridSplits, BoundarySurfaceIsClosedAndOutward) {
  const TetGridDesc d = desc(3, 4, 5, GetParam());
  const auto mesh = sinew::make_tet_grid(d);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  const sinew::TriMesh surface = sinew::extract_boundary_surface(*mesh);
  EXPECT_EQ(surface.vertices.size(), mesh->vertices.size());
  EXPECT_EQ(surface.triangles.size(), static_cast<std::size_t>(2 * (3 * 4 + 4 * 5 + 3 * 5) * 2));
  EXPECT_TRUE(closed_and_consistent(surface));
  // Positive and equal to the box: the winding is outward everywhere.
  EXPECT_NEAR(enclosed_volume(surface), box_volume(d), 1e-9 * box_volume(d));
  for (const auto& t : surface.triangles) {
    EXPECT_TRUE(on_box_boundary(*mesh, sorted_face(t[0], t[1], t[2]), d));
  }
}

std::string split_name(const ::testing::TestParamInfo<TetsPerCell>& p) {
  return p.param == TetsPerCell::five ? "Five" : "Six";
}

INSTANTIATE_TEST_SUITE_P(Splits, TetGridSplits, ::testing::Values(TetsPerCell::five, TetsPerCell::six),
                         split_name);

TEST(TetGrid, BoundarySurfaceIsDeterministic) {
  const auto mesh = sinew::make_tet_grid(desc(4, 3, 2, TetsPerCell::five));
  ASSERT_TRUE(mesh.ok());
  const auto a = sinew::extract_boundary_surface(*mesh);
  const auto b = sinew::extract_boundary_surface(*mesh);
  EXPECT_EQ(a.triangles, b.triangles);
}

TEST(TetGrid, SingleTetBoundaryWindsOutward) {
  // The four faces of one positively oriented tet must all face away from
  // the opposite vertex.
  TetMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.tets = {{0, 1, 2, 3}};
  ASSERT_GT(signed_volume(m, m.tets[0]), 0.0);
  const auto s = sinew::extract_boundary_surface(m);
  ASSERT_EQ(s.triangles.size(), 4u);
  for (const auto& t : s.triangles) {
    std::uint32_t opposite = 0;
    while (opposite == t[0] || opposite == t[1] || opposite == t[2]) ++opposite;
    const Vec3d n = cross(sub(m.vertices[t[1]], m.vertices[t[0]]), sub(m.vertices[t[2]], m.vertices[t[0]]));
    EXPECT_LT(dot(n, sub(m.vertices[opposite], m.vertices[t[0]])), 0.0);
  }
}

struct BadGrid {
  TetGridDesc desc;
  std::string parameter;
};

TEST(TetGrid, RejectsBadParametersNamingThem) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<BadGrid> cases;
  auto add = [&](std::string parameter, auto edit) {
    TetGridDesc d;
    edit(d);
    cases.push_back({d, std::move(parameter)});
  };
  add("nx", [](TetGridDesc& d) { d.nx = 0; });
  add("ny", [](TetGridDesc& d) { d.ny = -3; });
  add("nz", [](TetGridDesc& d) { d.nz = 0; });
  add("cell_size[0]", [](TetGridDesc& d) { d.cell_size[0] = 0.0; });
  add("cell_size[1]", [](TetGridDesc& d) { d.cell_size[1] = -1.0; });
  add("cell_size[2]", [&](TetGridDesc& d) { d.cell_size[2] = nan; });
  add("cell_size[0]", [&](TetGridDesc& d) { d.cell_size[0] = inf; });
  add("origin[1]", [&](TetGridDesc& d) { d.origin[1] = nan; });
  add("origin[2]", [&](TetGridDesc& d) { d.origin[2] = -inf; });
  add("origin[0]", [](TetGridDesc& d) {
    d.nx = 10;
    d.cell_size[0] = 1e308;
  });                                                            // extent overflows
  add("nx", [](TetGridDesc& d) { d.nx = d.ny = d.nz = 2000; });  // 2001^3 vertices > 2^32
  add("nz", [](TetGridDesc& d) { d.nx = d.ny = d.nz = std::numeric_limits<int>::max(); });
  for (const BadGrid& c : cases) {
    const auto mesh = sinew::make_tet_grid(c.desc);
    ASSERT_FALSE(mesh.ok()) << c.parameter;
    EXPECT_NE(mesh.error().message().find(c.parameter), std::string::npos) << mesh.error().message();
    EXPECT_NE(mesh.error().message().find("make_tet_grid"), std::string::npos) << mesh.error().message();
  }
  const auto mesh = sinew::make_tet_grid(cases[0].desc);
  EXPECT_NE(mesh.error().message().find("(got 0)"), std::string::npos) << mesh.error().message();
}

TEST(TetGrid, ScaleMeshScalesVolumeByCube) {
  auto mesh = sinew::make_tet_grid(desc(2, 3, 2, TetsPerCell::six));
  ASSERT_TRUE(mesh.ok());
  double before = 0.0, after = 0.0;
  for (const auto& t : mesh->tets) before += signed_volume(*mesh, t);
  sinew::scale_mesh(*mesh, 1e-3);
  for (const auto& t : mesh->tets) after += signed_volume(*mesh, t);
  EXPECT_NEAR(after, before * 1e-9, 1e-9 * before * 1e-9);
  // The check's tolerance is relative, so the scaled mesh still passes.
  EXPECT_TRUE(sinew::check_tet_mesh(*mesh).ok());
}

}  // namespace
