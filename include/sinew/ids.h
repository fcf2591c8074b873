// sinew/ids.h — typed ids of a Simulation's objects (Box2D v3's b2BodyId
// idea): a tool's id cannot be passed where a needle's is expected, and an
// id names the Simulation it came from, so one used on another Simulation
// is a named error instead of acting on whichever object has its index
// there. Ids come from the feature handles (Simulation::tools(),
// graspers(), needles(), topology()): `tools().tool(0)` is the scene's
// first ToolDesc.
//
// The scene's objects (bodies, tools, colliders, targets, graspers,
// needles) live as long as the Simulation. What does get removed while it
// runs are elements (tets, triangles, thread segments): they are never
// renumbered or reused, so an element index of a body stays its element
// for good, and naming a removed one is a named error ("was removed").
#pragma once

#include <cstdint>
#include <limits>

namespace sinew {

/// A typed index into one Simulation's objects of one kind. A default
/// (null) id is refused by every call.
template <class Tag>
struct Id {
  std::uint32_t index = std::numeric_limits<std::uint32_t>::max();  ///< among the scene's objects of the kind
  std::uint32_t scene = 0;  ///< the Simulation it belongs to (a number unique in the process; 0: none)
  /// Whether it names nothing (a default id).
  [[nodiscard]] bool is_null() const { return scene == 0; }
  /// Equal when they name the same object of the same Simulation.
  friend bool operator==(const Id&, const Id&) = default;
};

struct ToolTag;
struct ColliderTag;
struct TargetTag;
struct GrasperTag;
struct NeedleTag;
struct TetBodyTag;
struct TriBodyTag;
struct LineBodyTag;
using ToolId = Id<ToolTag>;          ///< SceneDesc::tools
using ColliderId = Id<ColliderTag>;  ///< SceneDesc::colliders
using TargetId = Id<TargetTag>;      ///< SceneDesc::targets
using GrasperId = Id<GrasperTag>;    ///< SceneDesc::graspers
using NeedleId = Id<NeedleTag>;      ///< SceneDesc::needles
using TetBodyId = Id<TetBodyTag>;    ///< SceneDesc::tet_bodies
using TriBodyId = Id<TriBodyTag>;    ///< SceneDesc::tri_bodies
using LineBodyId = Id<LineBodyTag>;  ///< SceneDesc::line_bodies

}  // namespace sinew
