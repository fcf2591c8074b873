// feature_readers.cpp — a scene file's solver settings, colliders, level
// sets, tools, needles, graspers, attachments (to targets and between
// bodies) and mesh collision. Keys are
// the fields of the structs in sinew/scene.h, enumerators their names.
#include <cmath>
#include <limits>

#include "scene_file/readers.h"
#include "sinew/mesh.h"

namespace sinew::scene_file {

void read_solver(const Json& v, const std::string& path, Context& ctx, SolverSettings& out) {
  Object o(v, path, ctx);
  if (const Json* m = o.find("method"))
    read_enum(*m, o.path("method"), ctx, {{"xpbd", SolverMethod::xpbd}, {"vbd", SolverMethod::vbd}}, out.method);
  o.read("time_step", out.time_step);
  o.read("substeps", out.substeps);
  o.read("iterations", out.iterations);
  o.read("contact_sweeps", out.contact_sweeps);
  o.read("measure_errors", out.measure_errors);
  o.read("reorder_particles", out.reorder_particles);
  o.read("residual_tolerance", out.residual_tolerance);
  o.read("max_iterations", out.max_iterations);
  o.read("check_interval", out.check_interval);
  o.read("time_budget_ms", out.time_budget_ms);
  o.read("warm_start", out.warm_start);
  o.read("chebyshev_rho", out.chebyshev_rho);
  o.read("chebyshev_gamma", out.chebyshev_gamma);
  o.read("chebyshev_delay", out.chebyshev_delay);
  o.finish();
}

namespace {

// A level set: {"file" (closed binary STL) and "scale" | "sphere": {"centre",
// "radius"} | "box": {"min", "max"}}, with "voxel_size", "exterior_band"
// and "interior_band" (LevelSetSettings; "whole": the whole inside stored,
// infinity, as a level set that is cut needs).
void read_level_set(const Json& v, const std::string& path, const Where& where, Context& ctx,
                    std::optional<LevelSet>& out) {
  Object o(v, path, ctx);
  LevelSetSettings settings;
  o.read("voxel_size", settings.voxel_size);
  o.read("exterior_band", settings.exterior_band);
  if (const Json* band = o.find("interior_band")) {
    if (band->is_string() && band->get_ref<const std::string&>() == "whole")
      settings.interior_band = std::numeric_limits<double>::infinity();
    else if (band->is_string() && !ctx.failed())
      ctx.fail(ErrorCode::bad_input_file, o.path("interior_band"), "must be a number [m] or \"whole\" (the whole inside)");
    else
      read_double(*band, o.path("interior_band"), ctx, settings.interior_band);
  }
  const int sources = o.has("file") + o.has("sphere") + o.has("box");
  if (!ctx.failed() && sources != 1)
    return ctx.fail(ErrorCode::bad_input_file, path, "needs exactly one of \"file\", \"sphere\" or \"box\"");
  double scale = 1.0;
  o.read("scale", scale);
  if (!ctx.failed() && !(scale > 0.0)) return ctx.fail(ErrorCode::bad_parameter, o.path("scale"), "must be > 0");
  Result<LevelSet> made = Error(ErrorCode::internal, "no level set");
  if (o.has("file")) {
    const std::filesystem::path p = read_file_member(o, where, ctx);
    if (ctx.failed()) return;
    auto surface = read_stl(p);
    if (!surface) return ctx.fail(ErrorCode::bad_input_file, o.path("file"), surface.error().message());
    if (scale != 1.0) scale_mesh(*surface, scale);
    made = LevelSet::from_mesh(*surface, settings);
  } else if (const Json* s = o.find("sphere")) {
    Object so(*s, o.path("sphere"), ctx);
    std::array<double, 3> centre{};
    double radius = 0.0;
    so.read("centre", centre, true);
    so.read("radius", radius, true);
    so.finish();
    if (ctx.failed()) return;
    made = LevelSet::sphere(centre, radius, settings);
  } else if (const Json* b = o.find("box")) {
    Object bo(*b, o.path("box"), ctx);
    std::array<double, 3> lo{}, hi{};
    bo.read("min", lo, true);
    bo.read("max", hi, true);
    bo.finish();
    if (ctx.failed()) return;
    made = LevelSet::box(lo, hi, settings);
  }
  o.finish();
  if (ctx.failed()) return;
  if (!made) return ctx.fail(made.error().code(), path, made.error().message());
  out = std::move(*made);
}

void read_implicit_node(const Json& v, const std::string& path, Context& ctx, ImplicitNode& out) {
  Object o(v, path, ctx);
  if (const Json* op = o.find("op"))
    read_enum(*op, o.path("op"), ctx,
              {{"half_space", ImplicitOp::half_space}, {"sphere", ImplicitOp::sphere}, {"capsule", ImplicitOp::capsule},
               {"box", ImplicitOp::box}, {"cylinder", ImplicitOp::cylinder}, {"torus", ImplicitOp::torus},
               {"unite", ImplicitOp::unite}, {"intersect", ImplicitOp::intersect}, {"subtract", ImplicitOp::subtract}},
              out.op);
  else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("op"), "is required");
  o.read("position", out.position);
  o.read("rotation", out.rotation);
  o.read("radius", out.radius);
  o.read("half_height", out.half_height);
  o.read("half_extents", out.half_extents);
  o.read("minor_radius", out.minor_radius);
  o.read("rounding", out.rounding);
  o.finish();
}

}  // namespace

