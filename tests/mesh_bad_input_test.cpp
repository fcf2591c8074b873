// Bad input: every reader error is an Error (never a crash) whose message
// names the file and the line, or the parameter/tet that is wrong.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mesh_test_helpers.h"
#include "sinew/mesh.h"

namespace {

namespace fs = std::filesystem;

fs::path tmp_dir() { return sinew::mesh_test::tmp_dir("mesh_bad_input"); }

fs::path write_file(const std::string& name, const std::string& text) {
  const fs::path p = tmp_dir() / name;
  std::ofstream out(p, std::ios::binary);
  out << text;
  return p;
}

// Two positive tets on five points; line numbers are those of the text.
const std::string kNode =
    "5 3 0 0\n"   // 1
    "0 0 0 0\n"   // 2
    "1 1 0 0\n"   // 3
    "2 0 1 0\n"   // 4
    "3 0 0 1\n"   // 5
    "4 1 1 1\n";  // 6
const std::string kEle =
    "2 4 0\n"       // 1
    "0 0 1 2 3\n"   // 2
    "1 1 2 3 4\n";  // 3

// Writes stem.node and stem.ele and reads them.
sinew::Result<sinew::TetMesh> read_pair(const std::string& stem, const std::string& node,
                                        const std::string& ele) {
  write_file(stem + ".node", node);
  write_file(stem + ".ele", ele);
  return sinew::read_tetgen(tmp_dir() / stem);
}

// The message holds every expected fragment (e.g. "file.node:4:"), and the
// error is a bad file (ErrorCode::bad_input_file), whatever is wrong in it.
::testing::AssertionResult fails_with(const sinew::Result<sinew::TetMesh>& r,
                                      std::vector<std::string> fragments) {
  if (r.ok()) return ::testing::AssertionFailure() << "read succeeded";
  if (r.error().code() != sinew::ErrorCode::bad_input_file) {
    return ::testing::AssertionFailure() << "code " << sinew::error_code_name(r.error().code())
                                         << ", not bad_input_file: " << r.error().message();
  }
  for (const std::string& f : fragments) {
    if (r.error().message().find(f) == std::string::npos) {
      return ::testing::AssertionFailure() << "'" << f << "' not in: " << r.error().message();
    }
  }
  return ::testing::AssertionSuccess() << r.error().message();
}

std::string replace_line(const std::string& text, int line, const std::string& with) {
  std::string out;
  int n = 1;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t eol = text.find('\n', pos);
    const std::string current = text.substr(pos, eol - pos);
    out += (n == line ? with : current) + "\n";
    pos = eol + 1;
    ++n;
  }
  return out;
}

TEST(MeshBadInput, ValidBaseReads) {
  const auto mesh = read_pair("base", kNode, kEle);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  EXPECT_EQ(mesh->tets.size(), 2u);
}

TEST(MeshBadInput, TetGenTruncatedNodeLine) {
  EXPECT_TRUE(fails_with(read_pair("trunc_node", kNode.substr(0, kNode.find("3 0 0 1") + 3), kEle),
                         {"trunc_node.node:5:"}));
}

TEST(MeshBadInput, TetGenTruncatedEleLine) {
  EXPECT_TRUE(
      fails_with(read_pair("trunc_ele", kNode, kEle.substr(0, kEle.size() - 5)), {"trunc_ele.ele:3:"}));
}

TEST(MeshBadInput, TetGenHeaderCountLargerThanFile) {
  EXPECT_TRUE(fails_with(read_pair("count_node", replace_line(kNode, 1, "7 3 0 0"), kEle),
                         {"count_node.node:6:", "5 of the 7"}));
  EXPECT_TRUE(fails_with(read_pair("count_ele", kNode, replace_line(kEle, 1, "3 4 0")),
                         {"count_ele.ele:3:", "2 of the 3"}));
}

TEST(MeshBadInput, TetGenHeaderCountSmallerThanFile) {
  EXPECT_TRUE(
      fails_with(read_pair("fewer_ele", kNode, replace_line(kEle, 1, "1 4 0")), {"fewer_ele.ele:3:"}));
}

