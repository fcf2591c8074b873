// fluid_reader.cpp — a scene file's "fluid": the SPH settings, particles
// (listed, or a box filled on the spacing's lattice), fixed boundary
// (listed, or box walls), emitters, sinks and the tissue surfaces it is
// coupled to.
#include <cmath>

#include "scene_file/readers.h"
#include "sinew/fluid.h"
#include "sinew/mesh.h"

namespace sinew::scene_file {
namespace {

void read_settings(const Json& v, const std::string& path, Context& ctx, FluidSettings& out) {
  Object o(v, path, ctx);
  if (const Json* m = o.find("method"))
    read_enum(*m, o.path("method"), ctx, {{"wcsph", FluidMethod::wcsph}, {"pbf", FluidMethod::pbf}}, out.method);
  o.read("spacing", out.spacing);
  o.read("support", out.support);
  o.read("rest_density", out.rest_density);
  o.read("speed_of_sound", out.speed_of_sound);
  o.read("viscosity", out.viscosity);
  o.read("boundary_viscosity", out.boundary_viscosity);
  o.read("time_step", out.time_step);
  o.read("gravity", out.gravity);
  o.read("surface_tension", out.surface_tension);
  o.read("pbf_iterations", out.pbf_iterations);
  o.read("pbf_relaxation", out.pbf_relaxation);
  o.finish();
}

void read_points(const Json& v, const std::string& path, Context& ctx, std::vector<std::array<double, 3>>& out) {
  read_array(v, path, ctx, [&](const Json& p, const std::string& pp) {
    std::array<double, 3> x{};
    if (read_doubles(p, pp, ctx, x)) out.push_back(x);
  });
}

// "fill": {"min", "max"}: a particle at min + (i + 1/2) spacing per axis
// for every lattice cell inside the box.
void fill_box(const Json& v, const std::string& path, double spacing, Context& ctx,
              std::vector<std::array<double, 3>>& out) {
  Object o(v, path, ctx);
  std::array<double, 3> lo{}, hi{};
  o.read("min", lo, true);
  o.read("max", hi, true);
  o.finish();
  if (ctx.failed()) return;
  if (!(spacing > 0.0)) return ctx.fail(ErrorCode::bad_parameter, path, "needs settings.spacing > 0");
  std::array<long long, 3> n{};
  double total = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double cells = std::floor((hi[a] - lo[a]) / spacing);
    n[a] = cells > 0.0 ? static_cast<long long>(std::min(cells, 1e7)) : 0;
    total *= double(n[a]);
  }
  // A bound on the file's work (FluidDesc::capacity is bounded likewise).
  if (total > 1e7) return ctx.fail(ErrorCode::bad_parameter, path, "makes more than 10^7 particles");
  // An empty box fills nothing (and must not walk the other axes' cells).
  if (total == 0.0) return;
  for (long long i = 0; i < n[0]; ++i)
    for (long long j = 0; j < n[1]; ++j)
      for (long long k = 0; k < n[2]; ++k)
        out.push_back({lo[0] + (double(i) + 0.5) * spacing, lo[1] + (double(j) + 0.5) * spacing,
                       lo[2] + (double(k) + 0.5) * spacing});
}

void read_surface(const Json& v, const std::string& path, const SceneDesc& scene, Context& ctx,
                  FluidSurfaceDesc& out) {
  Object o(v, path, ctx);
  if (const Json* k = o.find("body_kind")) read_body_kind(*k, o.path("body_kind"), ctx, out.body_kind);
  std::uint32_t body = 0;
  o.read("body", body);
  out.body = body;
  if (ctx.failed()) return;
  if (out.body_kind == BodyKind::line)
    return ctx.fail(ErrorCode::bad_parameter, o.path("body_kind"), "must be \"tet\" or \"tri\"");
  const std::size_t bodies = out.body_kind == BodyKind::tet ? scene.tet_bodies.size() : scene.tri_bodies.size();
  if (body >= bodies)
    return ctx.fail(ErrorCode::bad_parameter, o.path("body"),
                    "body " + std::to_string(body) + " does not exist (there are " + std::to_string(bodies) + ")");
  if (const Json* t = o.find("triangles")) {
    read_array(*t, o.path("triangles"), ctx, [&](const Json& e, const std::string& p) {
      std::array<std::uint32_t, 3> tri{};
      if (read_uint32s(e, p, ctx, tri)) out.triangles.push_back(tri);
    });
  } else {
    // The surface's triangles (a tet body's boundary, a tri body's own)
    // whose centroid, or any of whose vertices, lies in one of the boxes.
    const bool by_centroid = o.has("centroid_in");
    const char* key = by_centroid ? "centroid_in" : "any_vertex_in";
    if (const Json* s = o.find(key)) {
      const TriangleTest test = by_centroid ? TriangleTest::centroid : TriangleTest::any_vertex;
      if (by_centroid && o.has("any_vertex_in") && !ctx.failed())
        return ctx.fail(ErrorCode::bad_input_file, path, "give one of \"triangles\", \"centroid_in\", \"any_vertex_in\"");
      if (out.body_kind == BodyKind::tet) {
        const TriMesh surface = extract_boundary_surface(scene.tet_bodies[body].mesh);
        select_triangles(*s, o.path(key), ctx, surface.vertices, surface.triangles, out.triangles, test);
      } else {
        const TriMesh& mesh = scene.tri_bodies[body].mesh;
        select_triangles(*s, o.path(key), ctx, mesh.vertices, mesh.triangles, out.triangles, test);
      }
    }
  }
  o.finish();
}

}  // namespace

