// The first scene of docs/getting_started.md: a block of tissue, pinned on one face, sags onto a ball that
// then rises and lifts it. ctest builds it against the installed sinew and runs it (Tutorial.FirstScene).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <sinew/simulation.h>

int main() {
  // 1. A tissue block, 10 x 2 x 4 cm in 1 cm cells, of 200 kPa tissue, pinned on its x = 0 face.
  auto mesh = sinew::make_tet_grid({.nx = 10, .ny = 2, .nz = 4, .cell_size = {0.01, 0.01, 0.01}});
  if (!mesh) { std::fprintf(stderr, "%s\n", mesh.error().message().c_str()); return 1; }
  sinew::TetBodyDesc body;
  body.mesh = *mesh;
  body.density = 1060.0;  // kg/m^3
  if (auto s = body.set_elastic(200e3, 0.45); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
  std::vector<std::uint32_t> free_end;  // the vertices of the x = 10 cm face
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v) {
    if (body.mesh.vertices[v][0] == 0.0) body.pinned.push_back(v);
    if (body.mesh.vertices[v][0] > 0.0999) free_end.push_back(v);
  }

  // 2. The scene: the body and a ball of 1 cm radius 2 cm under its free end; 60 frames a second, 10 substeps.
  sinew::SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 1};
  scene.tet_bodies.push_back(std::move(body));
  sinew::ColliderDesc ball;
  ball.shape = sinew::ColliderShape::sphere;
  ball.position = {0.09, -0.03, 0.02};  // [m]
  ball.radius = 0.01;
  scene.colliders.push_back(ball);

  // 3. The simulation, on the CPU backend ("auto" takes a GPU where one is built and found).
  auto sim = sinew::Simulation::create(scene, {.backend = "cpu"});
  if (!sim) { std::fprintf(stderr, "%s\n", sim.error().message().c_str()); return 1; }
  const auto ball_id = sim->tools().collider(0);
  if (!ball_id) { std::fprintf(stderr, "%s\n", ball_id.error().message().c_str()); return 1; }

  // 4. Two seconds: the block sags onto the ball for one, then the ball rises 4 cm and lifts it.
  std::vector<float> x;  // xyz + inverse mass per particle
  float resting = 0.0f, tip = 0.0f;
  for (int frame = 1; frame <= 120; ++frame) {
    const double rise = frame > 60 ? 0.04 * (frame - 60) / 60.0 : 0.0;
    if (auto s = sim->tools().set_pose(*ball_id, {0.09, -0.03 + rise, 0.02}, {1, 0, 0, 0}); !s) return 1;
    if (auto s = sim->step(); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
    if (auto s = sim->read_positions(x); !s) return 1;
    tip = 1.0f;  // the lowest point of the free end [m]
    for (std::uint32_t v : free_end) tip = std::fmin(tip, x[4 * v + 1]);
    if (!std::isfinite(tip)) { std::fprintf(stderr, "frame %d: not finite\n", frame); return 1; }
    if (frame == 60) resting = tip;
    if (frame % 20 == 0)
      std::printf("t = %.2f s  free end at %6.1f mm  %.2f ms per frame\n", sim->last_frame().time, 1e3 * tip,
                  sim->last_frame().wall_ms);
  }
  return tip - resting > 0.02f ? 0 : 1;  // the ball lifted the free end by more than 2 cm
}
