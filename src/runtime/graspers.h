// graspers.h — graspers that hold what their jaws close on (SceneDesc::
// graspers): a contact query at the particles' current positions picks
// the movable particles inside the jaws' box, and each gets a zero-length
// attachment to its own target, a point fixed in the grasper's frame; the
// targets follow the grasper's pose, interpolated across the frame's
// substeps like every target (contact_params.h, xpbd_solve_attachment).
// A surface triangle that crosses the jaws with none of its vertices
// inside is held at its point nearest the jaws' centre, through its
// barycentric weights (xpbd_solve_point_attachment; iMSTK's
// PbdObjectGrasping holds cells the same way): a coarse mesh is grasped
// where the jaws touch it, not only at vertices that happen to lie between
// them.
//
// Each grasper owns a block of `capacity` attachment slots in one colour
// and one of `point_capacity` point slots, made by compile_scene with none
// in use: closing writes the held particles (and points) into the first
// slots and sets the colours' counts, opening sets them to 0; the caller
// rebuilds the frame program after either. Moving only rewrites targets.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "backends/backend.h"
#include "compiler/scene_compiler.h"
#include "program/xpbd_program.h"
#include "runtime/topology_editor.h"
#include "sinew/simulation.h"

namespace sinew {

class GrasperHolds {
 public:
  /// What one grasper holds: the state a saved state carries for it.
  struct Hold {
    bool closed = false;
    std::vector<std::uint32_t> held;              ///< user particles
    std::vector<HeldPoint> points;                ///< surface points
    std::vector<std::array<double, 3>> offsets;   ///< each held particle's, then each point's, in the grasper's frame [m]
  };

  GrasperHolds(const SceneDesc& scene, const CompiledScene& compiled);

  [[nodiscard]] std::size_t count() const { return graspers_.size(); }
  [[nodiscard]] bool closed(std::size_t index) const { return graspers_[index].closed; }
  /// The bodies' surface triangles (user-order particles, 3 each): every
  /// tet body's boundary faces (of its live tets, when `topology` is
  /// given) and every tri body's (live) triangles. Made again after
  /// invalidate(), when next asked for: a boundary costs a pass over its
  /// body's tets, paid by the next close, not by every cut.
  const std::vector<std::uint32_t>& surface(const TopologyEditor* topology);
  /// The bodies' topology changed: surface() is made again when next asked for.
  void invalidate() { surface_stale_ = true; }
  /// The surface points grasper `index` holds (user-order particles).
  [[nodiscard]] const std::vector<HeldPoint>& points(std::size_t index) const {
    return graspers_[index].points;
  }

  /// Closes grasper `index` at `pose` on the movable particles inside the
  /// box of `half_extents` [m] centred on the pose (in its frame), and on
  /// the surface triangles that cross the box with no vertex inside it.
  /// [in] xyzw: every particle's position in the user's order;
  /// [in] surface: the bodies' surface triangles (user-order particles, 3
  /// each) the jaws can hold by a point;
  /// [in/out] targets: the host copy of the target buffer (uploaded by the
  /// caller); shape: the grasper block's particles go to the device here,
  /// its count into shape. Returns the held particles (user order).
  /// Errors: closed already; more particles than its capacity, or points
  /// than its point_capacity (nothing held).
  Result<std::vector<std::uint32_t>> close(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                           std::vector<float>& targets, const ParticleOrder& order,
                                           std::size_t index, const Pose& pose,
                                           const std::array<double, 3>& half_extents, std::span<const float> xyzw,
                                           std::span<const std::uint32_t> surface);
  /// The pose the grasper reaches by the end of the next frame: its held
  /// particles' targets' end points (an open grasper holds none: nothing
  /// changes).
  void move(std::vector<float>& targets, std::size_t index, const Pose& pose);
  /// Releases what it holds (its vertices returned, user order); its
  /// counts in shape are 0, and its slots' residuals (which the statistics
  /// reduce over the whole block) are zeroed on the device.
  Result<std::vector<std::uint32_t>> open(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                          std::size_t index);

  /// Grasper `index`'s hold, for a saved state.
  [[nodiscard]] Hold hold(std::size_t index) const;
  /// Whether `hold` fits grasper `index` of a scene of `particles`
  /// particles (capacities, particle indices, one offset per held particle
  /// and point); errors name `what` and the rule. Changes nothing.
  Status check(std::size_t index, const Hold& hold, std::size_t particles, const std::string& what) const;
  /// Makes grasper `index` hold `hold` (checked by check()): its slots on
  /// the device and its counts in `shape`, as close() leaves them, or open.
  /// The targets and the multipliers are the caller's (a saved state holds
  /// them). The caller rebuilds the frame program.
  Status restore(Device& device, const XpbdBuffers& buffers, CompiledScene& shape, const ParticleOrder& order,
                 std::size_t index, const Hold& hold);

 private:
  struct Grasper {
    std::uint32_t block = 0, first_target = 0, capacity = 0;
    std::uint32_t point_block = UINT32_MAX, point_first_target = 0, point_capacity = 0;
    double compliance = 0.0;  // GrasperDesc::compliance [m/N]
    bool closed = false;
    std::vector<std::uint32_t> held;                // user particles
    std::vector<HeldPoint> points;      // surface points
    std::vector<std::array<double, 3>> offsets;     // each held particle's, then each point's, in the grasper's frame [m]
  };
  // The held particles' slots and the points' triangles and data on the
  // device, and the blocks' counts in shape (close() and restore()).
  Status write_slots(Device& device, const XpbdBuffers& buffers, CompiledScene& shape, const ParticleOrder& order,
                     const Grasper& g, std::span<const std::uint32_t> held, std::span<const HeldPoint> points) const;
  std::vector<Grasper> graspers_;
  std::vector<TetMesh> tet_meshes_;  // the scene's tet bodies (their boundaries, for surface())
  std::vector<std::uint32_t> tet_first_;
  std::vector<TriMesh> tri_meshes_;
  std::vector<std::uint32_t> tri_first_;
  std::vector<std::uint32_t> surface_;
  bool surface_stale_ = true;
};

}  // namespace sinew
