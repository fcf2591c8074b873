// read_vtk: legacy VTK unstructured grids of tetrahedra, ASCII or BINARY.
//
// Format reference: "VTK File Formats" (The VTK User's Guide, Kitware;
// docs.vtk.org, design_documents/VTKFileFormats), section "Simple Legacy
// Formats", dataset UNSTRUCTURED_GRID:
//   line 1  # vtk DataFile Version x.y
//   line 2  a title (up to 256 characters)
//   line 3  ASCII | BINARY
//   DATASET UNSTRUCTURED_GRID
//   POINTS n dataType     n points, 3 coordinates each (dataType float or double here)
//   CELLS n size          per cell: its point count k, then k 0-based point indices
//                         (size = the sum over the cells of k + 1)
//   CELL_TYPES n          one type per cell (10 = VTK_TETRA, 5 = VTK_TRIANGLE, ...)
//   POINT_DATA / CELL_DATA / FIELD ...  attributes: not read (parsing stops
//                         once POINTS, CELLS and CELL_TYPES are read)
// In an ASCII file the values are whitespace-separated numbers. In a BINARY
// file they are raw big-endian values (float32 or float64 for POINTS, int32
// for CELLS and CELL_TYPES) starting right after the header line's '\n';
// a '\n' may follow the block. Keywords are matched case-insensitively, as
// VTK's own reader does. VTK_TETRA's first three points wind
// counter-clockwise seen from the fourth: sinew's positive orientation.
// VTK 5.x files whose CELLS section holds OFFSETS and CONNECTIVITY arrays
// are refused with a message saying so.
//
// The file is read whole; every length is checked before data is read.
// Error locations are "file:line" while the text can be counted in lines,
// "file: byte N" once binary data has been passed.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "sinew/mesh.h"
#include "text_scan.h"

