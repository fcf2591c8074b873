// benchmark_queries.h — the CCD benchmark's query files (Wang et al., "A
// Large Scale Benchmark and an Inclusion-Based Algorithm for Continuous
// Collision Detection", TOG 2021; data/ccd/handcrafted/FORMAT.md): 8 rows
// per query of exact rational coordinates and the ground-truth bit. Read by
// the CCD test (0 false negatives) and the CCD benchmark.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "sinew/ccd.h"
#include "sinew/result.h"

namespace sinew::ccd {

struct BenchmarkQuery {
  bool vertex_face = true;  ///< else edge-edge
  /// The 8 points in the file's order: vertex-face v, f0, f1, f2 at t0,
  /// then at t1; edge-edge ea0, ea1, eb0, eb1 at t0, then at t1.
  std::array<Point, 8> points{};
  bool truth = false;  ///< the exact answer: the primitives touch in [0, 1]
  std::string file;    ///< where it came from (scene/kind/data_i_j.csv)
};

/// Every query of every `<scene>/<kind>/*.csv` under `root` (kind
/// vertex-face or edge-edge), files in sorted order. Coordinates are
/// read exactly: numerators of at most 53 bits over power-of-two
/// denominators (FORMAT.md). Errors (bad_input_file): a missing folder, a
/// row without 7 integer columns, a denominator that is not a positive
/// power of two, a numerator that does not fit a double exactly, a file
/// whose rows are no multiple of 8 or whose truth bits differ within a
/// query; each names the file and the row.
Result<std::vector<BenchmarkQuery>> read_benchmark_queries(const std::filesystem::path& root);

/// The query answered by vertex_face or edge_edge.
Result<Hit> run_query(const BenchmarkQuery& query, const Settings& settings = {});

}  // namespace sinew::ccd
