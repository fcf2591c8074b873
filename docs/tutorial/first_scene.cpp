// The getting-started tutorial's first scene (docs/getting_started.md): a block
// of soft tissue, pinned on one face, sags under gravity while a ball pushes
// its free end up. ctest builds it against the installed sinew and runs it
// (Tutorial.FirstScene).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <sinew/simulation.h>

int main() {
  // 1. A tissue block, 10 x 2 x 4 cm in 1 cm cells, of 30 kPa soft tissue.
  auto mesh = sinew::make_tet_grid({.nx = 10, .ny = 2, .nz = 4, .cell_size = {0.01, 0.01, 0.01}});
  if (!mesh) { std::fprintf(stderr, "%s\n", mesh.error().message().c_str()); return 1; }
  sinew::TetBodyDesc body;
  body.mesh = *mesh;
  body.density = 1060.0;  // kg/m^3
  if (auto s = body.set_elastic(30e3, 0.45); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] == 0.0) body.pinned.push_back(v);  // the x = 0 face holds it

  // 2. The scene: the body, a 1 cm ball below its free end, 60 frames a second.
  sinew::SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 1};
  scene.tet_bodies.push_back(std::move(body));
  sinew::ColliderDesc sphere;
  sphere.shape = sinew::ColliderShape::sphere;
  sphere.position = {0.09, -0.05, 0.02};  // [m]
  sphere.radius = 0.01;
  scene.colliders.push_back(sphere);

  // 3. The simulation, on the CPU backend ("auto" takes a GPU where one is built and found).
  auto sim = sinew::Simulation::create(scene, {.backend = "cpu"});
  if (!sim) { std::fprintf(stderr, "%s\n", sim.error().message().c_str()); return 1; }
  const auto ball = sim->tools().collider(0);
  if (!ball) { std::fprintf(stderr, "%s\n", ball.error().message().c_str()); return 1; }

  // 4. Two seconds: the block sags for one, then the ball rises 5 cm under its free end.
  std::vector<float> x;  // xyz + inverse mass per particle
  for (int frame = 1; frame <= 120; ++frame) {
    const double rise = frame > 60 ? 0.05 * (frame - 60) / 60.0 : 0.0;
    if (auto s = sim->tools().set_pose(*ball, {0.09, -0.05 + rise, 0.02}, {1, 0, 0, 0}); !s) return 1;
    if (auto s = sim->step(); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
    if (auto s = sim->read_positions(x); !s) return 1;
    float tip = 1.0f;  // the lowest point of the free end (x = 10 cm)
    for (std::size_t p = 0; p < x.size() / 4; ++p)
      if (std::fabs(x[4 * p] - 0.1f) < 0.005f) tip = std::fmin(tip, x[4 * p + 1]);
    if (!std::isfinite(tip)) { std::fprintf(stderr, "frame %d: not finite\n", frame); return 1; }
    if (frame % 20 == 0)
      std::printf("t = %.2f s  free end at %6.1f mm  %.2f ms per frame\n", sim->last_frame().time,
                  1e3 * tip, sim->last_frame().wall_ms);
  }
  return 0;
}
