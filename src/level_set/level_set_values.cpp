// level_set_values.cpp — see level_set_values.h (built with OpenVDB).
#include "level_set/level_set_values.h"

#include <cstring>

#include "level_set/level_set_impl.h"

namespace sinew {

Status set_level_set_values(const LevelSet& level_set, std::span<const std::byte> saved, const std::string& what,
                            std::vector<std::array<std::uint64_t, 2>>& changed) {
  changed.clear();
  // A cut changes the shared grid in place (LevelSet::cut); so does this.
  auto& impl = const_cast<LevelSet::Impl&>(level_set.internals());
  auto* live = reinterpret_cast<std::byte*>(impl.nano.data());
  if (saved.size() != impl.nano.size())
    return Error(ErrorCode::bad_parameter, what + ": the saved state is of another scene: a level set of " +
                                               std::to_string(saved.size()) + " bytes (this scene's: " +
                                               std::to_string(impl.nano.size()) + ")");
  using Leaf = nanovdb::NanoLeaf<float>;
  auto& tree = impl.nano.grid<float>()->tree();
  Leaf* const first = tree.getFirstLeaf();
  const std::uint32_t leaves = tree.nodeCount(0);
  // A leaf's bytes before its values (its place, masks, statistics) do not
  // change with a cut: they must match (checked for all before any changes).
  const std::size_t head = reinterpret_cast<const std::byte*>(&first->data()->mValues[0]) -
                           reinterpret_cast<const std::byte*>(first);
  std::vector<std::uint32_t> differ;
  for (std::uint32_t i = 0; i < leaves; ++i) {
    const std::size_t at = reinterpret_cast<const std::byte*>(first + i) - live;
    if (std::memcmp(live + at, saved.data() + at, sizeof(Leaf)) == 0) continue;
    if (std::memcmp(live + at, saved.data() + at, head) != 0)
      return Error(ErrorCode::bad_parameter,
                   what + ": the saved state is of another scene: its level set's leaf " + std::to_string(i) +
                       " is of another place or layout");
    differ.push_back(i);
  }
  auto host = impl.grid->getAccessor();
  for (std::uint32_t i : differ) {
    Leaf* leaf = first + i;
    const std::size_t at = reinterpret_cast<const std::byte*>(leaf) - live;
    std::memcpy(live + at, saved.data() + at, sizeof(Leaf));
    for (std::uint32_t n = 0; n < Leaf::SIZE; ++n) {
      const nanovdb::Coord c = leaf->offsetToGlobalCoord(n);
      const openvdb::Coord ijk(c[0], c[1], c[2]);
      const float value = leaf->getValue(n);
      if (host.getValue(ijk) != value) host.setValueOnly(ijk, value);
    }
    changed.push_back({std::uint64_t(at), std::uint64_t(sizeof(Leaf))});
  }
  return {};
}

}  // namespace sinew
