// read_gmsh: Gmsh .msh files, ASCII format 2.x, 4.0 and 4.1.
//
// Format reference: Gmsh reference manual (gmsh.info/doc/texinfo), chapter
// "Gmsh file formats", section "MSH file format" (version 4.1) and
// "Legacy formats" / "MSH file format version 2" and "version 4.0".
//   $MeshFormat  version file-type(0 = ASCII, 1 = binary) data-size  $EndMeshFormat
//   4.1 $Nodes   numEntityBlocks numNodes minNodeTag maxNodeTag
//                per block: entityDim entityTag parametric numNodesInBlock,
//                then numNodesInBlock tags, then their "x y z [u [v [w]]]"
//   4.0 $Nodes   numEntityBlocks numNodes
//                per block: entityTag entityDim parametric numNodesInBlock,
//                then per node "tag x y z [u [v [w]]]"
//   4.1 $Elements numEntityBlocks numElements minElementTag maxElementTag
//                per block: entityDim entityTag elementType numElementsInBlock,
//                then per element "tag nodeTag..."
//   4.0 $Elements numEntityBlocks numElements
//                per block: entityTag entityDim elementType numElementsInBlock, ...
//   2.x $Nodes   numNodes, then "tag x y z" per node
//   2.x $Elements numElements, then "tag type numTags tag... nodeTag..."
// Parametric nodes carry entityDim extra coordinates. Other sections
// ($Entities, $PhysicalNames, $NodeData, ...) are skipped up to their $End
// line. Only element type 4 (4-node tetrahedron, reference corners
// (0,0,0), (1,0,0), (0,1,0), (0,0,1): positively oriented) is kept.
//
// The file is read whole and tokenised in place with std::from_chars
// (text_scan.h).
#include <algorithm>
#include <cstdint>
#include <limits>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "sinew/mesh.h"
#include "text_scan.h"

namespace sinew {
namespace {

using detail::parse_double;
using detail::parse_int;
using detail::parse_uint;
using detail::Parsed;
using detail::quoted;
using detail::read_whole_file;
using detail::Scanner;
using detail::Token;
using detail::Where;

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// Nodes per element for the MSH element types (reference manual, "MSH file
// format", elm-type list); -1 for types this reader does not know, whose
// elements are then skipped line by line (Gmsh writes one per line).
int nodes_per_element(std::uint64_t type) {
  switch (type) {
    case 1:
      return 2;  // line
    case 2:
      return 3;  // triangle
    case 3:
      return 4;  // quadrangle
    case 4:
      return 4;  // tetrahedron
    case 5:
      return 8;  // hexahedron
    case 6:
      return 6;  // prism
    case 7:
      return 5;  // pyramid
    case 8:
      return 3;  // 2nd order line
    case 9:
      return 6;  // 2nd order triangle
    case 10:
      return 9;  // 2nd order quadrangle
    case 11:
      return 10;  // 2nd order tetrahedron
    case 12:
      return 27;  // 2nd order hexahedron
    case 13:
      return 18;  // 2nd order prism
    case 14:
      return 14;  // 2nd order pyramid
    case 15:
      return 1;  // point
    case 16:
      return 8;  // 8-node quadrangle
    case 17:
      return 20;  // 20-node hexahedron
    case 18:
      return 15;  // 15-node prism
    case 19:
      return 13;  // 13-node pyramid
    case 20:
      return 9;  // incomplete 3rd order triangle
    case 21:
      return 10;  // 3rd order triangle
    case 22:
      return 12;  // incomplete 4th order triangle
    case 23:
      return 15;  // 4th order triangle
    case 24:
      return 15;  // incomplete 5th order triangle
    case 25:
      return 21;  // 5th order triangle
    case 26:
      return 4;  // 3rd order edge
    case 27:
      return 5;  // 4th order edge
    case 28:
      return 6;  // 5th order edge
    case 29:
      return 20;  // 3rd order tetrahedron
    case 30:
      return 35;  // 4th order tetrahedron
    case 31:
      return 56;  // 5th order tetrahedron
    case 92:
      return 64;  // 3rd order hexahedron
    case 93:
      return 125;  // 4th order hexahedron
    default:
      return -1;
  }
}

// Node tag -> index into the $Nodes arrays. Tags are usually dense
// (1..N), so a direct table is used unless the tags are very sparse.
class NodeLookup {
 public:
  /// [out] duplicate: a tag that occurs twice; returns false then.
  bool build(const std::vector<std::uint64_t>& tags, std::uint64_t& duplicate) {
    const std::uint64_t max_tag = tags.empty() ? 0 : *std::max_element(tags.begin(), tags.end());
    dense_ = max_tag <= 4 * static_cast<std::uint64_t>(tags.size()) + 1024;
    if (dense_) {
      table_.assign(static_cast<std::size_t>(max_tag) + 1, kNone);
      for (std::size_t i = 0; i < tags.size(); ++i) {
        std::uint32_t& slot = table_[static_cast<std::size_t>(tags[i])];
        if (slot != kNone) {
          duplicate = tags[i];
          return false;
        }
        slot = static_cast<std::uint32_t>(i);
      }
      return true;
    }
    sorted_.resize(tags.size());
    for (std::size_t i = 0; i < tags.size(); ++i) sorted_[i] = {tags[i], static_cast<std::uint32_t>(i)};
    std::sort(sorted_.begin(), sorted_.end());
    for (std::size_t i = 1; i < sorted_.size(); ++i) {
      if (sorted_[i].first == sorted_[i - 1].first) {
        duplicate = sorted_[i].first;
        return false;
      }
    }
    return true;
  }
  std::uint32_t find(std::uint64_t tag) const {
    if (dense_) return tag < table_.size() ? table_[static_cast<std::size_t>(tag)] : kNone;
    const auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::pair{tag, std::uint32_t{0}});
    return it != sorted_.end() && it->first == tag ? it->second : kNone;
  }

