// sutures_state.cpp — the needles' part of a saved state (Sutures::save,
// read, restore_needles; sinew/saved_state.h): everything a needle keeps
// between frames. Its poses at the frame's start and end (the end is what
// set_pose asked for the coming frame), a force-driven needle's rigid body,
// its reaction and counters, and its rows: the tie, the tip contact, the
// punctures and thread punctures with their tissue points, weights, inserted
// shaft lengths and slide speeds. The device's row buffers are written from
// these before every frame (Sutures::upload), the positions read again, and
// the exemption from contacts made again from the rows, so nothing else
// carries over.
#include <string>

#include "suture_params.h"
#include "runtime/state_format.h"
#include "runtime/sutures.h"
#include "runtime/tool_fields.h"

namespace sinew {

void Sutures::save(state_format::Writer& w) const {
  w.value(static_cast<std::uint64_t>(needles_.size()));
  for (const Needle& n : needles_) {
    for (const auto* v : {&n.position_start, &n.position_end, &n.reaction_force, &n.reaction_torque}) w.value(*v);
    w.value(n.rotation_start);
    w.value(n.rotation_end);
    tool_fields(n.body, [&](const auto& v) { w.value(v); });
    w.value(n.tip_force);
    const std::uint32_t refused[3] = {n.refused_degenerate, n.refused_inverted, n.refused_angle};
    w.value(refused);
    w.value(static_cast<std::uint64_t>(n.rows.size()));
    for (const Row& r : n.rows) {
      w.value(r.words);
      w.value(r.weights);
      w.value(r.surface);
      w.value(r.triangle);
      w.value(static_cast<std::uint8_t>(r.exit));
      w.value(r.slip);
    }
  }
}

Status Sutures::read(state_format::Reader& r, const std::string& what, std::vector<Needle>& out) const {
  std::uint64_t count = 0;
  if (Status s = r.value(count); !s) return s;
  if (count != needles_.size()) return r.mismatch("needles", count, needles_.size());
  out = needles_;  // each one's NeedleDesc and thread stay this scene's
  const std::uint32_t particles = static_cast<std::uint32_t>(positions_.size() / 4);
  for (std::size_t i = 0; i < out.size(); ++i) {
    Needle& n = out[i];
    for (auto* v : {&n.position_start, &n.position_end, &n.reaction_force, &n.reaction_torque})
      if (Status s = r.value(*v); !s) return s;
    for (Status s : {r.value(n.rotation_start), r.value(n.rotation_end)})
      if (!s) return s;
    Status body;
    tool_fields(n.body, [&](auto& v) {
      if (body) body = r.value(v);
    });
    if (!body) return body;
    std::uint32_t refused[3] = {};
    std::uint64_t rows = 0;
    for (Status s : {r.value(n.tip_force), r.value(refused), r.value(rows)})
      if (!s) return s;
    n.refused_degenerate = refused[0], n.refused_inverted = refused[1], n.refused_angle = refused[2];
    if (rows > kRowsPerNeedle) return r.mismatch("needle's rows", rows, kRowsPerNeedle);
    n.rows.assign(rows, Row{});
    for (std::size_t k = 0; k < rows; ++k) {
      Row& row = n.rows[k];
      std::uint8_t exit = 0;
      for (Status s : {r.value(row.words), r.value(row.weights), r.value(row.surface), r.value(row.triangle),
                       r.value(exit), r.value(row.slip)})
        if (!s) return s;
      row.exit = exit != 0;
      // What the kernel and the host index with: each must lie in this scene.
      const std::uint32_t* w = row.words.data();
      const bool surface_ok = row.surface < surfaces_.size() && row.triangle < surfaces_[row.surface].triangles.size();
      const char* bad = nullptr;
      if (w[0] < SINEW_SUTURE_TIE || w[0] > SINEW_SUTURE_BLUNT) bad = "its kind";
      else if (w[1] != i) bad = "its needle";
      else if (w[2] >= particles || w[3] >= particles || w[4] >= particles) bad = "its particles";
      else if (std::uint64_t{w[5]} + w[6] > slots_.size()) bad = "its thread's slots";
      else if (w[0] == SINEW_SUTURE_THREAD && !(w[7] + std::uint64_t{1} < w[6])) bad = "its thread segment";
      else if (w[0] != SINEW_SUTURE_TIE && !surface_ok) bad = "its surface or triangle";
      if (bad)
        return Error(ErrorCode::bad_parameter, what + ": row " + std::to_string(k) + " of needle " +
                                                   std::to_string(i) + " in the saved state is not of this scene (" +
                                                   bad + ")");
    }
  }
  return {};
}

void Sutures::restore_needles(std::vector<Needle> needles) {
  needles_ = std::move(needles);
  mark_exemption();
}

}  // namespace sinew