TEST(MeshBadInput, TetGenHeaderAttributeCountDisagreesWithLines) {
  EXPECT_TRUE(
      fails_with(read_pair("attr_node", replace_line(kNode, 1, "5 3 1 0"), kEle), {"attr_node.node:2:"}));
  EXPECT_TRUE(fails_with(read_pair("attr_ele", kNode, replace_line(kEle, 1, "2 4 2")), {"attr_ele.ele:2:"}));
}

TEST(MeshBadInput, TetGenOutOfRangeIndex) {
  EXPECT_TRUE(
      fails_with(read_pair("range", kNode, replace_line(kEle, 3, "1 1 2 3 5")), {"range.ele:3:", "5"}));
  // 1-based files may not use 0.
  std::string one_based = "5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n";
  EXPECT_TRUE(fails_with(read_pair("range1", one_based, "1 4 0\n1 0 1 2 3\n"), {"range1.ele:2:"}));
}

TEST(MeshBadInput, TetGenNegativeIndex) {
  EXPECT_TRUE(
      fails_with(read_pair("negative", kNode, replace_line(kEle, 3, "1 -1 2 3 4")), {"negative.ele:3:"}));
}

TEST(MeshBadInput, TetGenNonFiniteCoordinates) {
  EXPECT_TRUE(
      fails_with(read_pair("nan", replace_line(kNode, 4, "2 nan 1 0"), kEle), {"nan.node:4:", "non-finite"}));
  EXPECT_TRUE(
      fails_with(read_pair("inf", replace_line(kNode, 4, "2 0 inf 0"), kEle), {"inf.node:4:", "non-finite"}));
  EXPECT_TRUE(fails_with(read_pair("minf", replace_line(kNode, 5, "3 0 0 -INF"), kEle), {"minf.node:5:"}));
  EXPECT_TRUE(fails_with(read_pair("huge", replace_line(kNode, 6, "4 1 1e999 1"), kEle), {"huge.node:6:"}));
}

TEST(MeshBadInput, TetGenZeroVolumeTet) {
  // Point 3 moved into the plane of points 0, 1, 2.
  EXPECT_TRUE(fails_with(read_pair("flat", replace_line(kNode, 5, "3 0.5 0.5 0"), kEle),
                         {"flat.ele", "tet 0", "zero volume"}));
}

TEST(MeshBadInput, TetGenInvertedTet) {
  EXPECT_TRUE(fails_with(read_pair("inverted", kNode, replace_line(kEle, 3, "1 2 1 3 4")),
                         {"inverted.ele", "tet 1", "inverted"}));
}

TEST(MeshBadInput, TetGenRepeatedVertex) {
  EXPECT_TRUE(
      fails_with(read_pair("repeat", kNode, replace_line(kEle, 2, "0 0 1 1 3")), {"repeat.ele", "tet 0"}));
}

TEST(MeshBadInput, TetGenMissingEleFile) {
  write_file("lonely.node", kNode);
  fs::remove(tmp_dir() / "lonely.ele");
  EXPECT_TRUE(fails_with(sinew::read_tetgen(tmp_dir() / "lonely.node"), {"lonely.ele"}));
  EXPECT_TRUE(fails_with(sinew::read_tetgen(tmp_dir() / "does_not_exist"), {"does_not_exist.node"}));
}

TEST(MeshBadInput, TetGenEmptyFiles) {
  EXPECT_TRUE(fails_with(read_pair("empty", "", kEle), {"empty.node:1:", "empty"}));
  EXPECT_TRUE(fails_with(read_pair("empty_ele", kNode, "# only a comment\n\n"), {"empty_ele.ele:2:"}));
}

TEST(MeshBadInput, TetGenGarbage) {
  EXPECT_TRUE(
      fails_with(read_pair("garbage", "hello world\nthis is not a mesh\n", kEle), {"garbage.node:1:"}));
  EXPECT_TRUE(fails_with(read_pair("garbage_ele", kNode, replace_line(kEle, 2, "0 0 one 2 3")),
                         {"garbage_ele.ele:2:"}));
  EXPECT_TRUE(fails_with(read_pair("garbage_xyz", replace_line(kNode, 3, "1 1.0x 0 0"), kEle),
                         {"garbage_xyz.node:3:"}));
}

