// bench_support.h — what the scene benchmarks share: the backend they run
// on and the median they report.
#pragma once

#include <algorithm>
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

}  // namespace sinew::bench
