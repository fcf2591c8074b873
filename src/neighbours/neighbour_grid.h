// neighbour_grid.h — the fixed-radius neighbour search on a device (issue
// 15, part 1): the buffers for `capacity` points and the frame program that
// sorts them into a hashed uniform grid and writes every point's neighbour
// list, all on the device with the point count read from a device word
// (kernels/shared/neighbour_params.h has the method and its papers).
//
// The program (one submission):
//   nbr_cells    each point's cell and bucket (the key) | ranges zeroed
//   radix sort   (bucket, point) pairs, only the bucket's bits (primitives.h)
//   nbr_ranges   each bucket's run in the sorted order | nbr_gather: points
//                and cells copied into that order
//   nbr_query 0  each point's neighbour count
//   scan         the counts' exclusive scan: each list's offset; the total
//                is the counter "neighbour pairs" (capacity pair_capacity)
//   nbr_query 1  the lists
// The sorted points, cells and bucket ranges stay on the device after it:
// a solver reads them directly (a query visits the same 27 cells).
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "backends/backend.h"
#include "neighbour_params.h"

namespace sinew {

struct NeighbourGridBuffers {
  BufferHandle counts;         ///< uint: [0] the point count n, [1] the neighbour pairs found
  BufferHandle points;         ///< float4 per point: xyz [m] (the caller's input)
  BufferHandle keys, keys_tmp;    ///< uint per point: buckets (sorted after the program)
  BufferHandle order, order_tmp;  ///< uint per point: sorted position -> point
  BufferHandle cells;          ///< uint4 per point: its cell
  BufferHandle sorted_points;  ///< float4 per sorted point
  BufferHandle sorted_cells;   ///< uint4 per sorted point
  BufferHandle ranges;         ///< uint, 3 per bucket: a bucket's run [start, end) in sorted order, mixed (0/1)
  BufferHandle lists;          ///< uint per point: its list's offset in `neighbours` (after the program)
  BufferHandle neighbours;     ///< uint per pair: the point indices of every list, list after list
  BufferHandle scratch;        ///< the sort's and the scan's
};

class NeighbourGrid {
 public:
  /// Buffers for `capacity` points (> 0) of a search `radius` [m] (finite,
  /// > 0) and `pair_capacity` neighbour slots (> 0), and the program.
  static Result<std::unique_ptr<NeighbourGrid>> create(Device& device, std::uint32_t capacity, double radius,
                                                       std::uint32_t pair_capacity);
  ~NeighbourGrid();
  NeighbourGrid(const NeighbourGrid&) = delete;
  NeighbourGrid& operator=(const NeighbourGrid&) = delete;

  /// Writes `n` (<= capacity) points (xyz [m], stride 4 floats, w unused)
  /// and the count. Errors: n > capacity, a point not finite or farther
  /// than max_coordinate() from the origin on an axis (naming the point).
  Status upload(const float* xyzw, std::uint32_t n);
  /// Runs the program on the points uploaded (or written by the caller into
  /// buffers().points with the count in counts[0]). A run whose pairs
  /// exceed pair_capacity returns capacity_exceeded; pairs() then holds
  /// how many there were: grow_pairs(pairs()) and run again.
  Status run();
  /// Runs only the grid's part (up to nbr_gather): the sorted points and
  /// cells and the bucket ranges, for a solver that visits the cells itself.
  Status run_grid();
  /// The neighbour pairs the last run found (from its counter).
  [[nodiscard]] std::uint32_t pairs() const;
  /// Regrows the neighbour slots to `pair_capacity` and rebuilds the program.
  Status grow_pairs(std::uint32_t pair_capacity);

  /// Appends the grid's part of the program (up to nbr_gather, ending with a
  /// barrier) to another program: a solver's step that visits the cells.
  /// Its dispatches run over the live point count (live_points).
  void append_grid(FrameProgram& program) const;
  /// Declares the point count counts[0] a counter of `program` (at most
  /// capacity()) and returns its index, for dispatch_indirect: a dispatch
  /// over the live points rather than the capacity. Why: on a GPU no work
  /// item past the count is launched, and on the CPU the team splits the
  /// live points between its threads (a dispatch over the capacity gave
  /// them all to the first thread when fewer than half the slots were live).
  std::uint32_t live_points(FrameProgram& program) const;

  [[nodiscard]] const NeighbourGridBuffers& buffers() const { return b_; }
  [[nodiscard]] std::uint32_t capacity() const { return capacity_; }
  [[nodiscard]] std::uint32_t pair_capacity() const { return pair_capacity_; }
  [[nodiscard]] std::uint32_t buckets() const { return buckets_; }
  [[nodiscard]] float inv_cell() const { return inv_cell_; }
  [[nodiscard]] float radius2() const { return radius2_; }
  /// The largest |coordinate| [m] a point may have: 2^16 cells.
  [[nodiscard]] double max_coordinate() const;
  /// [out] out: every buffer with its size [bytes] appended (a saved state, Simulation::save_state).
  void state_buffers(std::vector<std::pair<BufferHandle, std::size_t>>& out) const;

 private:
  NeighbourGrid(Device& device) : device_(device) {}
  template <class Visit>
  void for_each_buffer(Visit visit);
  Status build_program();
  [[nodiscard]] kernels::NeighbourParams params() const;

  Device& device_;
  NeighbourGridBuffers b_{};
  std::uint32_t capacity_ = 0, pair_capacity_ = 0, buckets_ = 0, table_bits_ = 0;
  float inv_cell_ = 0.0f, radius2_ = 0.0f;
  ProgramHandle program_{}, grid_program_{};
  std::uint32_t pairs_counter_ = 0;  // the index of the counter "neighbour pairs" in program_
  bool have_program_ = false, have_grid_program_ = false;
};

}  // namespace sinew
