// haptics_block_scene.h — the tissue block the haptics-with-physics tests
// press tools into: 40 x 40 x 20 mm (8 x 8 x 4 cells of 5 mm), corotational
// at 10 kPa, nu 0.45, 1060 kg/m^3, its bottom (z = 0) pinned, in a scene
// without gravity (so it rests at its rest shape, its top at z = 20 mm),
// 60 Hz frames of 10 substeps x 2 iterations.
#pragma once

#include <gtest/gtest.h>

#include "sinew/mesh.h"
#include "sinew/scene.h"

namespace sinew::test {

inline constexpr double kBlockTop = 0.020;                       // [m]
inline constexpr double kBlockYoung = 10e3, kBlockPoisson = 0.45;  // [Pa], -

/// The scene with the block as its only body; add the tools.
inline SceneDesc block_press_scene() {
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 10;
  scene.solver.iterations = 2;
  TetBodyDesc body;
  body.mesh = *make_tet_grid({.nx = 8, .ny = 8, .nz = 4, .origin = {-0.02, -0.02, 0.0}, .cell_size = {0.005, 0.005, 0.005}});
  body.density = 1060.0;
  EXPECT_TRUE(body.set_material(TetMaterial::corotational, kBlockYoung, kBlockPoisson).ok());
  for (std::uint32_t i = 0; i < body.mesh.vertices.size(); ++i)
    if (body.mesh.vertices[i][2] == 0.0) body.pinned.push_back(i);
  scene.tet_bodies.push_back(std::move(body));
  return scene;
}

}  // namespace sinew::test