 private:
  bool dense_ = true;
  std::vector<std::uint32_t> table_;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> sorted_;
};

enum class Version { v2, v40, v41 };

class GmshParser {
 public:
  GmshParser(std::string_view text, std::string file) : scan_(text), where_{std::move(file)} {}

  Result<TetMesh> parse() {
    if (!read_format() || !read_sections() || !check_complete()) return *error_;
    return build_mesh();
  }

 private:
  bool fail(std::size_t line, const std::string& what) {
    error_ = where_.at(line, what);
    return false;
  }

  // The next data token of the current section; a '$' keyword or the end
  // of the file here means the section is shorter than its counts say.
  bool data_token(Token& t, const std::string& what) {
    if (!scan_.next(t)) {
      return fail(scan_.line(), "file ends inside " + section_ + ", expected " + what);
    }
    if (t.text.front() == '$') {
      return fail(t.line, section_ + " ends early: expected " + what + ", found " + quoted(t.text) +
                              " (fewer entries than its header announces)");
    }
    return true;
  }

  bool read_uint(std::uint64_t& v, const std::string& what, Token* where = nullptr) {
    Token t;
    if (!data_token(t, what)) return false;
    if (where) *where = t;
    if (!parse_uint(t.text, v))
      return fail(t.line, "expected " + what + " (an unsigned integer), found " + quoted(t.text));
    return true;
  }

  bool read_int(std::int64_t& v, const std::string& what) {
    Token t;
    if (!data_token(t, what)) return false;
    if (!parse_int(t.text, v))
      return fail(t.line, "expected " + what + " (an integer), found " + quoted(t.text));
    return true;
  }

  bool read_real(double& v, const std::string& what) {
    Token t;
    if (!data_token(t, what)) return false;
    const Parsed p = parse_double(t.text, v);
    if (p == Parsed::not_a_number)
      return fail(t.line, "expected " + what + " (a number), found " + quoted(t.text));
    if (p == Parsed::not_finite) return fail(t.line, "non-finite " + what + " " + quoted(t.text));
    return true;
  }

  bool expect_keyword(std::string_view keyword) {
    Token t;
    if (!scan_.next(t))
      return fail(scan_.line(), "file ends inside " + section_ + ", expected " + std::string(keyword));
    if (t.text != keyword) {
      return fail(t.line, "expected " + std::string(keyword) + ", found " + quoted(t.text) + " (" + section_ +
                              " has more entries than its header announces, or is not closed)");
    }
    return true;
  }

