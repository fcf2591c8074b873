// fuzz_ccd_queries.cpp — libFuzzer target for ccd::read_benchmark_queries
// (the CCD benchmark's query CSVs). Input: the first byte picks the folder
// (even: vertex-face, odd: edge-edge), the rest is the .csv file. Checked:
// a documented error, or queries that run_query answers (the first few,
// with a small box budget so one input stays fast) with a time in [0, 1].
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

#include "ccd/benchmark_queries.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sinew;
  if (size == 0) return 0;
  const std::filesystem::path root = fuzz::scratch_dir() / "queries";
  const std::filesystem::path folder = root / "scene" / (data[0] % 2 == 0 ? "vertex-face" : "edge-edge");
  std::error_code ec;
  std::filesystem::remove_all(root, ec);
  std::filesystem::create_directories(folder);
  fuzz::write_file(folder / "data_0_0.csv", {reinterpret_cast<const char*>(data) + 1, size - 1});
  const auto queries = ccd::read_benchmark_queries(root);
  if (!queries) {
    fuzz::check_error(queries.error(), {ErrorCode::bad_input_file}, "read_benchmark_queries");
    return 0;
  }
  fuzz::note("read_benchmark_queries: " + std::to_string(queries->size()) + " queries");
  ccd::Settings settings;
  settings.max_boxes = 4096;
  std::size_t n = 0;
  for (const ccd::BenchmarkQuery& q : *queries) {
    if (n++ == 4) break;
    for (const auto& p : q.points)
      for (double c : p)
        if (!std::isfinite(c)) fuzz::fail("read_benchmark_queries returned a non-finite coordinate");
    const Result<ccd::Hit> hit = ccd::run_query(q, settings);
    if (!hit) {  // coordinates too large for the exact arithmetic are refused by name
      fuzz::check_error(hit.error(), {ErrorCode::bad_parameter}, "run_query");
      continue;
    }
    if (!(hit->time >= 0.0 && hit->time <= 1.0)) fuzz::fail("run_query returned a time outside [0, 1]");
  }
  return 0;
}
