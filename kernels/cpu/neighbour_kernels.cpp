// neighbour_kernels.cpp — CPU reference of the fixed-radius neighbour
// search (kernels/shared/neighbour_params.h: cells, buckets, the 27-cell
// query; Green 2010, Hoetzlein 2014). The GPU twins are
// kernels/gpu/nbr_*.gpu; every float operation here is one the twins do in
// the same order, so the sets found are the same bits.
#include <cmath>
#include <cstdint>

#include "cpu/cpu_kernels.h"
#include "cpu/neighbour_cells.h"
#include "neighbour_params.h"

namespace sinew::kernels {
namespace {

using u32 = std::uint32_t;
using cells::bucket_of;
using cells::visit_cells;

u32 point_count(const NeighbourParams& p, const std::byte* counts) {
  const u32 n = reinterpret_cast<const u32*>(counts)[p.count_word];
  return n < p.capacity ? n : p.capacity;
}

}  // namespace

void nbr_cells(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const NeighbourParams*>(params);
  const u32 n = point_count(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  auto* keys = reinterpret_cast<u32*>(bindings[2]);
  auto* order = reinterpret_cast<u32*>(bindings[3]);
  auto* cells = reinterpret_cast<int*>(bindings[4]);
  for (u32 i = begin; i < end && i < n; ++i) {
    int c[3];
    for (int k = 0; k < 3; ++k) c[k] = int(std::floor(points[4 * std::size_t{i} + k] * p.inv_cell));
    keys[i] = bucket_of(c[0], c[1], c[2], p.table_mask);
    order[i] = i;
    for (int k = 0; k < 3; ++k) cells[4 * std::size_t{i} + k] = c[k];
    cells[4 * std::size_t{i} + 3] = 0;
  }
}

void nbr_ranges(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const NeighbourParams*>(params);
  const u32 n = point_count(p, bindings[0]);
  const auto* keys = reinterpret_cast<const u32*>(bindings[1]);
  const auto* order = reinterpret_cast<const u32*>(bindings[2]);
  const auto* cells = reinterpret_cast<const u32*>(bindings[3]);
  auto* ranges = reinterpret_cast<u32*>(bindings[4]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const u32 b = keys[s];
    if (s == 0 || keys[s - 1] != b) ranges[3 * std::size_t{b}] = s;
    if (s + 1 == n || keys[s + 1] != b) ranges[3 * std::size_t{b} + 1] = s + 1;
    if (s > 0 && keys[s - 1] == b) {
      const u32* c = cells + 4 * std::size_t{order[s]};
      const u32* d = cells + 4 * std::size_t{order[s - 1]};
      if (c[0] != d[0] || c[1] != d[1] || c[2] != d[2]) ranges[3 * std::size_t{b} + 2] = 1;
    }
  }
}

void nbr_gather(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const NeighbourParams*>(params);
  const u32 n = point_count(p, bindings[0]);
  const auto* order = reinterpret_cast<const u32*>(bindings[1]);
  const auto* points = reinterpret_cast<const float*>(bindings[2]);
  const auto* cells = reinterpret_cast<const u32*>(bindings[3]);
  auto* sorted_points = reinterpret_cast<float*>(bindings[4]);
  auto* sorted_cells = reinterpret_cast<u32*>(bindings[5]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const std::size_t i = order[s];
    for (int k = 0; k < 4; ++k) {
      sorted_points[4 * std::size_t{s} + k] = points[4 * i + k];
      sorted_cells[4 * std::size_t{s} + k] = cells[4 * i + k];
    }
  }
}

void nbr_query(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const NeighbourParams*>(params);
  const u32 n = point_count(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  const auto* order = reinterpret_cast<const u32*>(bindings[4]);
  auto* lists = reinterpret_cast<u32*>(bindings[5]);
  auto* neighbours = reinterpret_cast<u32*>(bindings[6]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    const int* c = cells + 4 * std::size_t{s};
    const u32 i = order[s];
    u32 found = 0;
    const u32 first = p.mode == 0 ? 0u : lists[i];
    // Fill: hits gather in a small batch, written out to the list when full
    // and at the end (a branch-free write past the list would land in the next).
    constexpr u32 kBatch = 64;
    u32 batch[kBatch + 1];
    u32 held = 0;
    const auto flush = [&] {
      for (u32 k = 0; k < held; ++k)
        if (first + found + k < p.out_capacity) neighbours[first + found + k] = batch[k];
      found += held;
      held = 0;
    };
    // Branch-free over the candidates (which pass is unpredictable).
    visit_cells(cells, ranges, p.table_mask, c, [&](u32 t) {
      const float* y = points + 4 * std::size_t{t};
      const float ex = y[0] - x[0], ey = y[1] - x[1], ez = y[2] - x[2];
      const float d2 = ex * ex + ey * ey + ez * ez;
      const u32 hit = u32(d2 < p.radius2) & u32(t != s);
      if (p.mode == 1) {
        batch[held] = order[t];  // kept only when it hits
        held += hit;
        if (held == kBatch) flush();
      } else {
        found += hit;
      }
    });
    if (p.mode == 1) flush();
    if (p.mode == 0) lists[i] = found;
  }
}

}  // namespace sinew::kernels
