// cholecystectomy — a cholecystectomy-like sequence (issue 16's example): a
// grasper lifts a thin membrane that joins the gallbladder to the liver bed,
// a cautery tip burns through one of its connections, and a blade cuts it
// free of the gallbladder. Topology changes while the scene runs
// (sinew/simulation.h: cut_body, cauterize, graspers).
//
// The scene:
//   - the gallbladder: data/meshes/tet/gallbladder_volumetric.vtk (1,063 tets,
//     the mesher's order, mm scaled to m), corotational FEM at 20 kPa, held
//     along its top (the fifth of its height nearest the liver);
//   - the membrane: thin tissue (a tri body) of 40 x 20 mm, 1 mm thick (1 mm
//     cells, 1,600 triangles), 50 kPa, with bending, lying under the
//     gallbladder. Its far edge is fastened to the
//     liver bed (pinned); its near edge to the gallbladder: each of those
//     vertices is attached, two ways, to the nearest gallbladder vertex at
//     their rest distance (BodyAttachmentDesc: the membrane pulls on the
//     organ as the organ pulls on it);
//   - at 0.5 s a grasper closes on the middle of the membrane where it
//     hangs then, and lifts it 15 mm over a second; from 0.8 s a cautery
//     tip of 3 mm radius (dwell 0.1 s) burns a strand near the liver edge,
//     where that strand is each frame; from 1.5 s a blade sweeps along the
//     gallbladder edge, following the membrane, cutting it free.
//
// scenes/cholecystectomy.json is this scene as a file (its script's
// landmarks find the membrane's middle and the strand in the running
// scene, a relative track lifts the grasper): `sinew run` on it writes
// the same files, byte for byte.
//
// Prints each topology event (what it removed and what it took) and the wall
// time per frame; writes cholecystectomy.pvd (sinew/vtk_output.h, from
// frame 0): the gallbladder's tets and the membrane's triangles (removed
// ones empty, with an alive flag) and the tools
// while they act (grasper: the jaws' box; cautery: the tip's ball; blade:
// the blade's edge as a line), and events.csv, the event log, to --out.
//
//   cholecystectomy --help   (the options, their defaults and units)
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "command_line.h"
#include "sinew/mesh.h"
#include "sinew/display_surfaces.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"