  bool read_format() {
    Token t;
    if (!scan_.next(t)) return fail(1, "empty file, expected $MeshFormat");
    if (t.text != "$MeshFormat") {
      return fail(t.line, "missing $MeshFormat at the start of the file, found " + quoted(t.text) +
                              " (not a Gmsh .msh file?)");
    }
    section_ = "$MeshFormat";
    Token version_tok, type_tok;
    std::uint64_t data_size = 0;
    if (!data_token(version_tok, "the format version") || !data_token(type_tok, "the file type"))
      return false;
    if (type_tok.text == "1") {
      return fail(type_tok.line,
                  "binary .msh not supported (re-save the mesh from Gmsh as ASCII MSH 4.1 or 2.2)");
    }
    if (type_tok.text != "0")
      return fail(type_tok.line, "file type must be 0 (ASCII), found " + quoted(type_tok.text));
    if (!read_uint(data_size, "the data size")) return false;
    double version = 0.0;
    if (parse_double(version_tok.text, version) != Parsed::ok) {
      return fail(version_tok.line, "bad format version " + quoted(version_tok.text));
    }
    if (version >= 2.0 && version < 3.0) {
      version_ = Version::v2;
    } else if (version == 4.0) {
      version_ = Version::v40;
    } else if (version == 4.1) {
      version_ = Version::v41;
    } else {
      return fail(version_tok.line, "unsupported .msh version " + std::string(version_tok.text) +
                                        " (supported: 2.x, 4.0, 4.1)");
    }
    return expect_keyword("$EndMeshFormat");
  }

  bool read_sections() {
    Token t;
    while (scan_.next(t)) {
      if (t.text == "$Nodes") {
        if (have_nodes_) return fail(t.line, "second $Nodes section");
        section_ = "$Nodes";
        if (!read_nodes(t.line)) return false;
      } else if (t.text == "$Elements") {
        if (!have_nodes_) return fail(t.line, "$Elements before $Nodes");
        if (have_elements_) return fail(t.line, "second $Elements section");
        section_ = "$Elements";
        if (!read_elements(t.line)) return false;
      } else if (t.text.front() == '$' && t.text.substr(0, 4) != "$End") {
        if (!skip_section(t)) return false;
      } else {
        return fail(t.line, "expected a section keyword such as $Nodes, found " + quoted(t.text));
      }
    }
    return true;
  }

  bool skip_section(const Token& start) {
    const std::string end = "$End" + std::string(start.text.substr(1));
    Token t;
    while (scan_.next(t)) {
      if (t.text == end) return true;
    }
    return fail(start.line, "section " + std::string(start.text) + " is not closed (no " + end + ")");
  }

  bool check_complete() {
    if (!have_nodes_) return fail(scan_.line(), "no $Nodes section");
    if (!have_elements_) return fail(scan_.line(), "no $Elements section");
    if (tets_.empty()) {
      return fail(elements_line_, "no 4-node tetrahedra (element type 4) in $Elements");
    }
    return true;
  }

  // ---------------------------------------------------------------- nodes
  bool read_node_coords(std::uint64_t entity_dim, bool parametric) {
    Vec3d p{};
    for (std::size_t a = 0; a < 3; ++a) {
      if (!read_real(p[a], "node coordinate")) return false;
    }
    // Parametric nodes add entityDim coordinates (u, v, w) that are not needed.
    const std::uint64_t extra = parametric ? std::min<std::uint64_t>(entity_dim, 3) : 0;
    for (std::uint64_t i = 0; i < extra; ++i) {
      double ignored = 0.0;
      if (!read_real(ignored, "parametric node coordinate")) return false;
    }
    positions_.push_back(p);
    return true;
  }

  bool read_nodes(std::size_t section_line) {
    std::uint64_t total = 0;
    if (version_ == Version::v2) {
      if (!read_uint(total, "the number of nodes") || !check_node_total(total, section_line)) return false;
      for (std::uint64_t i = 0; i < total; ++i) {
        std::uint64_t tag = 0;
        if (!read_uint(tag, "a node tag")) return false;
        tags_.push_back(tag);
        if (!read_node_coords(0, false)) return false;
      }
    } else if (!read_node_blocks(total, section_line)) {
      return false;
    }
    if (!expect_keyword("$EndNodes")) return false;
    std::uint64_t duplicate = 0;
    if (!lookup_.build(tags_, duplicate)) {
      return fail(section_line, "node tag " + std::to_string(duplicate) + " is defined twice in $Nodes");
    }
    have_nodes_ = true;
    return true;
  }