TEST(MeshBadInput, TetGenBadHeaders) {
  EXPECT_TRUE(
      fails_with(read_pair("dim2", replace_line(kNode, 1, "5 2 0 0"), kEle), {"dim2.node:1:", "dimension"}));
  EXPECT_TRUE(
      fails_with(read_pair("npt6", kNode, replace_line(kEle, 1, "2 6 0")), {"npt6.ele:1:", "4 or 10"}));
  EXPECT_TRUE(fails_with(read_pair("zero", replace_line(kNode, 1, "0 3 0 0"), kEle), {"zero.node:1:"}));
  EXPECT_TRUE(fails_with(read_pair("markers", replace_line(kNode, 1, "5 3 0 2"), kEle), {"markers.node:1:"}));
}

TEST(MeshBadInput, TetGenBadPointNumbering) {
  EXPECT_TRUE(fails_with(read_pair("start2", replace_line(kNode, 2, "2 0 0 0"), kEle), {"start2.node:2:"}));
  EXPECT_TRUE(fails_with(read_pair("gap", replace_line(kNode, 4, "7 0 1 0"), kEle), {"gap.node:4:"}));
}

// ------------------------------------------------------------------ Gmsh

const std::string kMsh41 =
    "$MeshFormat\n"     // 1
    "4.1 0 8\n"         // 2
    "$EndMeshFormat\n"  // 3
    "$Nodes\n"          // 4
    "1 5 1 5\n"         // 5
    "3 1 0 5\n"         // 6
    "1\n2\n3\n4\n5\n"   // 7-11
    "0 0 0\n"           // 12
    "1 0 0\n"           // 13
    "0 1 0\n"           // 14
    "0 0 1\n"           // 15
    "1 1 1\n"           // 16
    "$EndNodes\n"       // 17
    "$Elements\n"       // 18
    "2 3 1 3\n"         // 19
    "2 1 2 1\n"         // 20
    "1 1 2 3\n"         // 21
    "3 1 4 2\n"         // 22
    "2 1 2 3 4\n"       // 23
    "3 2 3 4 5\n"       // 24
    "$EndElements\n";   // 25

sinew::Result<sinew::TetMesh> read_msh(const std::string& name, const std::string& text) {
  return sinew::read_gmsh(write_file(name, text));
}

TEST(MeshBadInput, GmshValidBaseReads) {
  const auto mesh = read_msh("base.msh", kMsh41);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  EXPECT_EQ(mesh->tets.size(), 2u);
}

TEST(MeshBadInput, GmshMissingEndNodes) {
  EXPECT_TRUE(fails_with(read_msh("no_end_nodes.msh", replace_line(kMsh41, 17, "")),
                         {"no_end_nodes.msh:18:", "$EndNodes"}));
}

TEST(MeshBadInput, GmshUnknownNodeTag) {
  EXPECT_TRUE(fails_with(read_msh("unknown_tag.msh", replace_line(kMsh41, 24, "3 2 3 4 9")),
                         {"unknown_tag.msh:24:", "node tag 9"}));
}

TEST(MeshBadInput, GmshBinary) {
  std::string binary = "$MeshFormat\n4.1 1 8\n";
  binary += std::string("\x01\x00\x00\x00", 4) + "\n$EndMeshFormat\n$Nodes\n";
  binary += std::string("\x00\xff\x13\x37\x00\x00", 6);
  EXPECT_TRUE(fails_with(read_msh("binary.msh", binary), {"binary.msh:2:", "binary .msh not supported"}));
}

TEST(MeshBadInput, GmshNoTets) {
  std::string text = replace_line(kMsh41, 19, "1 1 1 1");
  text = replace_line(text, 22, "$EndElements");
  text = text.substr(0, text.find("$EndElements\n") + 13);
  EXPECT_TRUE(fails_with(read_msh("no_tets.msh", text), {"no_tets.msh:18:", "no 4-node tetrahedra"}));
}

TEST(MeshBadInput, GmshUnsupportedVersion) {
  EXPECT_TRUE(fails_with(read_msh("v3.msh", replace_line(kMsh41, 2, "3.0 0 8")), {"v3.msh:2:", "version"}));
  EXPECT_TRUE(fails_with(read_msh("v5.msh", replace_line(kMsh41, 2, "5 0 8")), {"v5.msh:2:", "version"}));
}

