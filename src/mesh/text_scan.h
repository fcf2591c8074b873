// text_scan.h — internal to the mesh readers (tetgen_reader.cpp,
// gmsh_reader.cpp); not part of the public API.
//
// Reading a whole file into memory, splitting text into whitespace-separated
// tokens with their 1-based line numbers, and strict number parsing with
// std::from_chars (no streams, no locale, no per-token allocation).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "sinew/result.h"

namespace sinew::detail {

/// [out] the file's bytes; errors name the path (missing, not a regular
/// file, unreadable, short read); out_of_memory when its size cannot be
/// allocated.
Result<std::string> read_whole_file(const std::filesystem::path& path);

/// Space, tab, CR, LF, VT, FF.
inline bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

/// A token in single quotes, cut to 40 characters (keeps messages short
/// for binary junk).
std::string quoted(std::string_view tok);

/// Formats errors as "file:line: what".
struct Where {
  std::string file;
  Error at(std::size_t line, const std::string& what) const;
};

struct Token {
  std::string_view text;
  std::size_t line = 0;  ///< 1-based
};

/// Whitespace-separated tokens of `text` with their line numbers.
class Scanner {
 public:
  explicit Scanner(std::string_view text) : text_(text) {}

  bool next(Token& t);
  bool next(std::string_view& tok) {
    Token t;
    if (!next(t)) return false;
    tok = t.text;
    return true;
  }
  /// Skips the rest of the current line.
  void skip_line();
  /// The tokens not yet read.
  std::size_t count() const;
  /// The line the scanner has reached.
  std::size_t line() const { return line_; }
  /// Characters not yet read.
  std::size_t remaining() const { return text_.size() - pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
};

/// The whole token is an integer (a leading '+' is allowed).
bool parse_int(std::string_view tok, std::int64_t& out);
/// The whole token is an unsigned integer.
bool parse_uint(std::string_view tok, std::uint64_t& out);

enum class Parsed { ok, not_a_number, not_finite };

/// The whole token is a number. from_chars accepts "nan" and "inf"; they
/// are reported as not_finite rather than as garbage, and so is overflow
/// (1e999).
Parsed parse_double(std::string_view tok, double& out);

}  // namespace sinew::detail
