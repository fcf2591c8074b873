// compile_thin.cpp — triangle bodies and thread bending. (Stage in progress.)
#include "scene/scene_compiler.h"

namespace sinew {

Status add_tri_body(SceneBuilder&, const TriBodyDesc&, const std::string& name) {
  return Error(name + ": triangle bodies are not supported yet by this version of sinew");
}

Status add_line_bending(SceneBuilder&, const LineBodyDesc&, std::uint32_t, const std::string& name) {
  return Error(name + ".bending_compliance: bending of line bodies is not supported yet by this version of sinew");
}

}  // namespace sinew