TEST(MeshBadInput, GmshMissingMeshFormat) {
  EXPECT_TRUE(fails_with(read_msh("no_format.msh", kMsh41.substr(kMsh41.find("$Nodes"))),
                         {"no_format.msh:1:", "$MeshFormat"}));
  EXPECT_TRUE(fails_with(read_msh("empty.msh", ""), {"empty.msh:1:"}));
  EXPECT_TRUE(fails_with(read_msh("text.msh", "just some words\n"), {"text.msh:1:"}));
}

TEST(MeshBadInput, GmshTruncatedSections) {
  // Header promises 5 nodes, the block holds 4: the coordinates run into $EndNodes.
  std::string short_block = replace_line(kMsh41, 6, "3 1 0 4");
  EXPECT_TRUE(fails_with(read_msh("short_block.msh", short_block), {"short_block.msh:"}));
  // The file stops in the middle of $Elements.
  EXPECT_TRUE(
      fails_with(read_msh("cut.msh", kMsh41.substr(0, kMsh41.find("3 2 3 4 5"))), {"cut.msh:", "$Elements"}));
  // A count larger than the section: reading runs into $EndElements on line 25.
  EXPECT_TRUE(
      fails_with(read_msh("count.msh", replace_line(replace_line(kMsh41, 19, "2 4 1 4"), 22, "3 1 4 3")),
                 {"count.msh:25:", "ends early"}));
  // A block larger than the section header allows is caught at the block header (line 22).
  EXPECT_TRUE(fails_with(read_msh("block.msh", replace_line(kMsh41, 22, "3 1 4 3")), {"block.msh:22:"}));
}

TEST(MeshBadInput, GmshNonFiniteCoordinate) {
  EXPECT_TRUE(
      fails_with(read_msh("nan.msh", replace_line(kMsh41, 14, "0 nan 0")), {"nan.msh:14:", "non-finite"}));
  EXPECT_TRUE(
      fails_with(read_msh("inf.msh", replace_line(kMsh41, 15, "0 0 -inf")), {"inf.msh:15:", "non-finite"}));
}

TEST(MeshBadInput, GmshInvertedTet) {
  EXPECT_TRUE(fails_with(read_msh("inverted.msh", replace_line(kMsh41, 23, "2 2 1 3 4")),
                         {"inverted.msh", "tet 0", "inverted"}));
}

TEST(MeshBadInput, GmshDuplicateNodeTag) {
  EXPECT_TRUE(fails_with(read_msh("dup.msh", replace_line(kMsh41, 11, "4")), {"dup.msh:4:", "tag 4"}));
}

TEST(MeshBadInput, GmshUnclosedUnknownSection) {
  EXPECT_TRUE(fails_with(read_msh("unclosed.msh", kMsh41 + "$Comments\nno end here\n"),
                         {"unclosed.msh:26:", "$Comments"}));
}

TEST(MeshBadInput, UnknownExtension) {
  EXPECT_TRUE(fails_with(sinew::read_tet_mesh(write_file("mesh.obj", "v 0 0 0\n")), {"mesh.obj", ".obj"}));
}

// Every prefix of a valid file, and random byte corruptions, must read
// cleanly or fail with an error that names the file; nothing may crash.
TEST(MeshBadInput, TruncationsAndCorruptionsNeverCrash) {
  std::mt19937 rng(7);
  auto check = [](const sinew::Result<sinew::TetMesh>& r, const std::string& name) {
    if (!r.ok()) {
      EXPECT_NE(r.error().message().find(name), std::string::npos) << r.error().message();
      EXPECT_EQ(r.error().code(), sinew::ErrorCode::bad_input_file) << r.error().message();
    }
  };
  for (std::size_t n = 0; n <= kMsh41.size(); ++n)
    check(read_msh("prefix.msh", kMsh41.substr(0, n)), "prefix.msh");
  for (std::size_t n = 0; n <= kEle.size(); ++n)
    check(read_pair("prefix", kNode, kEle.substr(0, n)), "prefix.");
  for (std::size_t n = 0; n <= kNode.size(); ++n)
    check(read_pair("prefix", kNode.substr(0, n), kEle), "prefix.");
  const std::string junk = "$-+.e9 \n\t0x#nanif";
  for (int trial = 0; trial < 400; ++trial) {
    std::string msh = kMsh41, node = kNode, ele = kEle;
    for (int k = 0; k < 3; ++k) {
      msh[rng() % msh.size()] = junk[rng() % junk.size()];
      node[rng() % node.size()] = junk[rng() % junk.size()];
      ele[rng() % ele.size()] = junk[rng() % junk.size()];
    }
    check(read_msh("corrupt.msh", msh), "corrupt.msh");
    check(read_pair("corrupt", node, ele), "corrupt.");
  }
}

