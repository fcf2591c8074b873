// read_tetgen and read_tet_mesh.
//
// Format reference: TetGen user manual (H. Si, "TetGen, a Quality
// Tetrahedral Mesh Generator and 3D Delaunay Triangulator", version 1.5),
// chapter "File Formats", sections on .node and .ele files:
//   .node  first line: <# of points> <dimension (3)> <# of attributes> <# of boundary markers (0 or 1)>
//          then per point: <point #> <x> <y> <z> [attributes] [boundary marker]
//   .ele   first line: <# of tetrahedra> <nodes per tetrahedron (4 or 10)> <# of attributes>
//          then per tet: <tetrahedron #> <node> <node> <node> <node> ... [attributes]
//   Blank lines and everything after '#' are ignored. Points are numbered
//   consecutively from 0 or 1 (the first point's number decides); tets
//   refer to points by those numbers. For 10-node tets the first four
//   nodes are the corners.
//
// Speed: the files are read whole and parsed in place with std::from_chars
// (text_scan.h: no streams, no per-line strings), so liver_382k (18 MB)
// parses in a fraction of a second.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include "sinew/mesh.h"
#include "text_scan.h"

namespace sinew {
namespace {

namespace fs = std::filesystem;
using detail::is_space;
using detail::parse_double;
using detail::parse_int;
using detail::Parsed;
using detail::quoted;
using detail::read_whole_file;
using detail::Scanner;
using detail::Where;

// One line that holds data (comment removed) and its 1-based number.
struct Record {
  std::string_view text;
  std::size_t line = 0;
};

// Yields the data lines of a file, skipping blank and comment-only lines.
class RecordReader {
 public:
  explicit RecordReader(std::string_view text) : text_(text) {}