void read_emitter(Object& o, FluidEmitter& out) {
  o.read("centre", out.centre);
  o.read("direction", out.direction);
  o.read("radius", out.radius);
  o.read("flow_rate", out.flow_rate);
}

void read_sink(Object& o, FluidSink& out) {
  o.read("centre", out.centre);
  o.read("radius", out.radius);
}

void read_fluid(const Json& v, const std::string& path, const SceneDesc& scene, Context& ctx, SceneFluidDesc& out) {
  Object o(v, path, ctx);
  FluidDesc& fluid = out.fluid;
  if (const Json* s = o.find("settings")) read_settings(*s, o.path("settings"), ctx, fluid.settings);
  if (const Json* p = o.find("particles")) read_points(*p, o.path("particles"), ctx, fluid.particles);
  if (const Json* f = o.find("fill")) fill_box(*f, o.path("fill"), fluid.settings.spacing, ctx, fluid.particles);
  if (const Json* p = o.find("velocities")) read_points(*p, o.path("velocities"), ctx, fluid.velocities);
  if (const Json* b = o.find("boundary")) read_points(*b, o.path("boundary"), ctx, fluid.boundary);
  if (const Json* w = o.find("box_walls")) {
    // sample_box_walls(min, max, spacing, layers): a container's walls.
    Object wo(*w, o.path("box_walls"), ctx);
    std::array<double, 3> lo{}, hi{};
    int layers = 2;
    wo.read("min", lo, true);
    wo.read("max", hi, true);
    wo.read("layers", layers);
    wo.finish();
    if (!ctx.failed()) {
      auto walls = sample_box_walls(lo, hi, fluid.settings.spacing, layers);
      if (!walls) ctx.fail(walls.error().code(), o.path("box_walls"), walls.error().message());
      else fluid.boundary.insert(fluid.boundary.end(), walls->begin(), walls->end());
    }
  }
  if (const Json* e = o.find("emitters"))
    read_array(*e, o.path("emitters"), ctx, [&](const Json& x, const std::string& p) {
      Object eo(x, p, ctx);
      read_emitter(eo, fluid.emitters.emplace_back());
      eo.finish();
    });
  if (const Json* s = o.find("sinks"))
    read_array(*s, o.path("sinks"), ctx, [&](const Json& x, const std::string& p) {
      Object so(x, p, ctx);
      read_sink(so, fluid.sinks.emplace_back());
      so.finish();
    });
  o.read("capacity", fluid.capacity);
  if (const Json* s = o.find("surfaces"))
    read_array(*s, o.path("surfaces"), ctx, [&](const Json& x, const std::string& p) {
      read_surface(x, p, scene, ctx, out.surfaces.emplace_back());
    });
  o.finish();
}

}  // namespace sinew::scene_file
