// sinew/neighbours.h — fixed-radius neighbour search on any backend (issue
// 15, part 1): for every point, the other points closer than a radius.
//
// A uniform grid of cells a little wider than the radius, hashed into
// buckets in Morton order; the points sorted by bucket on the device (radix
// sort) and every point's 27 surrounding cells visited (Green, "Particle
// Simulation using CUDA", NVIDIA 2010; Hoetzlein, "Fast Fixed-Radius
// Nearest Neighbors", GTC 2014). Everything runs in one device program
// whose sizes (the lists' total) are known only on the device; details in
// kernels/shared/neighbour_params.h.
//
// What "closer" means, exactly: j is a neighbour of i (j != i) when
//   float d2 = dx * dx + dy * dy + dz * dz;   d2 < float(radius) * float(radius)
// with dx = x_j - x_i etc. in float, each operation rounded in that order.
// Every backend finds the same sets, and so does a brute-force loop that
// computes the same expression.
//
//   auto search = sinew::NeighbourSearch::create({.radius = 0.002, .capacity = 100000});
//   sinew::NeighbourLists lists;
//   if (auto s = search->find(points, lists); !s) ...;
//   for (uint32_t k = lists.offsets[i]; k < lists.offsets[i + 1]; ++k) use(lists.neighbours[k]);
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "sinew/device.h"
#include "sinew/result.h"

namespace sinew {

/// What a NeighbourSearch is for: the radius, the most points, the lists'
/// starting slots and the device (NeighbourSearch::create).
struct NeighbourSettings {
  double radius = 0.0;          ///< [m], finite, > 0
  std::uint32_t capacity = 0;   ///< the most points one search takes, 1 .. 2^28
  /// Neighbour slots the lists start with; 0: 32 per point of capacity. A
  /// search that finds more grows them and runs again (NeighbourSearch::regrown).
  std::uint32_t pair_capacity = 0;
  DeviceOptions device;         ///< the backend it runs on
};

/// Neighbour lists in compressed rows: point i's neighbours are
/// neighbours[offsets[i] .. offsets[i + 1]), point indices, in an order
/// that is the same on every backend (by cell, then by the points' order
/// along the grid), not sorted by index.
struct NeighbourLists {
  std::vector<std::uint32_t> offsets;     ///< n + 1
  std::vector<std::uint32_t> neighbours;  ///< offsets[n]
};

/// For every point, the other points closer than a radius, on any backend
/// (docs/fluids.md, "Neighbour search").
class NeighbourSearch {
 public:
  /// Errors (bad_parameter): settings out of range; the backend's when it
  /// is not available.
  static Result<NeighbourSearch> create(const NeighbourSettings& settings);
  /// Moves the search and its device.
  ///@{
  NeighbourSearch(NeighbourSearch&&) noexcept;
  NeighbourSearch& operator=(NeighbourSearch&&) noexcept;
  ///@}
  ~NeighbourSearch();

  /// [in] points: xyz [m]; [out] lists. Uploads the points, runs the
  /// search, reads the lists back. Errors (bad_parameter, lists unchanged):
  /// more points than the capacity; a coordinate that is not finite or lies
  /// 2^16 cells (about 65,000 radii) or more from the origin, naming the point.
  Status find(std::span<const std::array<float, 3>> points, NeighbourLists& lists);

  [[nodiscard]] std::string device_name() const;  ///< the device the search runs on
  /// Times the lists' slots grew since create().
  [[nodiscard]] std::uint32_t regrown() const;

  struct Impl;  ///< opaque (src/neighbours/neighbour_search.cpp)
 private:
  explicit NeighbourSearch(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sinew
