// benchmark_queries.cpp — reading the CCD benchmark's query files (see
// benchmark_queries.h).
#include "ccd/benchmark_queries.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace sinew::ccd {
namespace {

// A power of two written in decimal (up to 2^1023): its exponent, or -1.
int power_of_two(const std::string& digits) {
  if (digits.empty() || digits.size() > 310 || digits[0] == '-' || digits[0] == '+') return -1;
  for (char ch : digits)
    if (ch < '0' || ch > '9') return -1;
  // Divide the decimal string by 2 until it is 1; any odd remainder on the way: not a power.
  std::string n = digits;
  int exponent = 0;
  while (!(n.size() == 1 && n[0] == '1')) {
    if (n == "0") return -1;
    if ((n.back() - '0') % 2 != 0) return -1;
    std::string half;
    int carry = 0;
    for (char ch : n) {
      const int value = carry * 10 + (ch - '0');
      half.push_back(char('0' + value / 2));
      carry = value % 2;
    }
    const auto first = half.find_first_not_of('0');
    n = first == std::string::npos ? "0" : half.substr(first);
    ++exponent;
  }
  return exponent;
}

Error bad(const std::string& file, std::size_t row, const std::string& why) {
  return Error(ErrorCode::bad_input_file, file + ", row " + std::to_string(row) + ": " + why);
}

}  // namespace

Result<std::vector<BenchmarkQuery>> read_benchmark_queries(const std::filesystem::path& root) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(root, ec))
    return Error(ErrorCode::bad_input_file, "ccd queries: " + root.string() + " is not a folder");
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(root, ec))
    if (entry.is_regular_file() && entry.path().extension() == ".csv") files.push_back(entry.path());
  if (ec) return Error(ErrorCode::bad_input_file, "ccd queries: cannot list " + root.string() + ": " + ec.message());
  if (files.empty()) return Error(ErrorCode::bad_input_file, "ccd queries: no .csv file under " + root.string());
  std::sort(files.begin(), files.end());
  std::vector<BenchmarkQuery> queries;
  for (const fs::path& path : files) {
    const std::string kind = path.parent_path().filename().string();
    const std::string name = fs::relative(path, root, ec).string();
    if (kind != "vertex-face" && kind != "edge-edge")
      return Error(ErrorCode::bad_input_file, "ccd queries: " + name + " is in neither a vertex-face nor an edge-edge folder");
    std::ifstream in(path);
    if (!in) return Error(ErrorCode::bad_input_file, "ccd queries: cannot open " + path.string());
    std::string line;
    std::size_t row = 0;
    BenchmarkQuery q;
    q.vertex_face = kind == "vertex-face";
    q.file = name;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.empty()) continue;
      ++row;
      std::vector<std::string> cols;
      std::stringstream split(line);
      for (std::string col; std::getline(split, col, ',');) cols.push_back(col);
      if (cols.size() != 7) return bad(name, row, std::to_string(cols.size()) + " columns, not 7");
      double point[3];
      for (int k = 0; k < 3; ++k) {
        std::int64_t numerator = 0;
        const std::string& n = cols[std::size_t(2 * k)];
        const auto [end, err] = std::from_chars(n.data(), n.data() + n.size(), numerator);
        if (err != std::errc() || end != n.data() + n.size())
          return bad(name, row, "numerator '" + n + "' is not an integer of 64 bits");
        if (numerator > (std::int64_t{1} << 53) || numerator < -(std::int64_t{1} << 53))
          return bad(name, row, "numerator " + n + " has more than 53 bits: not exact in a double");
        const int exponent = power_of_two(cols[std::size_t(2 * k + 1)]);
        if (exponent < 0) return bad(name, row, "denominator '" + cols[std::size_t(2 * k + 1)] + "' is not a positive power of two");
        point[k] = std::ldexp(double(numerator), -exponent);
      }
      const std::string& t = cols[6];
      if (t != "0" && t != "1") return bad(name, row, "truth bit '" + t + "' is neither 0 nor 1");
      const std::size_t slot = (row - 1) % 8;
      if (slot == 0) q.truth = t == "1";
      else if (q.truth != (t == "1")) return bad(name, row, "the truth bit differs within a query");
      q.points[slot] = {point[0], point[1], point[2]};
      if (slot == 7) queries.push_back(q);
    }
    if (row % 8 != 0) return bad(name, row, std::to_string(row) + " rows, not a multiple of 8");
  }
  return queries;
}

Result<Hit> run_query(const BenchmarkQuery& q, const Settings& settings) {
  const auto& x = q.points;
  if (q.vertex_face) return vertex_face({x[0], x[4]}, {x[1], x[5]}, {x[2], x[6]}, {x[3], x[7]}, settings);
  return edge_edge({x[0], x[4]}, {x[1], x[5]}, {x[2], x[6]}, {x[3], x[7]}, settings);
}

}  // namespace sinew::ccd
