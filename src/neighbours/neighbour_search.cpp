// neighbour_search.cpp — sinew/neighbours.h: a device and a NeighbourGrid
// (neighbour_grid.h) behind the public API.
#include "sinew/neighbours.h"

#include <algorithm>
#include <limits>

#include "backends/backend.h"
#include "neighbours/neighbour_grid.h"

namespace sinew {

struct NeighbourSearch::Impl {
  std::unique_ptr<Device> device;
  std::unique_ptr<NeighbourGrid> grid;
  std::vector<float> xyzw;
  std::uint32_t regrown = 0;
};

NeighbourSearch::NeighbourSearch(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
NeighbourSearch::NeighbourSearch(NeighbourSearch&&) noexcept = default;
NeighbourSearch& NeighbourSearch::operator=(NeighbourSearch&&) noexcept = default;
NeighbourSearch::~NeighbourSearch() {
  if (impl_) impl_->grid.reset();  // before its device
}

Result<NeighbourSearch> NeighbourSearch::create(const NeighbourSettings& settings) {
  if (settings.capacity == 0 || settings.capacity > (1u << 28))
    return Error(ErrorCode::bad_parameter,
                 "neighbour search: capacity must be 1 .. 2^28 points (got " + std::to_string(settings.capacity) + ")");
  auto device = create_device(settings.device);
  if (!device) return device.error();
  auto impl = std::make_unique<Impl>();
  impl->device = std::move(*device);
  const std::uint64_t slots = settings.pair_capacity > 0 ? settings.pair_capacity : std::uint64_t{32} * settings.capacity;
  auto grid = NeighbourGrid::create(*impl->device, settings.capacity, settings.radius,
                                    static_cast<std::uint32_t>(std::min<std::uint64_t>(slots, 1u << 30)));
  if (!grid) return grid.error();
  impl->grid = std::move(*grid);
  return NeighbourSearch(std::move(impl));
}

Status NeighbourSearch::find(std::span<const std::array<float, 3>> points, NeighbourLists& lists) {
  Impl& m = *impl_;
  if (points.size() > m.grid->capacity())
    return Error(ErrorCode::bad_parameter, "neighbour search: " + std::to_string(points.size()) +
                                               " points, more than its capacity " + std::to_string(m.grid->capacity()));
  const auto n = static_cast<std::uint32_t>(points.size());
  m.xyzw.resize(4 * std::size_t{n});
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 4; ++k) m.xyzw[4 * i + std::size_t(k)] = k < 3 ? points[i][std::size_t(k)] : 0.0f;
  if (Status s = m.grid->upload(m.xyzw.data(), n); !s) return s;
  Status ran = m.grid->run();
  if (!ran && ran.error().code() == ErrorCode::capacity_exceeded) {
    // More pairs than slots: grow to what the count pass found, run again.
    const std::uint32_t needed = m.grid->pairs();
    if (Status s = m.grid->grow_pairs(needed); !s) return s;
    ++m.regrown;
    ran = m.grid->run();
  }
  if (!ran) return ran;
  const std::uint32_t total = m.grid->pairs();
  std::vector<std::uint32_t> offsets(std::size_t{n} + 1), neighbours(total);
  if (n > 0)
    if (Status s = m.device->read_buffer(m.grid->buffers().lists, 0, offsets.data(), 4 * std::size_t{n}); !s) return s;
  offsets[n] = total;
  if (total > 0)
    if (Status s = m.device->read_buffer(m.grid->buffers().neighbours, 0, neighbours.data(), 4 * std::size_t{total}); !s)
      return s;
  lists.offsets = std::move(offsets);
  lists.neighbours = std::move(neighbours);
  return {};
}

std::string NeighbourSearch::device_name() const { return impl_->device->device_name(); }
std::uint32_t NeighbourSearch::regrown() const { return impl_->regrown; }

}  // namespace sinew
