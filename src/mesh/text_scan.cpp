// Text scanning shared by the mesh readers; see text_scan.h.
#include "text_scan.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace sinew::detail {

namespace fs = std::filesystem;

Result<std::string> read_whole_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec))
    return Error(ErrorCode::bad_input_file, path.string() + ": cannot open file (it does not exist)");
  if (!fs::is_regular_file(path, ec)) return Error(ErrorCode::bad_input_file, path.string() + ": not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error(ErrorCode::bad_input_file, path.string() + ": cannot open file (" + std::strerror(errno) + ")");
  const auto size = fs::file_size(path, ec);
  if (ec) return Error(ErrorCode::bad_input_file, path.string() + ": cannot read file size (" + ec.message() + ")");
  std::string text;
  try {
    text.resize(static_cast<std::size_t>(size));
  } catch (const std::exception&) {  // bad_alloc or length_error: a (sparse?) file larger than memory
    return Error(ErrorCode::out_of_memory,
                 path.string() + ": " + std::to_string(size) + " bytes, more than can be allocated to read it");
  }
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) {
    return Error(ErrorCode::bad_input_file,
                 path.string() + ": read error (file shorter than its size " + std::to_string(size) + ")");
  }
  return text;
}

std::string quoted(std::string_view tok) {
  constexpr std::size_t kMax = 40;
  return "'" + std::string(tok.substr(0, kMax)) + (tok.size() > kMax ? "...'" : "'");
}

Error Where::at(std::size_t line, const std::string& what) const {
  return Error(ErrorCode::bad_input_file, file + ":" + std::to_string(line) + ": " + what);
}

bool Scanner::next(Token& t) {
  while (pos_ < text_.size() && is_space(text_[pos_])) {
    if (text_[pos_] == '\n') ++line_;
    ++pos_;
  }
  if (pos_ == text_.size()) return false;
  const std::size_t begin = pos_;
  while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
  t = {text_.substr(begin, pos_ - begin), line_};
  return true;
}

void Scanner::skip_line() {
  const std::size_t eol = text_.find('\n', pos_);
  pos_ = eol == std::string_view::npos ? text_.size() : eol;
}

std::size_t Scanner::count() const {
  Scanner rest = *this;
  Token t;
  std::size_t n = 0;
  while (rest.next(t)) ++n;
  return n;
}

namespace {

template <class Int>
bool parse_whole(std::string_view tok, Int& out) {
  const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), out);
  return ec == std::errc() && end == tok.data() + tok.size() && !tok.empty();
}

}  // namespace

bool parse_int(std::string_view tok, std::int64_t& out) {
  if (tok.size() > 1 && tok.front() == '+' && tok[1] != '-') tok.remove_prefix(1);
  return parse_whole(tok, out);
}

bool parse_uint(std::string_view tok, std::uint64_t& out) { return parse_whole(tok, out); }

Parsed parse_double(std::string_view tok, double& out) {
  if (tok.size() > 1 && tok.front() == '+' && tok[1] != '-') tok.remove_prefix(1);
  const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), out);
  if (end != tok.data() + tok.size() || tok.empty()) return Parsed::not_a_number;
  if (ec == std::errc::result_out_of_range) return Parsed::not_finite;
  if (ec != std::errc()) return Parsed::not_a_number;
  return std::isfinite(out) ? Parsed::ok : Parsed::not_finite;
}

}  // namespace sinew::detail
