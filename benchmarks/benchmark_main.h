// benchmark_main.h — main() for the Google Benchmark programs: Google
// Benchmark's own command line (--benchmark_filter, --benchmark_out, ...)
// with a --help that first says what the program measures, and an unknown
// option an error with exit status 2, as for the examples.
//
//   SINEW_BENCHMARK_MAIN("bench_cube", "A 1 m cube hanging from its top face ...");
#pragma once

#include <benchmark/benchmark.h>

#include <cstdio>

namespace sinew::bench {

/// Runs the registered benchmarks; [in] name and about head --help.
/// Returns the exit status: 0 (--help included), 2 for an unknown option.
inline int run_benchmarks(int argc, char** argv, const char* name, const char* about) {
  // Google Benchmark's help printer takes no arguments: the text waits here.
  static const char* help_name = nullptr;
  static const char* help_about = nullptr;
  help_name = name;
  help_about = about;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  benchmark::Initialize(&argc, argv, [] {
    std::printf("%s\nUsage: %s [--benchmark_filter=REGEX] [--benchmark_out=FILE --benchmark_out_format=csv] ...\n\n"
                "Backend: the environment variable SINEW_BACKEND (auto, cpu, opencl, vulkan; default auto),\n"
                "for the benchmarks that take one. Google Benchmark's options:\n",
                help_about, help_name);
    benchmark::PrintDefaultHelp();
  });
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace sinew::bench

/// main() for a Google Benchmark program named `name`, measuring `about`.
#define SINEW_BENCHMARK_MAIN(name, about) \
  int main(int argc, char** argv) { return sinew::bench::run_benchmarks(argc, argv, name, about); }