void read_collider(const Json& v, const std::string& path, const Where& where, Context& ctx, ColliderDesc& out) {
  Object o(v, path, ctx);
  if (const Json* s = o.find("shape"))
    read_enum(*s, o.path("shape"), ctx,
              {{"plane", ColliderShape::plane}, {"sphere", ColliderShape::sphere}, {"capsule", ColliderShape::capsule},
               {"box", ColliderShape::box}, {"cylinder", ColliderShape::cylinder},
               {"implicit", ColliderShape::implicit}, {"level_set", ColliderShape::level_set}},
              out.shape);
  else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("shape"), "is required");
  o.read("position", out.position);
  o.read("rotation", out.rotation);
  o.read("radius", out.radius);
  o.read("half_height", out.half_height);
  o.read("half_extents", out.half_extents);
  o.read("static_friction", out.static_friction);
  o.read("dynamic_friction", out.dynamic_friction);
  o.read("compliance", out.compliance);
  if (const Json* n = o.find("implicit"))
    read_array(*n, o.path("implicit"), ctx, [&](const Json& e, const std::string& p) {
      read_implicit_node(e, p, ctx, out.implicit.emplace_back());
    });
  if (const Json* l = o.find("level_set")) read_level_set(*l, o.path("level_set"), where, ctx, out.level_set);
  o.finish();
}

void read_tool(const Json& v, const std::string& path, const Where& where, Context& ctx, ToolDesc& out) {
  Object o(v, path, ctx);
  if (const Json* s = o.find("shape"))
    read_enum(*s, o.path("shape"), ctx, {{"capsule", ToolShape::capsule}, {"level_set", ToolShape::level_set}},
              out.shape);
  o.read("radius", out.radius);
  o.read("half_height", out.half_height);
  if (const Json* l = o.find("level_set")) read_level_set(*l, o.path("level_set"), where, ctx, out.level_set);
  o.read("penalty_stiffness", out.penalty_stiffness);
  o.read("penalty_damping", out.penalty_damping);
  o.read("mass", out.mass);
  o.read("inertia", out.inertia);
  o.read("position", out.position);
  o.read("rotation", out.rotation);
  o.read("gravity", out.gravity);
  o.read("static_friction", out.static_friction);
  o.read("dynamic_friction", out.dynamic_friction);
  o.read("compliance", out.compliance);
  if (const Json* t = o.find("trocar")) {
    Object trocar(*t, o.path("trocar"), ctx);
    TrocarDesc& d = out.trocar.emplace();
    if (trocar.find("pivot")) trocar.read("pivot", d.pivot);
    else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, trocar.path("pivot"), "is required");
    trocar.read("axis", d.axis);
    trocar.finish();
  }
  if (const Json* c = o.find("cuts")) {
    Object cuts(*c, o.path("cuts"), ctx);
    ToolCutDesc& d = out.cuts.emplace();
    cuts.read("collider", d.collider, true);
    if (const Json* cutter = cuts.find("cutter")) read_cutter(*cutter, cuts.path("cutter"), ctx, d.cutter);
    else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, cuts.path("cutter"), "is required");
    cuts.finish();
  }
  o.finish();
}

void read_needle(const Json& v, const std::string& path, Context& ctx, NeedleDesc& out) {
  Object o(v, path, ctx);
  if (const Json* c = o.find("curve"))
    read_array(*c, o.path("curve"), ctx, [&](const Json& p, const std::string& pp) {
      std::array<double, 3> x{};
      if (read_doubles(p, pp, ctx, x)) out.curve.push_back(x);
    });
  else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("curve"), "is required");
  o.read("position", out.position);
  o.read("rotation", out.rotation);
  o.read("puncture_force", out.puncture_force);
  o.read("max_puncture_angle", out.max_puncture_angle);
  o.read("compliance", out.compliance);
  o.read("thread", out.thread);
  o.read("thread_static_friction", out.thread_static_friction);
  o.read("thread_dynamic_friction", out.thread_dynamic_friction);
  o.read("tip_radius", out.tip_radius);
  o.read("shaft_friction", out.shaft_friction);
  o.read("shaft_static_friction", out.shaft_static_friction);
  o.read("shaft_viscous_friction", out.shaft_viscous_friction);
  o.read("shaft_stick_velocity", out.shaft_stick_velocity);
  o.read("cutting_force", out.cutting_force);
  if (const Json* d = o.find("drive"))
    read_enum(*d, o.path("drive"), ctx, {{"kinematic", NeedleDrive::kinematic}, {"force", NeedleDrive::force}},
              out.drive);
  o.read("mass", out.mass);
  o.read("inertia", out.inertia);
  o.read("gravity", out.gravity);
  o.finish();
}