  bool next(Record& r) {
    while (pos_ < text_.size()) {
      const std::size_t eol = std::min(text_.find('\n', pos_), text_.size());
      std::string_view line = text_.substr(pos_, eol - pos_);
      pos_ = eol + 1;
      ++line_;
      if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      if (std::any_of(line.begin(), line.end(), [](char c) { return !is_space(c); })) {
        r = {line, line_};
        return true;
      }
    }
    return false;
  }
  /// The number of the last line read (the file's last line once next() failed).
  std::size_t line() const { return std::max<std::size_t>(line_, 1); }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_ = 0;
};

// Reads the header's integer fields; missing trailing fields keep their
// defaults, as in TetGen.
Status read_header(RecordReader& reader, const Where& where, const char* layout,
                   std::vector<std::int64_t>& fields, std::size_t& line) {
  Record r;
  if (!reader.next(r)) {
    return where.at(reader.line(), std::string("empty file, expected the header '") + layout + "'");
  }
  line = r.line;
  Scanner tokens(r.text);
  std::string_view tok;
  for (std::int64_t& f : fields) {
    if (!tokens.next(tok)) break;
    if (!parse_int(tok, f)) {
      return where.at(
          r.line, "expected an integer in the header '" + std::string(layout) + "', found " + quoted(tok));
    }
  }
  return {};
}

// The parts of a .node file the mesh needs.
struct NodeFile {
  std::vector<Vec3d> points;
  std::int64_t first_number = 0;
};

struct NodeHeader {
  std::int64_t count = 0, attributes = 0, markers = 0;
  std::size_t line = 0;
};

Status check_node_header(const std::vector<std::int64_t>& f, const Where& where, NodeHeader& h) {
  std::size_t line = h.line;
  if (f[0] < 1) {
    return where.at(line, "the header announces " + std::to_string(f[0]) +
                              " points (need >= 1; points in a .poly file are not supported)");
  }
  if (f[0] > std::numeric_limits<std::uint32_t>::max()) {
    return where.at(line, std::to_string(f[0]) + " points do not fit 32-bit vertex indices");
  }
  if (f[1] != 3) {
    return where.at(line, "node dimension must be 3 (got " + std::to_string(f[1]) + ")");
  }
  if (f[2] < 0 || f[2] > 1000) {
    return where.at(line, "bad number of point attributes " + std::to_string(f[2]));
  }
  if (f[3] != 0 && f[3] != 1) {
    return where.at(line, "number of boundary markers must be 0 or 1 (got " + std::to_string(f[3]) + ")");
  }
  h.count = f[0];
  h.attributes = f[2];
  h.markers = f[3];
  return {};
}

// Parses "<point #> <x> <y> <z> [attributes] [marker]".
Status parse_node_line(const Record& r, const NodeHeader& h, const Where& where, std::int64_t& number,
                       Vec3d& p) {
  Scanner tokens(r.text);
  const std::size_t expected = static_cast<std::size_t>(4 + h.attributes + h.markers);
  const std::size_t got = tokens.count();
  if (got != expected) {
    return where.at(r.line, "node line has " + std::to_string(got) + " values, expected " +
                                std::to_string(expected) + " (number, x, y, z, " +
                                std::to_string(h.attributes) + " attributes, " + std::to_string(h.markers) +
                                " markers, per the header on line " + std::to_string(h.line) + ")");
  }
  std::string_view tok;
  tokens.next(tok);
  if (!parse_int(tok, number)) return where.at(r.line, "expected a point number, found " + quoted(tok));
  for (std::size_t i = 0; i + 1 < expected; ++i) {
    tokens.next(tok);
    double value = 0.0;
    const Parsed parsed = parse_double(tok, value);
    if (parsed == Parsed::not_a_number) {
      return where.at(r.line, "expected a number, found " + quoted(tok));
    }
    // Attributes and markers may be anything numeric; coordinates must be finite.
    if (i < 3 && parsed == Parsed::not_finite) {
      return where.at(r.line, "non-finite coordinate " + quoted(tok));
    }
    if (i < 3) p[i] = value;
  }
  return {};
}

Status read_node_file(const fs::path& path, NodeFile& out) {
  auto text = read_whole_file(path);
  if (!text) return text.error();
  const Where where{path.string()};
  RecordReader reader(*text);
  std::vector<std::int64_t> fields{0, 3, 0, 0};
  NodeHeader h;
  if (Status s = read_header(reader, where, "<#points> <dimension> <#attributes> <#markers>", fields, h.line);
      !s) {
    return s;
  }
  if (Status s = check_node_header(fields, where, h); !s) return s;
  // A bogus header count must not trigger a huge allocation: a point line
  // has at least 8 characters.
  out.points.reserve(std::min<std::size_t>(static_cast<std::size_t>(h.count), text->size() / 8 + 1));
  Record r;
  for (std::int64_t i = 0; i < h.count; ++i) {
    if (!reader.next(r)) {
      return where.at(reader.line(), "file ends after " + std::to_string(i) + " of the " +
                                         std::to_string(h.count) +
                                         " points announced by the header on line " + std::to_string(h.line));
    }
    std::int64_t number = 0;
    Vec3d p{};
    if (Status s = parse_node_line(r, h, where, number, p); !s) return s;
    if (i == 0) {
      if (number != 0 && number != 1) {
        return where.at(r.line,
                        "the first point must be numbered 0 or 1 (got " + std::to_string(number) + ")");
      }
      out.first_number = number;
    } else if (number != out.first_number + i) {
      return where.at(r.line, "point number " + std::to_string(number) + ", expected " +
                                  std::to_string(out.first_number + i) +
                                  " (points must be numbered consecutively)");
    }
    out.points.push_back(p);
  }
  if (reader.next(r)) {
    return where.at(r.line, "more points than the " + std::to_string(h.count) +
                                " announced by the header on line " + std::to_string(h.line));
  }
  return {};
}

struct EleHeader {
  std::int64_t count = 0, nodes_per_tet = 4, attributes = 0;
  std::size_t line = 0;
};

Status check_ele_header(const std::vector<std::int64_t>& f, const Where& where, EleHeader& h) {
  if (f[0] < 1) {
    return where.at(h.line, "the header announces " + std::to_string(f[0]) + " tetrahedra (need >= 1)");
  }
  if (f[1] != 4 && f[1] != 10) {
    return where.at(h.line, "nodes per tetrahedron must be 4 or 10 (got " + std::to_string(f[1]) + ")");
  }
  if (f[2] < 0 || f[2] > 1000) {
    return where.at(h.line, "bad number of tetrahedron attributes " + std::to_string(f[2]));
  }
  h.count = f[0];
  h.nodes_per_tet = f[1];
  h.attributes = f[2];
  return {};
}

// Parses "<tet #> <node> x4 or x10 [attributes]" into 0-based corners.
Status parse_ele_line(const Record& r, const EleHeader& h, const NodeFile& nodes, const Where& where,
                      std::array<std::uint32_t, 4>& tet) {
  Scanner tokens(r.text);
  const std::size_t expected = static_cast<std::size_t>(1 + h.nodes_per_tet + h.attributes);
  const std::size_t got = tokens.count();
  if (got != expected) {
    return where.at(r.line, "tetrahedron line has " + std::to_string(got) + " values, expected " +
                                std::to_string(expected) + " (number, " + std::to_string(h.nodes_per_tet) +
                                " nodes, " + std::to_string(h.attributes) +
                                " attributes, per the header on line " + std::to_string(h.line) + ")");
  }
  std::string_view tok;
  std::int64_t value = 0;
  tokens.next(tok);
  if (!parse_int(tok, value)) return where.at(r.line, "expected a tetrahedron number, found " + quoted(tok));
  const std::int64_t first = nodes.first_number;
  const std::int64_t last = first + static_cast<std::int64_t>(nodes.points.size()) - 1;
  for (std::int64_t k = 0; k < h.nodes_per_tet; ++k) {
    tokens.next(tok);
    if (!parse_int(tok, value)) return where.at(r.line, "expected a node number, found " + quoted(tok));
    if (value < first || value > last) {
      return where.at(r.line, "node number " + std::to_string(value) +
                                  " is out of range (the .node file numbers its points " +
                                  std::to_string(first) + ".." + std::to_string(last) + ")");
    }
    if (k < 4) tet[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(value - first);
  }
  for (std::int64_t k = 0; k < h.attributes; ++k) {
    tokens.next(tok);
    double attribute = 0.0;
    if (parse_double(tok, attribute) == Parsed::not_a_number) {
      return where.at(r.line, "expected a number, found " + quoted(tok));
    }
  }
  return {};
}

Status read_ele_file(const fs::path& path, const NodeFile& nodes,
                     std::vector<std::array<std::uint32_t, 4>>& tets) {
  auto text = read_whole_file(path);
  if (!text) return text.error();
  const Where where{path.string()};
  RecordReader reader(*text);
  std::vector<std::int64_t> fields{0, 4, 0};
  EleHeader h;
  if (Status s = read_header(reader, where, "<#tetrahedra> <nodes per tet> <#attributes>", fields, h.line);
      !s) {
    return s;
  }
  if (Status s = check_ele_header(fields, where, h); !s) return s;
  tets.reserve(std::min<std::size_t>(static_cast<std::size_t>(h.count), text->size() / 10 + 1));
  Record r;
  for (std::int64_t i = 0; i < h.count; ++i) {
    if (!reader.next(r)) {
      return where.at(reader.line(),
                      "file ends after " + std::to_string(i) + " of the " + std::to_string(h.count) +
                          " tetrahedra announced by the header on line " + std::to_string(h.line));
    }
    std::array<std::uint32_t, 4> tet{};
    if (Status s = parse_ele_line(r, h, nodes, where, tet); !s) return s;
    tets.push_back(tet);
  }
  if (reader.next(r)) {
    return where.at(r.line, "more tetrahedra than the " + std::to_string(h.count) +
                                " announced by the header on line " + std::to_string(h.line));
  }
  return {};
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c); });
  return s;
}

