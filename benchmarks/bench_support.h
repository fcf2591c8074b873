// bench_support.h — what the scene benchmarks share: the backend they run
// on and the median and percentiles they report.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

namespace sinew::bench {

/// The backend named by SINEW_BACKEND (cpu, opencl, vulkan; default auto).
inline std::string backend() {
  const char* v = std::getenv("SINEW_BACKEND");
  return v ? v : "auto";
}

/// The median of `v` (the upper one of an even count; 0 when empty).
inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// The q-quantile of `v` (q in [0, 1]; nearest rank: the smallest value
/// with at least q of the values at or below it; 0 when empty).
inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t k = static_cast<std::size_t>(std::ceil(q * double(v.size())));
  return v[std::min(v.size() - 1, k == 0 ? 0 : k - 1)];
}

}  // namespace sinew::bench
