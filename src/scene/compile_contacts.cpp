// compile_contacts.cpp — colliders, tools and attachments. (Stage in progress.)
#include "scene/scene_compiler.h"

namespace sinew {

Status add_contacts(SceneBuilder&, const SceneDesc& scene, CompiledScene&) {
  if (!scene.colliders.empty()) return Error("colliders are not supported yet by this version of sinew");
  if (!scene.tools.empty()) return Error("tools are not supported yet by this version of sinew");
  if (!scene.attachments.empty()) return Error("attachments are not supported yet by this version of sinew");
  return {};
}

}  // namespace sinew