// "mesh.node", "mesh.ele" and "mesh" all name the pair mesh.node + mesh.ele.
void tetgen_paths(const fs::path& path, fs::path& node, fs::path& ele) {
  const std::string ext = lower(path.extension().string());
  if (ext == ".node" || ext == ".ele") {
    node = path;
    node.replace_extension(".node");
    ele = path;
    ele.replace_extension(".ele");
  } else {
    node = path;
    node += ".node";
    ele = path;
    ele += ".ele";
  }
}

}  // namespace

Result<TetMesh> read_tetgen(const std::filesystem::path& path) {
  fs::path node_path, ele_path;
  tetgen_paths(path, node_path, ele_path);
  try {
    NodeFile nodes;
    if (Status s = read_node_file(node_path, nodes); !s) return s.error();
    TetMesh mesh;
    if (Status s = read_ele_file(ele_path, nodes, mesh.tets); !s) return s.error();
    mesh.vertices = std::move(nodes.points);
    // check_tet_mesh says bad_parameter (a mesh given in code); here the file is at fault.
    if (Status s = check_tet_mesh(mesh, ele_path.string()); !s)
      return Error(ErrorCode::bad_input_file, s.error().message());
    return mesh;
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::out_of_memory, path.string() + ": out of memory while reading the mesh");
  }
}

Result<TetMesh> read_tet_mesh(const std::filesystem::path& path) {
  const std::string ext = lower(path.extension().string());
  if (ext == ".msh") return read_gmsh(path);
  if (ext == ".node" || ext == ".ele") return read_tetgen(path);
  if (ext == ".vtk") return read_vtk(path);
  return Error(ErrorCode::bad_input_file,
               path.string() + ": unknown tet mesh extension '" + path.extension().string() +
               "' (expected .msh, .node, .ele or .vtk)");
}

}  // namespace sinew
