// graspers.h — graspers that hold what their jaws close on (SceneDesc::
// graspers): a contact query at the particles' current positions picks
// the movable particles inside the jaws' box, and each gets a zero-length
// attachment to its own target, a point fixed in the grasper's frame; the
// targets follow the grasper's pose, interpolated across the frame's
// substeps like every target (contact_params.h, xpbd_solve_attachment).
//
// Each grasper owns a block of `capacity` attachment slots in one colour,
// made by compile_scene with none in use: closing writes the held
// particles into the first slots and sets the colour's count, opening sets
// it to 0; the caller rebuilds the frame program after either. Moving only
// rewrites targets.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "backends/backend.h"
#include "compiler/scene_compiler.h"
#include "program/xpbd_program.h"
#include "sinew/simulation.h"

namespace sinew {

class Graspers {
 public:
  Graspers(const SceneDesc& scene, const CompiledScene& compiled);

  [[nodiscard]] std::size_t count() const { return graspers_.size(); }
  [[nodiscard]] bool closed(std::size_t index) const { return !graspers_[index].held.empty(); }

  /// Closes grasper `index` at `pose` on the movable particles inside the
  /// box of `half_extents` [m] centred on the pose (in its frame).
  /// [in] xyzw: every particle's position in the user's order;
  /// [in/out] targets: the host copy of the target buffer (uploaded by the
  /// caller); shape: the grasper block's particles go to the device here,
  /// its count into shape. Returns the held particles (user order).
  /// Errors: closed already; more particles than its capacity (nothing held).
  Result<std::vector<std::uint32_t>> close(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                           std::vector<float>& targets, const ParticleOrder& order,
                                           std::size_t index, const Pose& pose,
                                           const std::array<double, 3>& half_extents, std::span<const float> xyzw);
  /// The pose the grasper reaches by the end of the next frame: its held
  /// particles' targets' end points (an open grasper holds none: nothing
  /// changes).
  void move(std::vector<float>& targets, std::size_t index, const Pose& pose);
  /// Releases what it holds (returned, user order); its count in shape is
  /// 0, and its slots' residuals (which the statistics reduce over the
  /// whole block) are zeroed on the device.
  Result<std::vector<std::uint32_t>> open(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                          std::size_t index);

 private:
  struct Grasper {
    std::uint32_t block = 0, first_target = 0, capacity = 0;
    std::vector<std::uint32_t> held;                // user particles
    std::vector<std::array<double, 3>> offsets;     // each in the grasper's frame [m]
  };
  std::vector<Grasper> graspers_;
};

}  // namespace sinew
