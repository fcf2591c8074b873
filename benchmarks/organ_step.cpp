// organ_step — median wall time of Simulation::step() on a real organ mesh, in the mesher's vertex
// order, timed outside step() (errors measured or not): how the frame costs on livers and kidneys,
// not only on the benchmark cube. Prints "median_ms,residual_rms,kinetic_energy,volume_change".
//   organ_step BACKEND MESH.node FRAMES MEASURE_ERRORS(0|1)
//   e.g. organ_step cpu build/data/meshes/tet/liver_382k.node 10 1
// The mesh is in millimetres (scaled to metres), E = 30 kPa, nu = 0.45, pinned within 5 mm of its
// lowest x, 10 substeps x 1 iteration at 60 Hz.
#include <sinew/simulation.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>
int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: organ_step BACKEND MESH.node FRAMES MEASURE_ERRORS(0|1)\n");
    return 2;
  }
  const std::string backend = argv[1];
  auto mesh = sinew::read_tet_mesh(argv[2]);
  if (!mesh) { std::fprintf(stderr, "%s\n", mesh.error().message().c_str()); return 1; }
  const int frames = std::atoi(argv[3]);
  if (frames < 1) {
    std::fprintf(stderr, "FRAMES must be >= 1\n");
    return 2;
  }
  const bool errors = std::atoi(argv[4]) != 0;
  sinew::scale_mesh(*mesh, 1e-3);
  sinew::TetBodyDesc body;
  body.mesh = std::move(*mesh);
  body.density = 1060.0;
  (void)body.set_elastic(3e4, 0.45);
  double lo = 1e30;
  for (const auto& v : body.mesh.vertices) lo = std::min(lo, v[0]);
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] < lo + 0.005) body.pinned.push_back(v);
  sinew::SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 1, .measure_errors = errors};
  scene.tet_bodies.push_back(std::move(body));
  auto sim = sinew::Simulation::create(scene, {.backend = backend, .quiet = true});
  if (!sim) { std::fprintf(stderr, "%s\n", sim.error().message().c_str()); return 1; }
  std::vector<double> t;
  for (int f = 0; f < frames; ++f) {
    const auto a = std::chrono::steady_clock::now();
    if (auto s = sim->step(); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  const auto& st = sim->last_frame();
  std::printf("%.3f,%.6e,%.6e,%.6e\n", t[t.size() / 2], st.residual_rms, st.kinetic_energy, st.volume_change);
}