namespace sinew {
namespace {

using detail::is_space;
using detail::parse_double;
using detail::parse_int;
using detail::parse_uint;
using detail::Parsed;
using detail::quoted;
using detail::read_whole_file;
using detail::Scanner;

constexpr std::int64_t kVtkTetra = 10;  // vtkCellType.h

// `word` equals `keyword` (given in upper case), ignoring case.
bool keyword_is(std::string_view word, std::string_view keyword) {
  return std::equal(word.begin(), word.end(), keyword.begin(), keyword.end(),
                    [](char w, char k) { return (w >= 'a' && w <= 'z' ? static_cast<char>(w - 'a' + 'A') : w) == k; });
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// A big-endian value of `bytes` (4 or 8) bytes, as a double (float32 or
// float64) or an int64 (int32).
template <class T>
T decode_big_endian(const char* p, std::size_t bytes) {
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < bytes; ++i) bits = (bits << 8) | static_cast<unsigned char>(p[i]);
  if constexpr (std::is_same_v<T, double>) {
    return bytes == 8 ? std::bit_cast<double>(bits) : std::bit_cast<float>(static_cast<std::uint32_t>(bits));
  } else {
    return std::bit_cast<std::int32_t>(static_cast<std::uint32_t>(bits));
  }
}

// A section header line, "KEYWORD arg...", and where it is.
struct Header {
  std::string at;  // "file:line" or "file: byte N"
  std::string_view line;
  std::vector<std::string_view> words;  // words[0] is the keyword
};

class VtkParser {
 public:
  VtkParser(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {}

  Result<TetMesh> parse() {
    if (!read_preamble() || !read_sections() || !collect_tets()) return *error_;
    TetMesh mesh{std::move(points_), std::move(tets_)};
    // Checked before the unused points are dropped, so that messages give
    // the file's point indices. check_tet_mesh says bad_parameter (a mesh
    // given in code); here the file is at fault.
    if (Status s = check_tet_mesh(mesh, file_); !s) return Error(ErrorCode::bad_input_file, s.error().message());
    return drop_unused_vertices(mesh);
  }

 private:
  bool fail(const std::string& at, const std::string& what) {
    error_ = Error(ErrorCode::bad_input_file, at + ": " + what);
    return false;
  }

  std::string here() const {
    return lines_known_ ? file_ + ":" + std::to_string(line_) : file_ + ": byte " + std::to_string(pos_);
  }

  void skip_space() {
    for (; pos_ < text_.size() && is_space(text_[pos_]); ++pos_) {
      if (text_[pos_] == '\n') ++line_;
    }
  }

  // The rest of the current line (without its '\n'); moves past the '\n'.
  std::string_view read_line() {
    const std::size_t eol = std::min(text_.find('\n', pos_), text_.size());
    const std::string_view line = text_.substr(pos_, eol - pos_);
    pos_ = std::min(eol + 1, text_.size());
    ++line_;
    return line;
  }

  // The next non-blank line as a section header; false at the end of the file.
  bool next_header(Header& h) {
    skip_space();
    if (pos_ == text_.size()) return false;
    h.at = here();
    h.line = trim(read_line());
    Scanner words(h.line);
    std::string_view w;
    while (words.next(w)) h.words.push_back(w);
    return true;
  }

  bool expect_words(const Header& h, std::size_t count, const char* layout) {
    if (h.words.size() == count) return true;
    return fail(h.at, std::string("expected '") + layout + "', found " + quoted(h.line));
  }

  bool count_word(const Header& h, std::size_t i, std::uint64_t& n) {
    if (parse_uint(h.words[i], n)) return true;
    return fail(h.at, std::string(h.words[0]) + ": expected a count, found " + quoted(h.words[i]));
  }

  bool read_preamble() {
    const std::string_view magic = trim(read_line());
    if (magic.substr(0, 22) != "# vtk DataFile Version") {
      return fail(file_ + ":1", "not a legacy VTK file: line 1 is " + quoted(magic) +
                                    ", expected '# vtk DataFile Version x.y'");
    }
    read_line();  // the title
    const std::string_view format = trim(read_line());
    binary_ = keyword_is(format, "BINARY");
    if (!binary_ && !keyword_is(format, "ASCII"))
      return fail(file_ + ":3", "expected ASCII or BINARY on line 3, found " + quoted(format));
    Header h;
    if (!next_header(h)) return fail(here(), "file ends before DATASET UNSTRUCTURED_GRID");
    if (!keyword_is(h.words[0], "DATASET"))
      return fail(h.at, "expected DATASET UNSTRUCTURED_GRID, found " + quoted(h.line));
    if (h.words.size() != 2 || !keyword_is(h.words[1], "UNSTRUCTURED_GRID")) {
      return fail(h.at, "the dataset is " + quoted(trim(h.line.substr(h.words[0].size()))) +
                            "; only DATASET UNSTRUCTURED_GRID holds tetrahedra");
    }
    return true;
  }

  const char* first_missing() const {
    return !have_points_ ? "POINTS" : !have_cells_ ? "CELLS" : "CELL_TYPES";
  }

  bool read_sections() {
    while (!have_points_ || !have_cells_ || !have_types_) {
      Header h;
      if (!next_header(h)) return fail(here(), std::string("file ends without a ") + first_missing() + " section");
      const std::string_view key = h.words[0];
      bool ok = false;
      if (keyword_is(key, "POINTS")) {
        ok = read_points(h);
      } else if (keyword_is(key, "CELLS")) {
        ok = read_cells(h);
      } else if (keyword_is(key, "CELL_TYPES")) {
        ok = read_types(h);
      } else {
        return fail(h.at, "expected POINTS, CELLS or CELL_TYPES, found " + quoted(key) + " (the " + first_missing() +
                              " section is missing)");
      }
      if (!ok) return false;
    }
    return true;
  }

  // Reads the `count` values that follow the header `h`: ASCII numbers, or
  // big-endian binary values of `bytes` bytes each.
  template <class T>
  bool read_values(const Header& h, std::uint64_t count, std::size_t bytes, std::vector<T>& out) {
    const std::string section(h.words[0]);
    if (binary_) {
      const std::size_t left = text_.size() - pos_;
      if (count > left / bytes) {
        return fail(h.at, section + ": binary data truncated: " + std::to_string(count) + " values of " +
                              std::to_string(bytes) + " bytes each, but the file has only " + std::to_string(left) +
                              " bytes left");
      }
      out.resize(static_cast<std::size_t>(count));
      const char* data = text_.data() + pos_;
      for (std::size_t i = 0; i < out.size(); ++i) out[i] = decode_big_endian<T>(data + i * bytes, bytes);
      pos_ += out.size() * bytes;
      lines_known_ = false;
      return true;
    }
    // Reserve no more than the file could hold, whatever the header claims.
    out.reserve(static_cast<std::size_t>(std::min<std::uint64_t>(count, (text_.size() - pos_) / 2 + 1)));
    for (std::uint64_t i = 0; i < count; ++i) {
      skip_space();
      if (pos_ == text_.size()) {
        return fail(here(), section + ": file ends after " + std::to_string(i) + " of the " + std::to_string(count) +
                                " values its header announces");
      }
      const std::size_t begin = pos_;
      while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
      const std::string_view tok = text_.substr(begin, pos_ - begin);
      T v{};
      Parsed parsed = Parsed::ok;
      if constexpr (std::is_same_v<T, double>) {
        parsed = parse_double(tok, v);
      } else if (!parse_int(tok, v)) {
        parsed = Parsed::not_a_number;
      }
      if (parsed == Parsed::not_finite) return fail(here(), section + ": non-finite coordinate " + quoted(tok));
      if (parsed != Parsed::ok) {
        // A keyword here means the section is shorter than its header says.
        const bool keyword = (tok.front() >= 'A' && tok.front() <= 'Z') || (tok.front() >= 'a' && tok.front() <= 'z');
        return fail(here(), section + ": expected value " + std::to_string(i + 1) + " of " + std::to_string(count) +
                                ", found " + quoted(tok) +
                                (keyword ? " (fewer values than its header announces)" : ""));
      }
      out.push_back(v);
    }
    return true;
  }

  bool read_points(const Header& h) {
    if (have_points_) return fail(h.at, "second POINTS section");
    std::uint64_t n = 0;
    if (!expect_words(h, 3, "POINTS n float|double") || !count_word(h, 1, n)) return false;
    const bool is_double = keyword_is(h.words[2], "DOUBLE");
    if (!is_double && !keyword_is(h.words[2], "FLOAT"))
      return fail(h.at, "POINTS data type " + quoted(h.words[2]) + " is not supported (float or double)");
    if (n >= std::numeric_limits<std::uint32_t>::max())
      return fail(h.at, std::to_string(n) + " points do not fit 32-bit indices");
    std::vector<double> xyz;
    if (!read_values(h, 3 * n, is_double ? 8 : 4, xyz)) return false;
    points_.resize(static_cast<std::size_t>(n));
    for (std::size_t i = 0; i < points_.size(); ++i) {
      points_[i] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
      if (!std::isfinite(xyz[3 * i]) || !std::isfinite(xyz[3 * i + 1]) || !std::isfinite(xyz[3 * i + 2]))
        return fail(h.at, "POINTS: point " + std::to_string(i) + " has a non-finite coordinate");
    }
    have_points_ = true;
    return true;
  }

  // VTK 5.x writes "CELLS n+1 size" followed by OFFSETS and CONNECTIVITY arrays.
  bool offsets_follow() const {
    std::size_t p = pos_;
    while (p < text_.size() && is_space(text_[p])) ++p;
    return keyword_is(text_.substr(p, 7), "OFFSETS");
  }

  bool read_cells(const Header& h) {
    if (have_cells_) return fail(h.at, "second CELLS section");
    std::uint64_t n = 0, size = 0;
    if (!expect_words(h, 3, "CELLS n size") || !count_word(h, 1, n) || !count_word(h, 2, size)) return false;
    if (offsets_follow()) {
      return fail(h.at, "CELLS in the VTK 5 layout (OFFSETS and CONNECTIVITY arrays) is not supported; "
                        "save the mesh as legacy VTK 4.2");
    }
    if (!read_values(h, size, 4, cells_)) return false;
    const std::string rule = " (size must be the sum over the cells of their point count + 1)";
    std::size_t next = 0;
    cell_starts_.reserve(static_cast<std::size_t>(std::min(n, size)));
    for (std::uint64_t i = 0; i < n; ++i) {
      if (next == cells_.size()) {
        return fail(h.at, "CELLS: its size " + std::to_string(size) + " ends after " + std::to_string(i) + " of its " +
                              std::to_string(n) + " cells" + rule);
      }
      const std::int64_t k = cells_[next];
      if (k < 0) {
        return fail(h.at, "CELLS: cell " + std::to_string(i) + " has a negative point count " + std::to_string(k));
      }
      if (static_cast<std::uint64_t>(k) >= cells_.size() - next) {
        return fail(h.at, "CELLS: cell " + std::to_string(i) + " has " + std::to_string(k) +
                              " points, which run past its size " + std::to_string(size) + rule);
      }
      cell_starts_.push_back(next);
      next += 1 + static_cast<std::size_t>(k);
    }
    if (next != cells_.size()) {
      return fail(h.at, "CELLS: its size is " + std::to_string(size) + ", but its " + std::to_string(n) +
                            " cells take " + std::to_string(next) + rule);
    }
    cells_at_ = h.at;
    have_cells_ = true;
    return true;
  }

  bool read_types(const Header& h) {
    if (have_types_) return fail(h.at, "second CELL_TYPES section");
    std::uint64_t n = 0;
    if (!expect_words(h, 2, "CELL_TYPES n") || !count_word(h, 1, n) || !read_values(h, n, 4, types_)) return false;
    types_at_ = h.at;
    have_types_ = true;
    return true;
  }

  // Checks every cell's point indices and keeps the tetrahedra.
  bool collect_tets() {
    if (types_.size() != cell_starts_.size()) {
      return fail(types_at_, "CELL_TYPES holds " + std::to_string(types_.size()) + " cell types, but CELLS holds " +
                                 std::to_string(cell_starts_.size()) + " cells");
    }
    const std::size_t n = points_.size();
    for (std::size_t i = 0; i < cell_starts_.size(); ++i) {
      const std::size_t start = cell_starts_[i];
      const auto k = static_cast<std::size_t>(cells_[start]);
      for (std::size_t j = 1; j <= k; ++j) {
        const std::int64_t v = cells_[start + j];
        if (v < 0 || static_cast<std::uint64_t>(v) >= n) {
          return fail(cells_at_, "CELLS: cell " + std::to_string(i) + " refers to point " + std::to_string(v) +
                                     ", but POINTS holds " + std::to_string(n) + " points (indices 0.." +
                                     std::to_string(static_cast<std::int64_t>(n) - 1) + ")");
        }
      }
      if (types_[i] != kVtkTetra) continue;
      if (k != 4) {
        return fail(cells_at_, "CELLS: cell " + std::to_string(i) + " has type 10 (VTK_TETRA) but " +
                                   std::to_string(k) + " points, not 4");
      }
      std::array<std::uint32_t, 4> tet{};
      for (std::size_t j = 0; j < 4; ++j) tet[j] = static_cast<std::uint32_t>(cells_[start + 1 + j]);
      tets_.push_back(tet);
    }
    if (tets_.empty()) {
      return fail(types_at_, "no tetrahedra: none of the " + std::to_string(types_.size()) +
                                 " cells has type 10 (VTK_TETRA)");
    }
    return true;
  }

  std::string_view text_;
  std::string file_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
  bool binary_ = false;
  bool lines_known_ = true;  // false once binary data has been passed
  std::optional<Error> error_;
  std::vector<Vec3d> points_;
  std::vector<std::int64_t> cells_;  // CELLS values as in the file
  std::vector<std::size_t> cell_starts_;  // index in cells_ of each cell's point count
  std::vector<std::int64_t> types_;
  std::vector<std::array<std::uint32_t, 4>> tets_;
  std::string cells_at_, types_at_;
  bool have_points_ = false, have_cells_ = false, have_types_ = false;
};

}  // namespace

Result<TetMesh> read_vtk(const std::filesystem::path& path) {
  try {
    auto text = read_whole_file(path);
    if (!text) return text.error();
    return VtkParser(*text, path.string()).parse();
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::out_of_memory, path.string() + ": out of memory while reading the mesh");
  }
}

}  // namespace sinew
