// view_snapshot.h — what the physics thread hands the viewer after each
// frame (docs/viewer.md): the particles, the live elements, the tools,
// colliders and needles where they are, the fluid and FrameStats, passed
// through a triple buffer so that neither thread ever waits for the other.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sinew/level_set.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace sinew::view {

/// One frame of the scene as the viewer draws it.
struct ViewSnapshot {
  std::uint64_t generation = 0;     ///< the Simulation it came from: 1 at start, +1 at every reset
  std::uint64_t frame = 0;          ///< frames stepped in that Simulation
  /// Changes of the bodies' elements or of a level set's shape in that
  /// Simulation (cuts, removals, cautery, tears): the viewer rebuilds its
  /// index buffers when it changes.
  std::uint64_t shape_version = 0;
  std::vector<float> positions;     ///< xyzw per particle (Simulation::read_positions)
  /// Each body's first particle in `positions` (SceneInfo::tet_body_first_particle, ...).
  std::vector<std::uint32_t> tet_first, tri_first, line_first;
  std::vector<float> speeds;        ///< |v| per particle [m/s]
  std::vector<std::vector<std::array<std::uint32_t, 3>>> tet_surfaces;  ///< per tet body: its live boundary, body-local indices
  std::vector<std::vector<std::array<std::uint32_t, 3>>> tri_surfaces;  ///< per tri body: its live triangles
  std::vector<std::vector<std::array<std::uint32_t, 2>>> line_segments;  ///< per line body: its unbroken segments
  std::vector<ToolState> tools;      ///< per tool
  std::vector<Pose> colliders;       ///< per collider: its pose now
  std::vector<NeedleState> needles;  ///< per needle (its punctures left out)
  std::vector<float> fluid;          ///< xyz per fluid particle
  /// Per collider: its level set's surface in the collider's frame (empty for
  /// other shapes); shared, remade only when a cut changes it.
  std::shared_ptr<const std::vector<TriMesh>> collider_surfaces;
  FrameStats stats;                  ///< Simulation::last_frame
  double physics_hz = 0.0;           ///< frames stepped per wall-clock second, lately
  bool paused = false;               ///< the physics waits for "step" or "run"
  std::string error;                 ///< why the physics stopped ("" while it runs)
};

/// One writer, one reader, newest value wins, no locks and no waiting on
/// either side: the writer fills its own slot and swaps it into the middle;
/// the reader swaps the middle out when it holds something newer. Each slot
/// belongs to one thread at a time, so the vectors inside are reused
/// (no allocation once they have grown).
template <class T>
class TripleBuffer {
 public:
  /// The writer's slot, to fill before publish().
  T& back() { return slots_[back_]; }
  /// Hands the back slot to the reader (writer thread only).
  void publish() { back_ = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & kIndex; }
  /// Takes the newest published slot if there is one newer than the front;
  /// returns whether it did (reader thread only).
  bool update() {
    if (!(middle_.load(std::memory_order_relaxed) & kFresh)) return false;
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
    return true;
  }
  /// The reader's slot: the newest value taken by update().
  const T& front() const { return slots_[front_]; }

 private:
  static constexpr unsigned kFresh = 4, kIndex = 3;
  T slots_[3];
  unsigned back_ = 0, front_ = 1;
  std::atomic<unsigned> middle_{2};
};

}  // namespace sinew::view
