// sinew/saved_state.h — a Simulation's state between two frames, in memory
// or in a file (Simulation::save_state, Simulation::restore_state).
//
// What it holds: the particles' positions, previous positions and
// velocities, every constraint's multiplier (lambda) and residual, the
// particle forces set for the next frame, the colliders' and kinematic
// targets' poses, the rigid tools' motion and reactions, a fluid's
// particles, grid, counts and emitters, each grasper's hold (open, or the
// particles and surface points it holds and where in its frame), what each
// trocar pushed over the last frame, each needle's poses, motion, reaction
// and rows (its tie to its thread, tip contact, punctures and thread
// punctures), the topology changes made so far in their order (each with
// the elements it removed and whether their mass was burned or handed on)
// and the cautery's heat per element, the values of every level-set
// collider a cut can change (interior_band infinite), the frame count and
// the divergence checks' history. Restoring it into the Simulation it came
// from, or into a new Simulation made from the same SceneDesc on the same
// backend, and stepping gives bitwise the positions of the run that was
// never interrupted, whatever topology changes and level-set cuts were made
// before or after the save.
//
// The bytes are the file's bytes (the format below), so a state in memory
// can be written as it is. A state restores only into a scene of the same
// shape (particles, constraint blocks, colliders, targets, tools, needles,
// level sets). Its topology changes are replayed where the Simulation has
// made none of its own beyond them (the state's first ones); a Simulation
// that has made others, or more, is made again from its SceneDesc and
// device options and replays them all (Simulation::restore_state). A level
// set is shared by every copy of its LevelSet: restoring sets the shared
// grid's values.
//
// File format, version 4 (all integers little-endian as the host writes
// them, which the byte-order word checks):
//   8 bytes   magic "sinewst\x1a"
//   uint32    format version (4; version 1 lacks the mesh collision's
//             velocities, see docs/robustness.md; versions 1 and 2 lack the
//             graspers' holds: they restore every grasper open; versions 1
//             to 3 lack the topology changes, the needles and the level
//             sets: they restore only where no change or cut was made
//             before the save, and leave the level sets as they are)
//   uint32    byte order 0x01020304
//   uint64    payload size [bytes]
//   uint64    FNV-1a 64 hash of the payload
//   payload   the scene's shape, then the state (src/runtime/state_format.h)
// A file that is shorter than its header says, has another magic, a newer
// version, another byte order or a wrong hash is an ErrorCode::bad_input_file
// error naming the file and the check that failed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sinew/result.h"

namespace sinew {

/// The format version written now; files of this version or older are read.
inline constexpr std::uint32_t kSavedStateVersion = 4;

struct SavedState {
  /// The header and payload, as in the file.
  std::vector<std::byte> bytes;
  /// The frame it was saved after (FrameStats::frame then); 0 for an empty or malformed state.
  [[nodiscard]] std::uint64_t frame() const;

  /// [in] path: the file to write (replaced). Errors: bad_input_file naming the path when it cannot be written.
  Status write_file(const std::string& path) const;
  /// [in] path: a file write_file wrote. Errors: bad_input_file naming the path and the failed check
  /// (missing, truncated, foreign magic, unknown version, byte order, hash).
  static Result<SavedState> read_file(const std::string& path);
};

}  // namespace sinew
