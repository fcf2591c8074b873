// A program built against an installed sinew (tests/consumer, run by the
// Consumer.* tests): a small block of soft tissue, pinned on its x = 0 face,
// sags under gravity on the cpu backend for a few frames. It fails unless
// every position is finite and the block has sagged, and (when the build
// says which version it expects) unless sinew/version.h agrees; the
// installed C API header (sinew/sinew.h) compiles as C++ and its library
// says the same version. The haptic plug-in loader links (dlopen comes with
// the package's link flags) and names a missing library as an error.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <utility>
#include <vector>

#include <sinew/haptics/device_plugin.h>
#include <sinew/mesh.h>
#include <sinew/simulation.h>
#include <sinew/sinew.h>
#include <sinew/version.h>

int main() {
  std::printf("sinew %s (%d.%d.%d)\n", SINEW_VERSION_STRING, SINEW_VERSION_MAJOR, SINEW_VERSION_MINOR,
              SINEW_VERSION_PATCH);
#ifdef SINEW_CONSUMER_EXPECTED_VERSION
  if (std::strcmp(SINEW_VERSION_STRING, SINEW_CONSUMER_EXPECTED_VERSION) != 0) {
    std::fprintf(stderr, "sinew/version.h says %s, the package %s\n", SINEW_VERSION_STRING,
                 SINEW_CONSUMER_EXPECTED_VERSION);
    return 1;
  }
#endif
  if (sinew_version() != SINEW_VERSION) {
    std::fprintf(stderr, "the C API's sinew_version() is %u, sinew/version.h says %d\n", unsigned(sinew_version()),
                 SINEW_VERSION);
    return 1;
  }

  // 8 cm x 2 cm x 4 cm, 4 x 1 x 2 cells of 2 cm.
  auto mesh = sinew::make_tet_grid({.nx = 4, .ny = 1, .nz = 2, .cell_size = {0.02, 0.02, 0.02}});
  if (!mesh) { std::fprintf(stderr, "%s\n", mesh.error().message().c_str()); return 1; }
  sinew::TetBodyDesc body;
  body.mesh = std::move(*mesh);
  body.density = 1060.0;
  if (auto s = body.set_elastic(30e3, 0.45); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] == 0.0) body.pinned.push_back(v);
  sinew::SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 2};
  scene.tet_bodies.push_back(std::move(body));

  auto sim = sinew::Simulation::create(scene, {.backend = "cpu"});
  if (!sim) { std::fprintf(stderr, "%s\n", sim.error().message().c_str()); return 1; }
  const int frames = 10;
  for (int f = 0; f < frames; ++f)
    if (auto s = sim->step(); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
  std::vector<float> x;  // xyz + inverse mass per particle
  if (auto s = sim->read_positions(x); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }

  float lowest = 0.0f;
  for (std::size_t p = 0; p < x.size() / 4; ++p) {
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(x[4 * p + c])) { std::fprintf(stderr, "particle %zu is not finite\n", p); return 1; }
    lowest = std::fmin(lowest, x[4 * p + 1]);
  }
  std::printf("%zu particles on %s, lowest point after %d frames: %.2f mm\n", x.size() / 4,
              sim->backend_name().c_str(), frames, 1e3 * lowest);
  if (lowest > -1e-3f) { std::fprintf(stderr, "the block did not sag (lowest point %g m)\n", lowest); return 1; }

  auto plugin = sinew::haptics::DevicePlugin::load("/nonexistent/sinew_consumer_plugin.so");
  if (plugin || plugin.error().code() != sinew::ErrorCode::bad_input_file) {
    std::fprintf(stderr, "loading a missing haptic plug-in did not fail with bad_input_file\n");
    return 1;
  }
  std::printf("missing haptic plug-in: %s\n", plugin.error().message().c_str());
  return 0;
}
