// fluid_checks.cpp — SceneDesc::fluid's parameters beyond FluidDesc's
// (which SphSolver::create checks): the surfaces' bodies and triangles,
// and a frame that is a whole number of fluid steps.
#include <cmath>
#include <cstdio>
#include <string>

#include "compiler/scene_compiler.h"

namespace sinew {
namespace {

std::string surface_name(std::size_t i) { return "fluid.surfaces[" + std::to_string(i) + "]"; }

}  // namespace

Status check_scene_fluid(const SceneDesc& scene) {
  if (!scene.fluid) return {};
  const SceneFluidDesc& fluid = *scene.fluid;
  const double frame = scene.solver.time_step, dt = fluid.fluid.settings.time_step;
  const long steps = std::isfinite(frame / dt) ? std::lround(frame / dt) : 0;
  if (!(dt > 0.0) || steps < 1 || std::abs(double(steps) * dt - frame) > 1e-9 * frame) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "fluid.fluid.settings.time_step: the scene's frame (solver.time_step %.6g s) is not a whole number "
                  "of fluid steps of %.6g s",
                  frame, dt);
    return Error(ErrorCode::bad_parameter, text);
  }
  for (std::size_t i = 0; i < fluid.surfaces.size(); ++i) {
    const FluidSurfaceDesc& s = fluid.surfaces[i];
    std::size_t bodies = 0, vertices = 0;
    if (s.body_kind == BodyKind::tet) {
      bodies = scene.tet_bodies.size();
      if (s.body < bodies) vertices = scene.tet_bodies[s.body].mesh.vertices.size();
    } else if (s.body_kind == BodyKind::tri) {
      bodies = scene.tri_bodies.size();
      if (s.body < bodies) vertices = scene.tri_bodies[s.body].mesh.vertices.size();
    } else {
      return Error(ErrorCode::bad_parameter, surface_name(i) + ".body_kind must be tet or tri (a thread holds no fluid)");
    }
    if (s.body >= bodies)
      return Error(ErrorCode::bad_parameter, surface_name(i) + ".body " + std::to_string(s.body) + " is not one of the " +
                                                 std::to_string(bodies) + " bodies of its kind");
    for (std::size_t t = 0; t < s.triangles.size(); ++t)
      for (std::uint32_t v : s.triangles[t])
        if (v >= vertices)
          return Error(ErrorCode::bad_parameter, surface_name(i) + ".triangles[" + std::to_string(t) +
                                                     "] names vertex " + std::to_string(v) + " of a mesh of " +
                                                     std::to_string(vertices));
  }
  return {};
}

}  // namespace sinew