// check_tet_mesh on meshes built in memory: messages carry the origin.
TEST(MeshBadInput, CheckTetMeshNamesOriginAndTet) {
  sinew::TetMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_NE(sinew::check_tet_mesh(m, "unit").error().message().find("unit"), std::string::npos);  // no tets
  m.tets = {{0, 1, 2, 3}};
  EXPECT_TRUE(sinew::check_tet_mesh(m, "unit").ok());
  m.tets = {{0, 1, 2, 3}, {0, 1, 2, 4}};
  const auto range = sinew::check_tet_mesh(m, "unit");
  ASSERT_FALSE(range.ok());
  EXPECT_NE(range.error().message().find("unit: tet 1"), std::string::npos) << range.error().message();
  // A mesh given in code is a bad parameter; the same fault read from a file is a bad file (fails_with).
  EXPECT_EQ(range.error().code(), sinew::ErrorCode::bad_parameter);
  m.tets = {{0, 1, 2, 3}};
  m.vertices[2][1] = std::numeric_limits<double>::quiet_NaN();
  const auto nan = sinew::check_tet_mesh(m, "unit");
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().message().find("vertex 2"), std::string::npos) << nan.error().message();
  // A tet far flatter than 1e-12 of its longest edge cubed is degenerate, at any scale.
  m.vertices = {{0, 0, 0}, {1e3, 0, 0}, {0, 1e3, 0}, {0, 0, 1e-10}};
  const auto thin = sinew::check_tet_mesh(m, "km");
  ASSERT_FALSE(thin.ok());
  EXPECT_NE(thin.error().message().find("zero volume"), std::string::npos) << thin.error().message();
  m.vertices = {{0, 0, 0}, {1e-3, 0, 0}, {0, 1e-3, 0}, {0, 0, 1e-3}};
  EXPECT_TRUE(sinew::check_tet_mesh(m, "mm").ok());
}

// The tolerance is per tet: a tiny, well-shaped tet in a large (graded) mesh
// passes; a flat one of the same size fails, naming the tet, its vertices,
// its signed volume and the minimum.
TEST(MeshBadInput, CheckTetMeshJudgesEachTetByItsOwnSize) {
  sinew::TetMesh m;
  m.vertices = {{0, 0, 0}, {1e3, 0, 0}, {0, 1e3, 0}, {0, 0, 1e3},                 // large tet
                {5, 5, 5}, {5 + 1e-3, 5, 5}, {5, 5 + 1e-3, 5}, {5, 5, 5 + 1e-3}};  // 1e-3 edge
  m.tets = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  const auto graded = sinew::check_tet_mesh(m, "graded");
  EXPECT_TRUE(graded.ok()) << graded.error().message();
  m.vertices[7][2] = 5 + 4e-15;  // height ~4e-15 against edges of 1e-3: flatter than 1e-12
  const auto flat = sinew::check_tet_mesh(m, "graded");
  ASSERT_FALSE(flat.ok());
  const std::string& msg = flat.error().message();
  for (const char* part : {"graded: tet 1 (vertices 4 5 6 7)", "zero volume", "signed volume", "minimum"}) {
    EXPECT_NE(msg.find(part), std::string::npos) << part << " not in: " << msg;
  }
  m.vertices[7][2] = 5 - 1e-4;  // below the base: inverted
  const auto inverted = sinew::check_tet_mesh(m, "graded");
  ASSERT_FALSE(inverted.ok());
  EXPECT_NE(inverted.error().message().find("tet 1 (vertices 4 5 6 7) is inverted"), std::string::npos)
      << inverted.error().message();
}

}  // namespace
