// topology_log.cpp — see topology_log.h.
#include "runtime/topology_log.h"

#include <algorithm>
#include <string>

#include "runtime/topology_editor.h"

namespace sinew {

bool is_prefix(const TopologyLog& head, const TopologyLog& log) {
  return head.size() <= log.size() && std::equal(head.begin(), head.end(), log.begin());
}

void write_log(state_format::Writer& w, const TopologyLog& log) {
  w.value(static_cast<std::uint64_t>(log.size()));
  for (const TopologyRecord& r : log) {
    const std::uint8_t kind_burn[2] = {static_cast<std::uint8_t>(r.kind), static_cast<std::uint8_t>(r.burn)};
    w.value(kind_burn);
    w.value(r.body);
    w.array(std::span<const std::uint32_t>(r.elements));
  }
}

Status read_log(state_format::Reader& r, const TopologyEditor* editor, const std::string& what, TopologyLog& out) {
  out.clear();
  std::uint64_t count = 0;
  if (Status s = r.value(count); !s) return s;
  if (count == 0) return {};
  if (!editor)
    return Error(ErrorCode::bad_parameter, what + ": the saved state holds " + std::to_string(count) +
                                               " topology changes; this scene was made without "
                                               "SceneDesc::topology_changes, so it cannot take them");
  // Every element of every body, as alive (1) or removed (0) by the records read so far.
  std::vector<std::vector<std::uint8_t>> alive[3];
  std::uint64_t total = 0;
  for (std::size_t b = 0; b < editor->bodies(); ++b) alive[0].emplace_back(editor->alive(b).size(), 1);
  for (std::size_t b = 0; b < editor->sheets(); ++b)
    alive[1].emplace_back(editor->view(BodyKind::tri, b).alive.size(), 1);
  for (std::size_t b = 0; b < editor->line_bodies(); ++b) alive[2].emplace_back(editor->whole(b).size(), 1);
  for (const auto& kind : alive)
    for (const auto& body : kind) total += body.size();
  if (count > total) return r.mismatch("topology changes", count, total);
  static const char* const kinds[3] = {"tet body", "tri body", "line body"};
  for (std::uint64_t i = 0; i < count; ++i) {
    TopologyRecord rec;
    std::uint8_t kind_burn[2] = {};
    if (Status s = r.value(kind_burn); !s) return s;
    if (Status s = r.value(rec.body); !s) return s;
    const std::string name = what + ": topology change " + std::to_string(i) + " of the saved state";
    if (kind_burn[0] > 2 || kind_burn[1] > 1)
      return Error(ErrorCode::bad_input_file, name + " is malformed (kind " + std::to_string(kind_burn[0]) +
                                                  ", burn " + std::to_string(kind_burn[1]) + ")");
    rec.kind = static_cast<BodyKind>(kind_burn[0]);
    rec.burn = kind_burn[1] != 0;
    auto& bodies = alive[kind_burn[0]];
    if (rec.body >= bodies.size())
      return Error(ErrorCode::bad_parameter, name + " is of " + kinds[kind_burn[0]] + " " + std::to_string(rec.body) +
                                                 "; the scene has " + std::to_string(bodies.size()));
    std::vector<std::uint8_t>& live = bodies[rec.body];
    if (Status s = r.array(rec.elements, live.size(), "topology change's elements"); !s) return s;
    if (rec.elements.empty()) return Error(ErrorCode::bad_input_file, name + " removes nothing");
    for (std::uint32_t e : rec.elements) {
      if (e >= live.size() || !live[e])
        return Error(ErrorCode::bad_parameter, name + " removes element " + std::to_string(e) + " of " +
                                                   kinds[kind_burn[0]] + " " + std::to_string(rec.body) +
                                                   (e >= live.size() ? ", which does not exist" : " a second time"));
      live[e] = 0;
    }
    out.push_back(std::move(rec));
  }
  return {};
}

}  // namespace sinew
