// neighbour_grid.cpp — the host side of the device neighbour search (see
// neighbour_grid.h; the kernels' contract: kernels/shared/neighbour_params.h).
#include "neighbours/neighbour_grid.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "neighbour_params.h"
#include "program/primitives.h"

namespace sinew {
namespace {

// The cell is this much wider than the radius, so that two points closer
// than the radius land in the same or adjacent cells whatever the float
// products round to, up to 2^16 cells from the origin (neighbour_params.h):
// their cell coordinates u = x / cell differ by at most (1 + 2^-23) / (1 +
// 2^-6) plus the two products' rounding, 2 * 2^-24 * 2^16 = 2^-7, < 1.
constexpr double kCellMargin = 1.0 + 1.0 / 64.0;
constexpr double kMaxCells = 65536.0;

std::string str(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

}  // namespace

// Every buffer with its size [bytes] and label, in one list: create makes
// them, the destructor frees them, state_buffers hands them to a saved state.
template <class Visit>
void NeighbourGrid::for_each_buffer(Visit visit) {
  const std::size_t n = capacity_;
  const std::uint32_t scratch = std::max(radix_sort_scratch_words(capacity_), scan_scratch_words(capacity_));
  NeighbourGridBuffers& b = b_;
  visit(b.counts, 8, "neighbour counts");
  visit(b.points, 16 * n, "neighbour points");
  visit(b.keys, 4 * n, "neighbour keys");
  visit(b.keys_tmp, 4 * n, "neighbour keys (sort)");
  visit(b.order, 4 * n, "neighbour order");
  visit(b.order_tmp, 4 * n, "neighbour order (sort)");
  visit(b.cells, 16 * n, "neighbour cells");
  visit(b.sorted_points, 16 * n, "neighbour sorted points");
  visit(b.sorted_cells, 16 * n, "neighbour sorted cells");
  visit(b.ranges, 12 * std::size_t{buckets_}, "neighbour bucket ranges");
  visit(b.lists, 4 * n, "neighbour lists");
  visit(b.neighbours, 4 * std::size_t{pair_capacity_}, "neighbours");
  visit(b.scratch, 4 * std::size_t{scratch}, "neighbour scratch");
}

Result<std::unique_ptr<NeighbourGrid>> NeighbourGrid::create(Device& device, std::uint32_t capacity, double radius,
                                                             std::uint32_t pair_capacity) {
  if (capacity == 0 || capacity > (1u << 28))
    return Error(ErrorCode::bad_parameter,
                 "neighbour search: capacity must be 1 .. 2^28 points (got " + std::to_string(capacity) + ")");
  if (!(radius > 0.0) || !std::isfinite(radius) || !std::isfinite(float(radius * radius)) ||
      !(float(radius) * float(radius) > 0.0f))
    return Error(ErrorCode::bad_parameter,
                 "neighbour search: radius must be finite and > 0 [m], its square a normal float (got " + str(radius) + ")");
  if (pair_capacity == 0)
    return Error(ErrorCode::bad_parameter, "neighbour search: pair_capacity must be > 0");
  std::unique_ptr<NeighbourGrid> g(new NeighbourGrid(device));
  g->capacity_ = capacity;
  g->pair_capacity_ = pair_capacity;
  // Buckets: a power of two, at least twice the points (few runs share one).
  g->buckets_ = std::max(64u, std::bit_ceil(std::min(2u * capacity, 1u << 29)));
  g->table_bits_ = static_cast<std::uint32_t>(std::countr_zero(g->buckets_));
  g->inv_cell_ = float(1.0 / (radius * kCellMargin));
  g->radius2_ = float(radius) * float(radius);
  Status made;
  g->for_each_buffer([&](BufferHandle& handle, std::size_t bytes, const char* label) {
    if (!made) return;
    auto buffer = device.create_buffer(bytes, label);
    if (!buffer) made = buffer.error();
    else handle = *buffer;
  });
  if (!made) return made.error();
  if (Status s = g->build_program(); !s) return s.error();
  return g;
}

void NeighbourGrid::state_buffers(std::vector<std::pair<BufferHandle, std::size_t>>& out) const {
  const_cast<NeighbourGrid*>(this)->for_each_buffer(
      [&](BufferHandle& handle, std::size_t bytes, const char*) { out.emplace_back(handle, bytes); });
}

NeighbourGrid::~NeighbourGrid() {
  if (have_program_) (void)device_.destroy_program(program_);
  if (have_grid_program_) (void)device_.destroy_program(grid_program_);
  for_each_buffer([&](BufferHandle& handle, std::size_t, const char*) {
    if (handle.valid()) (void)device_.destroy_buffer(handle);
  });
}

double NeighbourGrid::max_coordinate() const { return kMaxCells / double(inv_cell_); }

kernels::NeighbourParams NeighbourGrid::params() const {
  kernels::NeighbourParams p{};
  p.count_word = 0;
  p.capacity = capacity_;
  p.table_mask = buckets_ - 1;
  p.inv_cell = inv_cell_;
  p.radius2 = radius2_;
  p.out_capacity = pair_capacity_;
  return p;
}

std::uint32_t NeighbourGrid::live_points(FrameProgram& program) const {
  return program.counter("neighbour points", b_.counts, 0, capacity_);
}

void NeighbourGrid::append_grid(FrameProgram& program) const {
  const NeighbourGridBuffers& b = b_;
  const kernels::NeighbourParams p = params();
  const std::uint32_t live = live_points(program);
  program.fill(b.ranges, 0, 3 * buckets_, 0u);
  program.dispatch_indirect(Kernel::nbr_cells, live, {b.counts, b.points, b.keys, b.order, b.cells}, p);
  program.barrier();
  // Only the bucket's bits are sorted (table_bits_ of 32: fewer passes).
  append_radix_sort(program, {b.counts, 0, capacity_}, 32, b.keys, b.order, b.keys_tmp, b.order_tmp, {b.scratch, 0},
                    table_bits_);
  program.barrier();
  program.dispatch_indirect(Kernel::nbr_ranges, live, {b.counts, b.keys, b.order, b.cells, b.ranges}, p);
  program.dispatch_indirect(Kernel::nbr_gather, live,
                            {b.counts, b.order, b.points, b.cells, b.sorted_points, b.sorted_cells}, p);
  program.barrier();
}

Status NeighbourGrid::build_program() {
  for (bool* have : {&have_program_, &have_grid_program_})
    if (*have) {
      if (Status s = device_.destroy_program(have == &have_program_ ? program_ : grid_program_); !s) return s;
      *have = false;
    }
  const NeighbourGridBuffers& b = b_;
  kernels::NeighbourParams p = params();
  FrameProgram grid;
  append_grid(grid);
  auto made_grid = device_.create_program(grid);
  if (!made_grid) return made_grid.error();
  grid_program_ = *made_grid;
  have_grid_program_ = true;

  FrameProgram program;
  append_grid(program);
  const std::uint32_t live = live_points(program);
  p.mode = 0;
  program.dispatch_indirect(Kernel::nbr_query, live,
                   {b.counts, b.sorted_points, b.sorted_cells, b.ranges, b.order, b.lists, b.neighbours}, p);
  program.barrier();
  // The counts become each list's offset; the total is the pairs' counter.
  const std::uint32_t total =
      append_exclusive_scan(program, {b.counts, 0, capacity_}, {b.lists, 0}, {b.lists, 0}, {b.scratch, 0});
  program.copy(b.scratch, total, b.counts, 1, 1);
  program.barrier();
  pairs_counter_ = program.counter("neighbour pairs", b.counts, 1, pair_capacity_);
  p.mode = 1;
  program.dispatch_indirect(Kernel::nbr_query, live,
                   {b.counts, b.sorted_points, b.sorted_cells, b.ranges, b.order, b.lists, b.neighbours}, p);
  program.barrier();
  auto made = device_.create_program(program);
  if (!made) return made.error();
  program_ = *made;
  have_program_ = true;
  return {};
}

Status NeighbourGrid::upload(const float* xyzw, std::uint32_t n) {
  if (n > capacity_)
    return Error(ErrorCode::bad_parameter, "neighbour search: " + std::to_string(n) + " points, more than its capacity " +
                                               std::to_string(capacity_));
  const double limit = max_coordinate();
  for (std::uint32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      const float x = xyzw[4 * std::size_t{i} + std::size_t(k)];
      if (!std::isfinite(x) || std::abs(double(x)) >= limit)
        return Error(ErrorCode::bad_parameter, "neighbour search: point " + std::to_string(i) + " has coordinate " +
                                                   str(double(x)) + ": it must be finite and within " + str(limit) +
                                                   " m of the origin (2^16 cells)");
    }
  if (n > 0)
    if (Status s = device_.write_buffer(b_.points, 0, xyzw, 16 * std::size_t{n}); !s) return s;
  const std::uint32_t counts[2] = {n, 0u};
  return device_.write_buffer(b_.counts, 0, counts, sizeof counts);
}

Status NeighbourGrid::run() { return device_.run_program(program_); }
Status NeighbourGrid::run_grid() { return device_.run_program(grid_program_); }

std::uint32_t NeighbourGrid::pairs() const {
  const std::span<const std::uint32_t> c = device_.counters();
  return pairs_counter_ < c.size() ? c[pairs_counter_] : 0u;
}

Status NeighbourGrid::grow_pairs(std::uint32_t pair_capacity) {
  if (pair_capacity <= pair_capacity_) return {};
  if (Status s = device_.resize_buffer(b_.neighbours, 4 * std::size_t{pair_capacity}); !s) return s;
  pair_capacity_ = pair_capacity;
  return build_program();
}

}  // namespace sinew
