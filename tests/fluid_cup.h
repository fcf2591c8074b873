// fluid_cup.h — the tissue cup the fluid coupling tests pour fluid into:
// 8 x 5 x 8 cells of 1 mm with its inside [1, 7] x [1, 5] x [1, 7] mm taken
// out (walls and floor one cell thick), blocks of fluid particles, and a
// scene of fluid poured into the cup.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/scene.h"

namespace sinew::test {

constexpr double kCupCell = 1e-3;  // the cup's cell and the fluid's spacing [m]

inline TetMesh fluid_cup() {
  constexpr double s = kCupCell;
  auto grid = make_tet_grid({.nx = 8, .ny = 5, .nz = 8, .cell_size = {s, s, s}});
  EXPECT_TRUE(grid.ok());
  TetMesh carved;
  carved.vertices = grid->vertices;
  for (const auto& t : grid->tets) {
    std::array<double, 3> c{};
    for (std::uint32_t v : t)
      for (int a = 0; a < 3; ++a) c[a] += 0.25 * grid->vertices[v][a];
    if (c[0] > s && c[0] < 7 * s && c[2] > s && c[2] < 7 * s && c[1] > s) continue;  // the cavity
    carved.tets.push_back(t);
  }
  return drop_unused_vertices(carved);
}

/// The cup as a tet body of 200 kPa (nu 0.3), pinned at its base when `pinned`.
inline TetBodyDesc fluid_cup_body(bool pinned) {
  TetBodyDesc body;
  body.mesh = fluid_cup();
  EXPECT_TRUE(body.set_elastic(2e5, 0.3).ok());
  if (pinned)
    for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
      if (body.mesh.vertices[v][1] < 1e-9) body.pinned.push_back(v);
  return body;
}

/// nx x ny x nz particles a spacing apart, the first cell's corner at `lo` [m].
inline std::vector<std::array<double, 3>> fluid_block(int nx, int ny, int nz, std::array<double, 3> lo) {
  std::vector<std::array<double, 3>> out;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        out.push_back({lo[0] + (i + 0.5) * kCupCell, lo[1] + (j + 0.5) * kCupCell, lo[2] + (k + 0.5) * kCupCell});
  return out;
}

// The cup (pinned at its base or free) with fluid poured in, coupled
// through its whole boundary surface.
inline SceneDesc cup_scene(bool pinned, std::array<double, 3> gravity, std::vector<std::array<double, 3>> fluid,
                           std::array<double, 3> velocity = {}) {
  SceneDesc scene;
  TetBodyDesc body = fluid_cup_body(pinned);
  scene.tet_bodies.push_back(std::move(body));
  scene.gravity = gravity;
  scene.solver.time_step = 1e-3;
  scene.solver.substeps = 4;
  scene.solver.iterations = 10;
  SceneFluidDesc f;
  f.fluid.settings.spacing = kCupCell;
  f.fluid.settings.gravity = gravity;
  f.fluid.velocities.assign(fluid.size(), velocity);
  f.fluid.particles = std::move(fluid);
  f.surfaces.push_back({.body_kind = BodyKind::tet, .body = 0, .triangles = {}});
  scene.fluid = std::move(f);
  return scene;
}

}  // namespace sinew::test
