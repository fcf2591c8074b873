// topology_log.h — the topology changes a Simulation has made, in the order
// it made them (removals, cuts, cautery, tears and broken thread segments
// as the editor applied them), so that a saved state can carry them.
//
// Why a log: the editor's state (every constraint's slot, every colour's
// count, the masses handed on or burned, each body's live elements and
// boundary) is a deterministic function of the scene and the ordered
// changes applied to it, each change given as the elements it removed. A
// change moves its colour's last constraint into a freed slot, so the order
// and the element lists matter; replaying the same records in the same
// order from the same compiled scene gives the same slots, masses and
// colours bit for bit (topology_editor.h). A restore replays what the
// Simulation has not made yet, or rebuilds it and replays the whole log.
#pragma once

#include <cstdint>
#include <vector>

#include "runtime/state_format.h"
#include "sinew/result.h"
#include "sinew/scene.h"

namespace sinew {

class TopologyEditor;

/// One change as the editor applied it.
struct TopologyRecord {
  BodyKind kind = BodyKind::tet;  ///< tet, tri (remove) or line (remove_segments)
  std::uint64_t body = 0;         ///< among the scene's bodies of that kind
  bool burn = false;              ///< tet, tri: the mass left the scene (cautery); else it was handed on
  std::vector<std::uint32_t> elements;  ///< tets, triangles or segments removed, in the order given
  bool operator==(const TopologyRecord&) const = default;
};

using TopologyLog = std::vector<TopologyRecord>;

/// Whether `head` is the first head.size() records of `log`.
[[nodiscard]] bool is_prefix(const TopologyLog& head, const TopologyLog& log);

/// Appends the log to a state's payload.
void write_log(state_format::Writer& w, const TopologyLog& log);
/// Reads a log and checks it can be applied to the scene from its start:
/// each body exists, each element exists and is removed at most once
/// (against the editor's bodies' sizes; the editor may be null: then a
/// non-empty log is an error naming what the scene lacks).
Status read_log(state_format::Reader& r, const TopologyEditor* editor, const std::string& what, TopologyLog& out);

}  // namespace sinew