void read_grasper(const Json& v, const std::string& path, Context& ctx, GrasperDesc& out) {
  Object o(v, path, ctx);
  o.read("capacity", out.capacity);
  o.read("point_capacity", out.point_capacity);
  o.read("compliance", out.compliance);
  o.finish();
}

void read_body_kind(const Json& v, const std::string& path, Context& ctx, BodyKind& out) {
  read_enum(v, path, ctx, {{"tet", BodyKind::tet}, {"tri", BodyKind::tri}, {"line", BodyKind::line}}, out);
}

void read_attachment(const Json& v, const std::string& path, Context& ctx, AttachmentDesc& out) {
  Object o(v, path, ctx);
  if (const Json* r = o.find("vertex")) {
    Object ro(*r, o.path("vertex"), ctx);
    if (const Json* k = ro.find("body_kind")) read_body_kind(*k, ro.path("body_kind"), ctx, out.vertex.body_kind);
    ro.read("body", out.vertex.body);
    ro.read("vertex", out.vertex.vertex, true);
    ro.finish();
  } else if (!ctx.failed()) {
    ctx.fail(ErrorCode::bad_input_file, o.path("vertex"), "is required");
  }
  o.read("target", out.target, true);
  o.read("compliance", out.compliance);
  o.finish();
}

namespace {

// {"body_kind", "body", "vertices": [1 to 4 indices], "weights": [as many numbers]}.
void read_barycentric_point(Object& parent, const std::string& key, Context& ctx, BarycentricPoint& out) {
  const Json* r = parent.find(key);
  if (!r) {
    if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, parent.path(key), "is required");
    return;
  }
  Object o(*r, parent.path(key), ctx);
  if (const Json* k = o.find("body_kind")) read_body_kind(*k, o.path("body_kind"), ctx, out.body_kind);
  o.read("body", out.body);
  if (const Json* vs = o.find("vertices"))
    read_array(*vs, o.path("vertices"), ctx, [&](const Json& e, const std::string& p) {
      read_uint32(e, p, ctx, out.vertices.emplace_back());
    });
  else if (!ctx.failed())
    ctx.fail(ErrorCode::bad_input_file, o.path("vertices"), "is required");
  if (const Json* ws = o.find("weights"))
    read_array(*ws, o.path("weights"), ctx, [&](const Json& e, const std::string& p) {
      read_double(e, p, ctx, out.weights.emplace_back());
    });
  else if (!ctx.failed())
    ctx.fail(ErrorCode::bad_input_file, o.path("weights"), "is required");
  o.finish();
}

}  // namespace

void read_body_attachment(const Json& v, const std::string& path, Context& ctx, BodyAttachmentDesc& out) {
  Object o(v, path, ctx);
  read_barycentric_point(o, "a", ctx, out.a);
  read_barycentric_point(o, "b", ctx, out.b);
  o.read("compliance", out.compliance);
  o.read("break_force", out.break_force);  // absent: infinity, never breaks
  o.read("rest_length", out.rest_length);  // absent: 0, the points held together
  o.finish();
}

void read_mesh_collision(const Json& v, const std::string& path, Context& ctx, MeshCollisionDesc& out) {
  Object o(v, path, ctx);
  o.read("enabled", out.enabled);
  if (const Json* s = o.find("schedule"))
    read_enum(*s, o.path("schedule"), ctx, {{"colored", ContactSchedule::colored},
                                                  {"jacobi", ContactSchedule::jacobi},
                                                  {"device_colored", ContactSchedule::device_colored}},
              out.schedule);
  o.read("thickness", out.thickness);
  o.read("margin", out.margin);
  o.read("self_collision", out.self_collision);
  o.read("self_culling", out.self_culling);
  o.read("tool_faces", out.tool_faces);
  o.read("face_manifold", out.face_manifold);
  o.read("compliance", out.compliance);
  o.read("static_friction", out.static_friction);
  o.read("dynamic_friction", out.dynamic_friction);
  o.read("continuous", out.continuous);
  o.read("continuous_repairs", out.continuous_repairs);
  o.read("device_colors", out.device_colors);
  o.read("device_rounds", out.device_rounds);
  o.finish();
}

void read_pose(Object& o, Pose& out) {
  o.read("position", out.position);
  o.read("rotation", out.rotation);
}

void read_cutter(const Json& v, const std::string& path, Context& ctx, CutterShape& out) {
  Object o(v, path, ctx);
  if (const Json* k = o.find("kind"))
    read_enum(*k, o.path("kind"), ctx,
              {{"sphere", CutterShape::Kind::sphere}, {"capsule", CutterShape::Kind::capsule},
               {"box", CutterShape::Kind::box}},
              out.kind);
  o.read("radius", out.radius);
  o.read("half_height", out.half_height);
  o.read("half_extents", out.half_extents);
  o.finish();
}

}  // namespace sinew::scene_file
