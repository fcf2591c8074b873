// check_info_commands.cpp — `sinew check` (a scene file read and checked,
// nothing run) and `sinew info` (the backends built in and their devices,
// and the haptic device plug-ins named with --haptic-plugin).
#include <cstdio>
#include <string>

#include "commands.h"
#include "sinew/device.h"
#include "sinew/haptics/device_plugin.h"
#include "sinew/mesh.h"
#include "sinew/scene_file.h"
#include "sinew/simulation.h"
#include "sinew/version.h"

namespace sinew::cli {

int check_scene_file(const std::string& scene) {
  auto file = load_scene_file(scene);
  if (!file) {
    std::fprintf(stderr, "sinew check: %s\n", file.error().message().c_str());
    return 1;
  }
  const SceneDesc& s = file->scene;
  std::printf("%s: ok\n", scene.c_str());
  for (const SceneBodyName& b : file->bodies) {
    if (b.kind == BodyKind::tet)
      std::printf("  tet body %u \"%s\": %zu vertices, %zu tets, %zu pinned\n", b.index, b.name.c_str(),
                  s.tet_bodies[b.index].mesh.vertices.size(), s.tet_bodies[b.index].mesh.tets.size(),
                  s.tet_bodies[b.index].pinned.size());
    else if (b.kind == BodyKind::tri)
      std::printf("  tri body %u \"%s\": %zu vertices, %zu triangles, %zu pinned\n", b.index, b.name.c_str(),
                  s.tri_bodies[b.index].mesh.vertices.size(), s.tri_bodies[b.index].mesh.triangles.size(),
                  s.tri_bodies[b.index].pinned.size());
    else
      std::printf("  line body %u \"%s\": %zu vertices, %zu segments, %zu pinned\n", b.index, b.name.c_str(),
                  s.line_bodies[b.index].vertices.size(), s.line_bodies[b.index].segments.size(),
                  s.line_bodies[b.index].pinned.size());
  }
  std::printf("  %zu colliders, %zu targets, %zu attachments, %zu tools, %zu needles, %zu graspers; mesh collision %s; fluid %s\n",
              s.colliders.size(), s.targets.size(), s.attachments.size(), s.tools.size(), s.needles.size(),
              s.graspers.size(), s.mesh_collision.enabled ? "on" : "off", s.fluid ? "yes" : "no");
  std::printf("  script: %zu pose tracks, %zu force tracks, %zu actions; run: %d frames of %g s, output every %d, backend %s\n",
              file->script.poses.size(), file->script.forces.size(), file->script.actions.size(), file->run.frames,
              s.solver.time_step, file->run.every, file->run.backend.c_str());
  return 0;
}

namespace {
// One plug-in: its name, ABI and devices, or why it does not load. Returns
// whether it loaded and listed.
bool print_haptic_plugin(const std::string& path) {
  auto plugin = haptics::DevicePlugin::load(path);
  if (!plugin) {
    std::printf("%s\n", plugin.error().message().c_str());
    return false;
  }
  auto devices = (*plugin)->devices();
  if (!devices) {
    std::printf("%s\n", devices.error().message().c_str());
    return false;
  }
  std::printf("haptic plug-in %s: \"%s\", ABI version %u, %zu device%s\n", path.c_str(), (*plugin)->name().c_str(),
              unsigned((*plugin)->abi_version()), devices->size(), devices->size() == 1 ? "" : "s");
  for (std::size_t i = 0; i < devices->size(); ++i) std::printf("  %zu: %s\n", i, (*devices)[i].c_str());
  return true;
}
}  // namespace

int print_info(const std::vector<std::string>& haptic_plugins) {
  std::printf("sinew %s\nbackends built in:", SINEW_VERSION_STRING);
  for (const std::string& b : built_backends()) std::printf(" %s", b.c_str());
  std::printf("\n");
  // A one-tet scene made on each backend says whether it has a device;
  // asking for a device no name contains makes it list the devices it has.
  SceneDesc probe;
  probe.tet_bodies.emplace_back().mesh = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 1, 2, 3}}};
  for (const std::string& b : built_backends()) {
    auto sim = Simulation::create(probe, {.backend = b, .quiet = true});
    if (!sim) {
      std::printf("%s: unavailable: %s\n", b.c_str(), sim.error().message().c_str());
      continue;
    }
    std::printf("%s: default device %s\n", b.c_str(), sim->device_name().c_str());
    if (b == "cpu") continue;
    auto listed = Simulation::create(probe, {.backend = b, .device = "\x01(list the devices)", .quiet = true});
    if (!listed) {
      const std::string& m = listed.error().message();
      const auto at = m.find("devices:");
      if (at != std::string::npos) std::printf("%s devices:%s\n", b.c_str(), m.substr(at + 8).c_str());
    }
  }
  bool plugins_ok = true;
  for (const std::string& path : haptic_plugins) plugins_ok = print_haptic_plugin(path) && plugins_ok;
  return plugins_ok ? 0 : 1;
}

}  // namespace sinew::cli