  bool check_node_total(std::uint64_t total, std::size_t section_line) {
    if (total >= kNone) return fail(section_line, std::to_string(total) + " nodes do not fit 32-bit indices");
    // Reserve no more than the file could hold, whatever the header claims.
    const std::size_t cap =
        static_cast<std::size_t>(std::min<std::uint64_t>(total, scan_.remaining() / 6 + 1));
    tags_.reserve(cap);
    positions_.reserve(cap);
    return true;
  }

  bool read_node_blocks(std::uint64_t& total, std::size_t section_line) {
    std::uint64_t blocks = 0, min_tag = 0, max_tag = 0;
    if (!read_uint(blocks, "the number of entity blocks") || !read_uint(total, "the number of nodes"))
      return false;
    if (version_ == Version::v41 &&
        (!read_uint(min_tag, "the minimum node tag") || !read_uint(max_tag, "the maximum node tag"))) {
      return false;
    }
    if (!check_node_total(total, section_line)) return false;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      if (!read_node_block(total)) return false;
    }
    if (tags_.size() != total) {
      return fail(section_line, "$Nodes header announces " + std::to_string(total) +
                                    " nodes, but its blocks hold " + std::to_string(tags_.size()));
    }
    return true;
  }

  bool read_node_block(std::uint64_t total) {
    std::uint64_t first = 0, second = 0, parametric = 0, count = 0;
    Token header;
    if (!read_uint(first, "an entity block header", &header) ||
        !read_uint(second, "an entity block header") || !read_uint(parametric, "the parametric flag") ||
        !read_uint(count, "the number of nodes in the block")) {
      return false;
    }
    if (parametric > 1)
      return fail(header.line, "parametric flag must be 0 or 1, found " + std::to_string(parametric));
    if (count > total - tags_.size()) {
      return fail(header.line, "entity block holds " + std::to_string(count) + " nodes, but only " +
                                   std::to_string(total - tags_.size()) + " of the " + std::to_string(total) +
                                   " the $Nodes header announces are left");
    }
    // 4.1 writes entityDim first, 4.0 entityTag first.
    const std::uint64_t entity_dim = version_ == Version::v41 ? first : second;
    if (version_ == Version::v41) {
      for (std::uint64_t i = 0; i < count; ++i) {
        std::uint64_t tag = 0;
        if (!read_uint(tag, "a node tag")) return false;
        tags_.push_back(tag);
      }
      for (std::uint64_t i = 0; i < count; ++i) {
        if (!read_node_coords(entity_dim, parametric == 1)) return false;
      }
      return true;
    }
    for (std::uint64_t i = 0; i < count; ++i) {
      std::uint64_t tag = 0;
      if (!read_uint(tag, "a node tag")) return false;
      tags_.push_back(tag);
      if (!read_node_coords(entity_dim, parametric == 1)) return false;
    }
    return true;
  }

  // ------------------------------------------------------------- elements
  bool read_tet_nodes(std::uint64_t element_tag) {
    std::array<std::uint32_t, 4> tet{};
    for (std::uint32_t& v : tet) {
      std::uint64_t tag = 0;
      Token where;
      if (!read_uint(tag, "a node tag", &where)) return false;
      v = lookup_.find(tag);
      if (v == kNone) {
        return fail(where.line, "element " + std::to_string(element_tag) + " refers to node tag " +
                                    std::to_string(tag) + ", which $Nodes does not define");
      }
    }
    tets_.push_back(tet);
    return true;
  }

  // Reads the node list of one element after its tag (and, in 2.x, its tags).
  bool read_element_nodes(std::uint64_t element_tag, std::uint64_t type) {
    if (type == 4) return read_tet_nodes(element_tag);
    const int n = nodes_per_element(type);
    if (n < 0) {
      scan_.skip_line();
      return true;
    }
    for (int i = 0; i < n; ++i) {
      std::uint64_t ignored = 0;
      if (!read_uint(ignored, "a node tag")) return false;
    }
    return true;
  }

