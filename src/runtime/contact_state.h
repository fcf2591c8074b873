// contact_state.h — the host side of contacts that Simulation::Impl keeps
// between frames (simulation_contacts.cpp): which device buffers need an
// upload and the rigid tools' state (rigid_tool.h). Everything is sized in init_contacts; nothing here
// grows per frame.
#pragma once

#include <cstdint>
#include <vector>

#include "runtime/rigid_tool.h"
#include "sinew/scene.h"

namespace sinew {

struct ContactState {
  std::uint32_t colliders = 0;  ///< scene colliders; the tools' entries follow them in the collider buffer
  std::uint32_t substeps = 1, iterations = 1;
  bool colliders_dirty = false;  ///< the collider buffer changed since its last upload
  bool targets_dirty = false;    ///< the target buffer changed since its last upload
  std::vector<ToolBody> tools;
  std::vector<ColliderDesc> shapes;  ///< the scene's colliders (the tools meet them on the host, tool_contacts.h)
  /// Per scene collider, where its level set's grid starts in the level-set
  /// grids buffer [bytes] (0 for other shapes; CompiledScene::level_set_offsets).
  std::vector<std::uint64_t> level_set_offsets;
  std::vector<ColliderDesc> tool_shapes;  ///< each tool's capsule or level set, for the meshes' faces (mesh_collision.h) and the penalty (tool_penalty.h)
};

}  // namespace sinew
