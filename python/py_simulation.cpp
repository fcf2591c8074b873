// py_simulation.cpp — stepping a Python Simulation: the script's frame,
// the step, and what happened in it.
#include "py_simulation.h"

#include <algorithm>

#include "errors.h"

namespace sinew::python {
namespace {

const char* action_name(ScriptActionKind kind) {
  switch (kind) {
    case ScriptActionKind::close_grasper: return "close_grasper";
    case ScriptActionKind::open_grasper: return "open_grasper";
    case ScriptActionKind::cut: return "cut";
    case ScriptActionKind::cauterize: return "cauterize";
    case ScriptActionKind::remove: return "remove";
    case ScriptActionKind::cut_collider: return "cut_collider";
    case ScriptActionKind::set_emitter: return "set_emitter";
    case ScriptActionKind::set_sink: return "set_sink";
  }
  return "unknown";
}

// A puncture is the same one from frame to frame while it holds the same
// triangle of the same body the same way (its weights and thread position
// move as the needle and thread slide).
bool same_puncture(const Puncture& a, const Puncture& b) {
  return a.body_kind == b.body_kind && a.body == b.body && a.triangle == b.triangle && a.exit == b.exit;
}

}  // namespace

PySimulation::PySimulation(const SceneFile& file, const DeviceOptions& device, bool play_script)
    : PySimulation(take(Simulation::create(file.scene, device)), file, play_script) {}

PySimulation::PySimulation(Simulation&& made, const SceneFile& file, bool play_script)
    : sim(std::move(made)), scene(file.scene), bodies(file.bodies) {
  if (play_script) player_.emplace(file.script);
  // The file's scripted hands play with its script (on the frames' clock).
  if (play_script && !file.hands.empty()) hands_ = take(haptics::ScriptedHands::create(file.hands, sim, file.scene.solver.time_step));
  punctures_.resize(sim.needles().count());
}

Status PySimulation::step(FrameStats* stats) {
  std::lock_guard<std::mutex> held(lock);
  events.clear();
  script_events_.clear();
  const int next = frame + 1;
  if (player_)
    if (Status s = player_->before_frame(sim, next, script_events_); !s) return s;
  if (hands_)
    if (Status s = hands_->before_step(sim); !s) return s;
  if (Status s = sim.step(); !s) return s;
  if (hands_)
    if (Status s = hands_->after_step(sim); !s) return s;
  frame = next;
  if (stats) *stats = sim.last_frame();
  return gather_events(script_events_);
}

Status PySimulation::gather_events(std::vector<ScriptEvent>& script_events) {
  const int now = frame.load();
  for (ScriptEvent& e : script_events) {
    FrameEvent& out = events.emplace_back();
    out.frame = e.frame;
    out.kind = action_name(e.kind);
    out.index = e.index;
    out.text = e.text.empty() ? "frame " + std::to_string(e.frame) + ": " + out.kind + " " + std::to_string(e.index)
                              : std::move(e.text);
    out.particles = std::move(e.particles);
    if (e.kind == ScriptActionKind::cut || e.kind == ScriptActionKind::cauterize || e.kind == ScriptActionKind::remove)
      out.topology = std::move(e.topology);
    if (e.kind == ScriptActionKind::cut_collider) out.collider_cut = std::move(e.collider_cut);
  }
  for (const TopologyEvent& t : sim.topology().last_tears()) {
    FrameEvent& out = events.emplace_back();
    out.frame = now;
    out.kind = "tear";
    out.index = static_cast<std::uint32_t>(t.body);
    const std::size_t elements = t.tets_removed.size() + t.triangles_removed.size() + t.segments_removed.size();
    out.text = "frame " + std::to_string(now) + ": tear: " + std::to_string(elements) + " elements removed";
    out.topology = t;
  }
  Needles needles = sim.needles();
  for (std::size_t n = 0; n < punctures_.size(); ++n) {
    auto id = needles.needle(n);
    if (!id) return id.error();
    auto state = needles.state(*id);
    if (!state) return state.error();
    for (const Puncture& p : state->punctures) {
      const auto& before = punctures_[n];
      if (std::any_of(before.begin(), before.end(), [&](const Puncture& q) { return same_puncture(p, q); })) continue;
      FrameEvent& out = events.emplace_back();
      out.frame = now;
      out.kind = "puncture";
      out.index = static_cast<std::uint32_t>(n);
      out.text = "frame " + std::to_string(now) + ": needle " + std::to_string(n) + " punctured " +
                 (p.body_kind == BodyKind::tet ? "tet" : "tri") + " body " + std::to_string(p.body) + " at triangle " +
                 std::to_string(p.triangle) + (p.exit ? " (exit)" : " (entry)");
      out.puncture = p;
    }
    punctures_[n] = std::move(state->punctures);
  }
  return {};
}

}  // namespace sinew::python
