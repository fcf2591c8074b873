// py_simulation.h — the state behind a Python `sinew.Simulation`: the
// library's Simulation, the scene file's script played before each frame
// (as `sinew run` plays it, so Python and the runner compute the same
// numbers), the events of the last frame, and a lock that makes calls from
// several Python threads take turns (step() runs without the GIL).
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sinew/needles.h"
#include "sinew/scene_file.h"
#include "sinew/simulation.h"

namespace sinew::python {

/// Something that happened in a frame: one of the script's actions (a
/// grasp, a release, a cut, cautery, a removal, a collider cut, an emitter
/// or sink change), a tear, or a needle's new puncture.
struct FrameEvent {
  int frame = 0;  ///< the frame it happened in (the step() that made it)
  /// "close_grasper", "open_grasper", "cut", "cauterize", "remove",
  /// "cut_collider", "set_emitter", "set_sink" (the script's actions),
  /// "tear" or "puncture".
  std::string kind;
  std::uint32_t index = 0;  ///< the grasper, body, collider, emitter, sink or needle
  std::string text;         ///< one line, as `sinew run` prints the script's events
  std::vector<std::uint32_t> particles;     ///< grasps: the particles held or released
  std::optional<TopologyEvent> topology;    ///< cut, cauterize, remove, tear
  std::optional<CutReport> collider_cut;    ///< cut_collider
  std::optional<Puncture> puncture;         ///< puncture
};

/// A Simulation with its script, as Python sees it.
class PySimulation {
 public:
  /// Makes the Simulation of `file`'s scene on [in] device; with
  /// [in] play_script, each step() first plays the file's script for its frame.
  PySimulation(const SceneFile& file, const DeviceOptions& device, bool play_script);

  /// Plays the script's frame (when playing it), steps one frame, gathers
  /// its events; [out] stats, when given, gets a copy of its FrameStats.
  /// Call without the GIL (it takes `lock`).
  Status step(FrameStats* stats = nullptr);

  Simulation sim;
  SceneDesc scene;                    ///< what it was made from (its meshes, for surfaces)
  std::vector<SceneBodyName> bodies;  ///< the bodies' names
  std::atomic<int> frame = 0;         ///< frames stepped (read by other threads while one steps)
  std::vector<FrameEvent> events;     ///< the last step()'s events
  std::vector<float> staging;         ///< read_positions/read_velocities land here first (capacity reused)
  std::mutex lock;                    ///< held by every call into `sim`

 private:
  PySimulation(Simulation&& made, const SceneFile& file, bool play_script);
  Status gather_events(std::vector<ScriptEvent>& script_events);

  std::optional<ScriptPlayer> player_;
  std::unique_ptr<haptics::ScriptedHands> hands_;  // the file's scripted hands, played with the script
  std::vector<ScriptEvent> script_events_;          // reused each frame
  std::vector<std::vector<Puncture>> punctures_;    // each needle's punctures after the last frame
};

}  // namespace sinew::python