namespace {

using V3 = std::array<double, 3>;
constexpr double kFrame = 1.0 / 60.0;  // [s]
constexpr double kCell = 1e-3;         // the membrane's cells [m]

int fail(const std::string& what) {
  std::fprintf(stderr, "cholecystectomy: %s\n", what.c_str());
  return 1;
}

struct Box {
  V3 lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
  void add(const V3& p) {
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  }
};

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "cholecystectomy",
      "A cholecystectomy-like sequence on the gallbladder: a grasper lifts the membrane joining it to the\n"
      "liver bed, a cautery tip burns a strand, a blade cuts the membrane free (topology changes while the\n"
      "scene runs), 150 frames of 1/60 s. Prints each topology event; writes cholecystectomy.pvd (the\n"
      "gallbladder, the membrane and the tools while they act) and events.csv into --out.");
  std::string backend = "auto", out = cli.default_out();
  int every = 5;
  cli.add_backend(backend);
  cli.app().add_option("--every", every, "Write the VTU files every N frames of 1/60 s")
      ->check(sinew::examples::at_least(1));
  cli.add_out(out);
  if (auto exit = cli.parse(argc, argv)) return *exit;

  auto gallbladder = sinew::read_tet_mesh(std::string(SINEW_DATA_DIR) + "/meshes/tet/gallbladder_volumetric.vtk");
  if (!gallbladder) return fail(gallbladder.error().message());
  sinew::scale_mesh(*gallbladder, 1e-3);
  Box g;
  for (const auto& v : gallbladder->vertices) g.add(v);

  // The membrane under the gallbladder's middle: 40 mm along x, 20 mm
  // along z from the gallbladder's lowest point towards -z, 1 mm below it;
  // two triangles a 1 mm cell.
  const V3 centre{0.5 * (g.lo[0] + g.hi[0]), g.lo[1], 0.5 * (g.lo[2] + g.hi[2])};
  const double near_z = centre[2], far_z = centre[2] - 0.02;
  sinew::TriMesh membrane;
  constexpr int kNx = 40, kNz = 20;
  for (int i = 0; i <= kNx; ++i)
    for (int k = 0; k <= kNz; ++k) membrane.vertices.push_back({centre[0] - 0.02 + i * kCell, centre[1] - kCell, far_z + k * kCell});
  for (std::uint32_t i = 0; i < kNx; ++i)
    for (std::uint32_t k = 0; k < kNz; ++k) {
      const std::uint32_t a = i * (kNz + 1) + k, b = a + 1, c = a + kNz + 1, d = c + 1;
      membrane.triangles.push_back({a, b, d});
      membrane.triangles.push_back({a, d, c});
    }

  sinew::SceneDesc scene;
  scene.solver.time_step = kFrame;
  scene.solver.substeps = 10;
  scene.solver.iterations = 2;
  scene.topology_changes = true;
  scene.graspers.push_back({.capacity = 64, .compliance = 0.0});
  sinew::TetBodyDesc organ;
  organ.mesh = *gallbladder;
  organ.density = 1050.0;
  if (auto s = organ.set_material(sinew::TetMaterial::corotational, 2e4, 0.45); !s) return fail(s.error().message());
  organ.velocity_damping = 2.0;
  for (std::uint32_t v = 0; v < organ.mesh.vertices.size(); ++v)
    if (organ.mesh.vertices[v][1] > g.hi[1] - 0.2 * (g.hi[1] - g.lo[1])) organ.pinned.push_back(v);
  scene.tet_bodies.push_back(organ);
  sinew::TriBodyDesc sheet;
  sheet.mesh = membrane;
  sheet.density = 1050.0;
  sheet.thickness = 1e-3;
  sheet.distance_compliance = 1.0 / 5e4;  // 50 kPa
  sheet.area_compliance = 1.0 / 5e4;
  // No bending constraints: a membrane this thin drapes (and each hinge
  // costs about as much as its two triangles' area and edges together).
  sheet.velocity_damping = 2.0;
  // The near edge is attached to the gallbladder, two ways: each vertex
  // there to its three nearest gallbladder vertices (the first of equals),
  // each at their rest distance. One strut would let the vertex swing
  // about its organ vertex like a pendulum; three hold it where it lies.
  std::size_t fastened = 0;
  for (std::uint32_t v = 0; v < sheet.mesh.vertices.size(); ++v) {
    const V3& p = sheet.mesh.vertices[v];
    if (p[2] < far_z + 1e-9) sheet.pinned.push_back(v);  // the liver bed
    if (p[2] < near_z - 1e-9) continue;
    std::vector<std::pair<double, std::uint32_t>> by_distance;  // (squared distance, gallbladder vertex)
    for (std::uint32_t u = 0; u < organ.mesh.vertices.size(); ++u) {
      double d2 = 0.0;
      for (int a = 0; a < 3; ++a) d2 += (organ.mesh.vertices[u][a] - p[a]) * (organ.mesh.vertices[u][a] - p[a]);
      by_distance.emplace_back(d2, u);
    }
    std::partial_sort(by_distance.begin(), by_distance.begin() + 3, by_distance.end());
    for (int k = 0; k < 3; ++k)
      scene.body_attachments.push_back(
          {.a = {.body_kind = sinew::BodyKind::tri, .body = 0, .vertices = {v}, .weights = {1.0}},
           .b = {.body_kind = sinew::BodyKind::tet, .body = 0, .vertices = {by_distance[k].second}, .weights = {1.0}},
           .compliance = 0.0,
           .rest_length = std::sqrt(by_distance[k].first)});
    ++fastened;
  }
  scene.tri_bodies.push_back(sheet);
  auto sim = sinew::Simulation::create(scene, {.backend = backend});
  if (!sim) return fail(sim.error().message());
  const std::uint32_t sheet_first = sim->info().tri_body_first_particle[0];
  // The features' handles and the ids of what the script drives.
  sinew::Topology topology = sim->topology();
  const auto grasper = sim->graspers().grasper(0);
  const auto gallbladder_id = topology.tet_body(0);
  const auto membrane_id = topology.tri_body(0);
  if (!grasper || !gallbladder_id || !membrane_id) return fail("the scene lacks its grasper or bodies");
  std::printf("cholecystectomy: %s; gallbladder %zu tets, membrane %zu triangles (%zu vertices fastened to the "
              "gallbladder)\n",
              sim->device_name().c_str(), organ.mesh.tets.size(), sheet.mesh.triangles.size(), fastened);

  std::printf("  %u colours a sweep, %u dispatches and %u barriers a frame\n", sim->info().colors,
              sim->info().dispatches_per_frame, sim->info().barriers_per_frame);
  std::FILE* log = std::fopen((out + "/events.csv").c_str(), "w");
  if (!log) return fail("cannot write " + out + "/events.csv");
  std::fprintf(log, "time_s,event,body_kind,body,triangles_removed,vertices_removed,constraints_removed,"
                    "edges_softened,mass_moved_kg,mass_removed_kg,wall_ms,rebuild_ms\n");
  auto record = [&](double t, const char* what, const sinew::TopologyEvent& e) {
    if (e.triangles_removed.empty()) return;
    std::fprintf(log, "%.4f,%s,tri,%zu,%zu,%zu,%u,%u,%.4g,%.4g,%.3f,%.3f\n", t, what, e.body,
                 e.triangles_removed.size(), e.vertices_removed.size(), e.constraints_removed, e.edges_softened,
                 e.mass_moved, e.mass_removed, e.wall_ms, e.rebuild_ms);
    std::printf("  %5.3f s  %-8s %3zu triangles, %2zu vertices, %3u constraints removed, %3u edges softened; "
                "%.2f ms (rebuild %.2f)\n",
                t, what, e.triangles_removed.size(), e.vertices_removed.size(), e.constraints_removed,
                e.edges_softened, e.wall_ms, e.rebuild_ms);
  };

  // The strand the cautery burns: the membrane vertex 12 mm right of the
  // middle, 4 mm from the liver bed (at rest).
  std::uint32_t strand = 0;
  for (std::uint32_t v = 0; v < sheet.mesh.vertices.size(); ++v) {
    const V3& p = sheet.mesh.vertices[v];
    if (std::abs(p[0] - (centre[0] + 0.012)) < 0.5 * kCell && std::abs(p[2] - (far_z + 4e-3)) < 0.5 * kCell) strand = v;
  }

  const int frames = 150;
  std::vector<float> x;
  std::vector<double> frame_ms;
  sinew::Pose jaws;
  V3 grasped_at{};  // where the jaws closed
  std::size_t held = 0;
  auto output = sinew::SceneOutput::create(
      scene, out,
      {.bodies = {{.kind = sinew::BodyKind::tet, .name = "gallbladder"}, {.kind = sinew::BodyKind::tri, .name = "membrane"}},
       .name = "cholecystectomy"});
  if (!output) return fail(output.error().message());
  if (auto s = output->write(*sim, 0); !s) return fail(s.error().message());
  const std::array<double, 3> jaws_half_extents{1.5e-3, 2e-3, 1.5e-3};  // 3 x 3 vertices
  for (int frame = 1; frame <= frames; ++frame) {
    const double t = frame * kFrame;
    const auto t0 = std::chrono::steady_clock::now();
    if (auto s = sim->read_positions(x); !s) return fail(s.error().message());
    // The grasper: closes on the membrane's middle at 0.5 s, lifts 15 mm by
    // 1.5 s (linearly in the frame number) and holds it there.
    if (frame == 30) {
      // Where the membrane's middle hangs now (the mean of its vertices
      // within 1.5 mm of the middle at rest).
      V3 middle{};
      int n = 0;
      for (std::uint32_t v = 0; v < sheet.mesh.vertices.size(); ++v) {
        const V3& p = sheet.mesh.vertices[v];
        if (std::abs(p[0] - centre[0]) > 1.5e-3 || std::abs(p[2] - (near_z - 0.01)) > 1.5e-3) continue;
        for (int a = 0; a < 3; ++a) middle[a] += x[4 * (std::size_t{sheet_first} + v) + a];
        ++n;
      }
      for (double& c : middle) c /= n;
      jaws.position = middle;
      grasped_at = middle;
      auto h = sim->graspers().close(*grasper, jaws, jaws_half_extents);
      if (!h) return fail(h.error().message());
      held = h->size();
      std::printf("  %5.3f s  grasp    %zu particles held\n", t, held);
    } else if (frame > 30) {
      jaws.position[1] = grasped_at[1] + 0.015 * std::min(double(frame - 30) / 60.0, 1.0);
      if (auto s = sim->graspers().move(*grasper, jaws); !s) return fail(s.error().message());
    }
    // Cautery: a 3 mm tip held on a strand near the liver edge, 0.8 to
    // 1.2 s: it touches the membrane where that strand is now (the
    // membrane sags and swings under the grasper).
    std::optional<V3> cautery_tip;  // where the cautery touches this frame
    if (t >= 0.8 && t < 1.2) {
      const float* tip = &x[4 * (std::size_t{sheet_first} + strand)];
      cautery_tip = V3{tip[0], tip[1], tip[2]};
      auto e = topology.cauterize(*membrane_id, {tip[0], tip[1], tip[2]}, 3e-3, kFrame, 0.1);
      if (!e) return fail(e.error().message());
      record(t, "cautery", *e);
    }
    // The blade: from 1.5 s it sweeps along the gallbladder edge across the
    // membrane, 2 mm a frame, following the tissue: each stroke is placed on
    // the membrane vertex that lay 2 mm from the edge at rest, where that
    // vertex is now (the membrane pulls the gallbladder's bottom towards
    // the liver as the grasper lifts it, so a fixed line would miss). A
    // stroke runs from 3 mm behind that vertex to 1 mm past it, 6 mm above
    // to 9 mm below it: each starts 2 mm back of the last one's end, since a
    // stroke cuts what it touches where the tissue is now and the membrane
    // moves between frames (strokes that only met end to end left uncut
    // tissue that had swung back across the line).
    std::optional<sinew::Blade> blade;  // the blade's edge at the end of this frame's stroke
    if (frame >= 90 && frame <= 110) {
      const std::uint32_t on_line = static_cast<std::uint32_t>(2 * (frame - 90)) * (kNz + 1) + (kNz - 2);
      const float* q = &x[4 * (std::size_t{sheet_first} + on_line)];
      const auto at = [&](double dx, double dy) { return V3{q[0] + dx, q[1] + dy, q[2] + 0.0}; };
      const sinew::Blade from{at(-3e-3, 6e-3), at(-3e-3, -9e-3)};
      const sinew::Blade to{at(1e-3, 6e-3), at(1e-3, -9e-3)};
      blade = to;
      auto e = topology.cut(*membrane_id, from, to);
      if (!e) return fail(e.error().message());
      record(t, "cut", *e);
    }
    if (auto s = sim->step(); !s) return fail(s.error().message());
    frame_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    if (frame % every != 0) continue;

    if (auto s = sim->read_positions(x); !s) return fail(s.error().message());
    for (float c : x)
      if (!std::isfinite(c)) return fail("a position is not finite at " + std::to_string(t) + " s");
    // The tools while they act.
    if (frame >= 30) output->add_surface("grasper", sinew::box_surface(jaws_half_extents, jaws));
    if (cautery_tip) output->add_surface("cautery", sinew::capsule_surface(3e-3, 0.0, {.position = *cautery_tip}));
    if (blade) output->add_polyline("blade", std::array{blade->a, blade->b});
    if (auto s = output->write(*sim, frame); !s) return fail(s.error().message());
  }
  std::fclose(log);
  // The cut freed the membrane: the gap between the live vertices on the
  // gallbladder's side of the blade's line (rest z > near_z - 2 mm) and
  // those on the liver's side (rest z < near_z - 3 mm), at the end.
  auto live = topology.current_triangles(*membrane_id);
  if (!live) return fail(live.error().message());
  std::vector<std::uint8_t> used(sheet.mesh.vertices.size(), 0);
  for (const auto& triangle : *live)
    for (std::uint32_t v : triangle) used[v] = 1;
  if (auto s = sim->read_positions(x); !s) return fail(s.error().message());
  double gap = std::numeric_limits<double>::infinity();
  for (std::uint32_t a = 0; a < sheet.mesh.vertices.size(); ++a) {
    if (!used[a] || sheet.mesh.vertices[a][2] <= near_z - 2e-3) continue;
    for (std::uint32_t b = 0; b < sheet.mesh.vertices.size(); ++b) {
      if (!used[b] || sheet.mesh.vertices[b][2] >= near_z - 3e-3) continue;
      double d2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double d = x[4 * (std::size_t{sheet_first} + a) + k] - x[4 * (std::size_t{sheet_first} + b) + k];
        d2 += d * d;
      }
      gap = std::min(gap, std::sqrt(d2));
    }
  }
  // And whether any live triangles still join the gallbladder's edge to
  // the liver's (the membrane's pieces, by shared vertices).
  std::vector<std::uint32_t> root(sheet.mesh.vertices.size());
  for (std::uint32_t v = 0; v < root.size(); ++v) root[v] = v;
  auto find = [&](std::uint32_t v) {
    while (root[v] != v) v = root[v] = root[root[v]];
    return v;
  };
  for (const auto& triangle : *live)
    for (int k = 1; k < 3; ++k) root[find(triangle[k])] = find(triangle[0]);
  bool joined = false;
  for (std::uint32_t a = 0; a < root.size() && !joined; ++a) {
    if (!used[a] || sheet.mesh.vertices[a][2] < near_z - 1e-9) continue;  // the gallbladder's edge
    for (std::uint32_t b = 0; b < root.size() && !joined; ++b)
      joined = used[b] && sheet.mesh.vertices[b][2] < far_z + 1e-9 && find(a) == find(b);  // the liver's
  }
  std::sort(frame_ms.begin(), frame_ms.end());
  std::printf("cholecystectomy: membrane %zu of %zu triangles left; the gallbladder's edge is %s the liver's; across the "
              "cut the nearest live vertices are %.1f mm apart (1 mm at rest); frame median %.1f ms, slowest %.1f ms; "
              "wrote %d frames and events.csv to %s\n",
              live->size(), sheet.mesh.triangles.size(), joined ? "still joined to" : "cut free of", 1e3 * gap,
              frame_ms[frame_ms.size() / 2], frame_ms.back(), 1 + frames / every, out.c_str());
  if (joined) return fail("the blade left the membrane joined to the gallbladder");
  return 0;
}
