// level_set_values.h — a level set's values put back as a saved state held
// them (sinew/saved_state.h): a cut (LevelSet::cut) changes values only,
// never the grid's layout, so the NanoVDB copy's bytes of an earlier
// moment, laid over the grid leaf by leaf, are that moment's grid.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sinew/level_set.h"
#include "sinew/result.h"

namespace sinew {

/// [in] level_set: the grid to set (the host grid and its NanoVDB copy,
/// for every copy of the LevelSet, as a cut changes them); saved: its
/// nanovdb_bytes() as they were. [out] changed: the byte ranges (offset,
/// size) of the NanoVDB copy that changed, to upload. Errors
/// (bad_parameter, nothing changed): bytes of another size or of another
/// layout (a leaf elsewhere), naming `what`.
Status set_level_set_values(const LevelSet& level_set, std::span<const std::byte> saved, const std::string& what,
                            std::vector<std::array<std::uint64_t, 2>>& changed);

}  // namespace sinew
