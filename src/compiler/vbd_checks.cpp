// vbd_checks.cpp — what a scene may hold with SolverSettings::method = vbd
// (Vertex Block Descent; program/vbd_program.h): tet bodies with a
// corotational or neo_hookean material, pinned vertices, gravity. Every
// other feature is an error naming it, never a silent fallback to xPBD:
// contacts, attachments, tools and the rest are xPBD constraints that VBD's
// per-vertex energy descent does not solve yet (the paper's augmented
// form for hard constraints and contacts is not implemented).
#include <string>

#include "compiler/scene_compiler.h"

namespace sinew {
namespace {

Error unsupported(const std::string& what) {
  return Error(ErrorCode::bad_parameter, "solver.method vbd does not support " + what +
                                             " yet (tet bodies with a corotational or neo_hookean material and "
                                             "pinned vertices only; docs/materials.md)");
}

}  // namespace

Status check_vbd_scene(const SceneDesc& scene) {
  const SolverSettings& solver = scene.solver;
  if (solver.method != SolverMethod::vbd) return {};
  if (solver.residual_tolerance > 0.0) return unsupported("the residual-driven mode (solver.residual_tolerance > 0)");
  if (solver.warm_start) return unsupported("solver.warm_start");
  if (scene.tet_bodies.empty()) return unsupported("a scene without tet bodies");
  for (std::size_t i = 0; i < scene.tet_bodies.size(); ++i) {
    const TetBodyDesc& b = scene.tet_bodies[i];
    const std::string name = "tet_bodies[" + std::to_string(i) + "]";
    if (b.material != TetMaterial::corotational && b.material != TetMaterial::neo_hookean)
      return unsupported(name + (b.material == TetMaterial::stvk
                                     ? ".material stvk (its Hessian blocks are not positive semi-definite)"
                                     : " without an FEM material (distance and volume constraints)"));
    if (b.distance_constraints || b.volume_constraints)
      return unsupported(name + "'s distance or volume constraints (set_material turns them off)");
    if (b.tear_strain > 0.0) return unsupported(name + ".tear_strain");
  }
  if (!scene.tri_bodies.empty()) return unsupported("tri_bodies");
  if (!scene.line_bodies.empty()) return unsupported("line_bodies");
  if (!scene.colliders.empty()) return unsupported("colliders");
  if (!scene.attachments.empty()) return unsupported("attachments");
  if (!scene.body_attachments.empty()) return unsupported("body_attachments");
  if (!scene.tools.empty()) return unsupported("tools");
  if (!scene.needles.empty()) return unsupported("needles");
  if (!scene.graspers.empty()) return unsupported("graspers");
  if (scene.mesh_collision.enabled) return unsupported("mesh_collision");
  if (scene.external_forces) return unsupported("external_forces");
  if (scene.topology_changes) return unsupported("topology_changes");
  if (scene.fluid) return unsupported("a fluid");
  return {};
}

}  // namespace sinew
