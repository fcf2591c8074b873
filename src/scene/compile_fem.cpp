// compile_fem.cpp — FEM constraints of tet bodies. (Stage in progress.)
#include "scene/scene_compiler.h"

namespace sinew {

Status add_fem_constraints(SceneBuilder&, const TetBodyDesc&, std::uint32_t, const std::string& name) {
  return Error(name + ".material: FEM materials are not supported yet by this version of sinew");
}

}  // namespace sinew