  bool read_elements(std::size_t section_line) {
    elements_line_ = section_line;
    if (version_ == Version::v2) {
      std::uint64_t total = 0;
      if (!read_uint(total, "the number of elements")) return false;
      for (std::uint64_t i = 0; i < total; ++i) {
        if (!read_v2_element()) return false;
      }
    } else if (!read_element_blocks(section_line)) {
      return false;
    }
    if (!expect_keyword("$EndElements")) return false;
    have_elements_ = true;
    return true;
  }

  bool read_v2_element() {
    std::uint64_t tag = 0, type = 0, tag_count = 0;
    if (!read_uint(tag, "an element tag") || !read_uint(type, "an element type") ||
        !read_uint(tag_count, "the number of element tags")) {
      return false;
    }
    for (std::uint64_t i = 0; i < tag_count; ++i) {
      std::int64_t ignored = 0;  // physical/elementary/partition tags may be negative
      if (!read_int(ignored, "an element tag")) return false;
    }
    return read_element_nodes(tag, type);
  }

  bool read_element_blocks(std::size_t section_line) {
    std::uint64_t blocks = 0, total = 0, min_tag = 0, max_tag = 0;
    if (!read_uint(blocks, "the number of entity blocks") || !read_uint(total, "the number of elements")) {
      return false;
    }
    if (version_ == Version::v41 &&
        (!read_uint(min_tag, "the minimum element tag") || !read_uint(max_tag, "the maximum element tag"))) {
      return false;
    }
    std::uint64_t seen = 0;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      std::uint64_t first = 0, second = 0, type = 0, count = 0;
      Token header;
      if (!read_uint(first, "an entity block header", &header) ||
          !read_uint(second, "an entity block header") || !read_uint(type, "an element type") ||
          !read_uint(count, "the number of elements in the block")) {
        return false;
      }
      if (count > total - seen) {
        return fail(header.line, "entity block holds " + std::to_string(count) + " elements, but only " +
                                     std::to_string(total - seen) + " of the " + std::to_string(total) +
                                     " the $Elements header announces are left");
      }
      for (std::uint64_t i = 0; i < count; ++i) {
        std::uint64_t tag = 0;
        if (!read_uint(tag, "an element tag") || !read_element_nodes(tag, type)) return false;
      }
      seen += count;
    }
    if (seen != total) {
      return fail(section_line, "$Elements header announces " + std::to_string(total) +
                                    " elements, but its blocks hold " + std::to_string(seen));
    }
    return true;
  }

  // Renumbers the nodes used by tets densely, in $Nodes order.
  Result<TetMesh> build_mesh() {
    std::vector<std::uint32_t> dense(positions_.size(), kNone);
    for (const auto& tet : tets_) {
      for (std::uint32_t v : tet) dense[v] = 0;
    }
    TetMesh mesh;
    for (std::size_t i = 0; i < positions_.size(); ++i) {
      if (dense[i] == kNone) continue;
      dense[i] = static_cast<std::uint32_t>(mesh.vertices.size());
      mesh.vertices.push_back(positions_[i]);
    }
    mesh.tets.reserve(tets_.size());
    for (const auto& tet : tets_)
      mesh.tets.push_back({dense[tet[0]], dense[tet[1]], dense[tet[2]], dense[tet[3]]});
    // check_tet_mesh says bad_parameter (a mesh given in code); here the file is at fault.
    if (Status s = check_tet_mesh(mesh, where_.file); !s) return Error(ErrorCode::bad_input_file, s.error().message());
    return mesh;
  }

  Scanner scan_;
  Where where_;
  std::string section_;
  Version version_ = Version::v41;
  std::optional<Error> error_;
  std::vector<std::uint64_t> tags_;  // $Nodes, in file order
  std::vector<Vec3d> positions_;
  NodeLookup lookup_;
  std::vector<std::array<std::uint32_t, 4>> tets_;  // indices into positions_
  std::size_t elements_line_ = 0;
  bool have_nodes_ = false;
  bool have_elements_ = false;
};

}  // namespace

Result<TetMesh> read_gmsh(const std::filesystem::path& path) {
  try {
    auto text = read_whole_file(path);
    if (!text) return text.error();
    return GmshParser(*text, path.string()).parse();
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::out_of_memory, path.string() + ": out of memory while reading the mesh");
  }
}

}  // namespace sinew
