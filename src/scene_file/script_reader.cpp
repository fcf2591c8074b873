// script_reader.cpp — a scene file's "script": keyframed poses and forces,
// and actions at given frames (docs/scene_files.md, "Script").
#include <algorithm>
#include <limits>

#include "scene_file/readers.h"

namespace sinew::scene_file {
namespace {

constexpr int kMostFrames = 100'000'000;

// A track: {"<subject>": index, "keys": [{"frame", ...}]}, its subject one of `subjects`.
void read_track(const Json& v, const std::string& path, Context& ctx, bool forces,
                std::initializer_list<std::pair<const char*, ScriptSubject>> subjects, ScriptTrack& out) {
  Object o(v, path, ctx);
  int named = 0;
  for (const auto& [key, subject] : subjects)
    if (o.has(key)) {
      ++named;
      out.subject = subject;
      o.read(key, out.index);
    }
  if (!ctx.failed() && named != 1) {
    std::string all;
    for (const auto& [key, subject] : subjects) all += (all.empty() ? "\"" : ", \"") + std::string(key) + "\"";
    return ctx.fail(ErrorCode::bad_input_file, path, "needs exactly one of " + all);
  }
  if (const Json* k = o.find("keys")) {
    read_array(*k, o.path("keys"), ctx, [&](const Json& e, const std::string& p) {
      Object ko(e, p, ctx);
      ScriptKey key;
      long long frame = 0;
      if (const Json* f = ko.find("frame")) read_int(*f, ko.path("frame"), ctx, 0, kMostFrames, frame);
      else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, ko.path("frame"), "is required");
      key.frame = static_cast<int>(frame);
      if (forces) {
        ko.read("force", key.position);
        ko.read("torque", key.torque);
      } else {
        ko.read("position", key.position, true);
        ko.read("rotation", key.rotation);
      }
      ko.finish();
      if (!out.keys.empty() && !ctx.failed() && key.frame <= out.keys.back().frame)
        ctx.fail(ErrorCode::bad_parameter, ko.path("frame"), "must be greater than the previous key's frame");
      out.keys.push_back(key);
    });
    if (!ctx.failed() && out.keys.empty()) ctx.fail(ErrorCode::bad_parameter, o.path("keys"), "must not be empty");
  } else if (!ctx.failed()) {
    ctx.fail(ErrorCode::bad_input_file, o.path("keys"), "is required");
  }
  if (!forces && o.has("relative")) {
    o.read("relative", out.relative);
    if (!ctx.failed() && out.relative && out.subject != ScriptSubject::grasper)
      ctx.fail(ErrorCode::bad_parameter, o.path("relative"),
               "only a grasper's track can be relative (to the pose its jaws closed at)");
  }
  o.finish();
}

// A landmark: {"body_kind", "body", "vertices": [...], "offset"}.
void read_landmark(Object& o, const std::string& key, ScriptLandmark& out) {
  Context& ctx = o.ctx();
  const Json* v = o.find(key);  // null once an earlier key failed: that error stands
  if (!v) return;
  Object lo(*v, o.path(key), ctx);
  if (const Json* k = lo.find("body_kind")) read_body_kind(*k, lo.path("body_kind"), ctx, out.body_kind);
  lo.read("body", out.body, true);
  if (const Json* vs = lo.find("vertices")) {
    read_array(*vs, lo.path("vertices"), ctx, [&](const Json& x, const std::string& p) {
      std::uint32_t i = 0;
      if (read_uint32(x, p, ctx, i)) out.vertices.push_back(i);
    });
    if (!ctx.failed() && out.vertices.empty()) ctx.fail(ErrorCode::bad_parameter, lo.path("vertices"), "must not be empty");
  } else if (!ctx.failed()) {
    ctx.fail(ErrorCode::bad_input_file, lo.path("vertices"), "is required");
  }
  lo.read("offset", out.offset);
  lo.finish();
}

// An action's point: a landmark under "at", or the numbers under `key`
// (required unless `optional`), not both.
void read_point_or_landmark(Object& o, const char* key, bool optional, std::array<double, 3>& point,
                            std::optional<ScriptLandmark>& at) {
  if (!o.has("at")) return o.read(key, point, !optional);
  if (o.has(key) && !o.ctx().failed())
    return o.ctx().fail(ErrorCode::bad_input_file, o.path(key),
                        std::string("give \"") + key + "\" or \"at\" (a landmark), not both");
  read_landmark(o, "at", at.emplace());
}

void read_blade(Object& o, const std::string& key, std::array<double, 3>& a, std::array<double, 3>& b) {
  const Json* v = o.find(key);
  if (!v) {
    if (!o.ctx().failed()) o.ctx().fail(ErrorCode::bad_input_file, o.path(key), "is required");
    return;
  }
  Object bo(*v, o.path(key), o.ctx());
  bo.read("a", a, true);
  bo.read("b", b, true);
  bo.finish();
}

void read_action(const Json& v, const std::string& path, Context& ctx, ScriptAction& out) {
  Object o(v, path, ctx);
  long long frame = 1;
  if (const Json* f = o.find("frame")) read_int(*f, o.path("frame"), ctx, 1, kMostFrames, frame);
  else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("frame"), "is required");
  out.frame = static_cast<int>(frame);
  if (const Json* d = o.find("do"))
    read_enum(*d, o.path("do"), ctx,
              {{"close_grasper", ScriptActionKind::close_grasper}, {"open_grasper", ScriptActionKind::open_grasper},
               {"cut", ScriptActionKind::cut}, {"cauterize", ScriptActionKind::cauterize},
               {"remove", ScriptActionKind::remove}, {"cut_collider", ScriptActionKind::cut_collider},
               {"set_emitter", ScriptActionKind::set_emitter}, {"set_sink", ScriptActionKind::set_sink}},
              out.kind);
  else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("do"), "is required");
  if (ctx.failed()) return;
  switch (out.kind) {
    case ScriptActionKind::close_grasper:
      o.read("grasper", out.index, true);
      read_point_or_landmark(o, "position", true, out.pose.position, out.at);
      o.read("rotation", out.pose.rotation);
      o.read("half_extents", out.half_extents, true);
      break;
    case ScriptActionKind::open_grasper: o.read("grasper", out.index, true); break;
    case ScriptActionKind::cut:
    case ScriptActionKind::cauterize:
    case ScriptActionKind::remove:
      if (const Json* k = o.find("body_kind")) read_body_kind(*k, o.path("body_kind"), ctx, out.body_kind);
      o.read("body", out.index, true);
      if (out.kind == ScriptActionKind::cut) {
        read_blade(o, "from", out.a_from, out.b_from);
        read_blade(o, "to", out.a_to, out.b_to);
        if (o.has("at")) read_landmark(o, "at", out.at.emplace());  // the blade's points relative to it
      } else if (out.kind == ScriptActionKind::cauterize) {
        read_point_or_landmark(o, "centre", false, out.centre, out.at);
        o.read("radius", out.radius, true);
        o.read("seconds", out.seconds, true);
        o.read("dwell_time", out.dwell_time, true);
      } else if (const Json* e = o.find("elements")) {
        read_array(*e, o.path("elements"), ctx, [&](const Json& x, const std::string& p) {
          std::uint32_t i = 0;
          if (read_uint32(x, p, ctx, i)) out.elements.push_back(i);
        });
      } else {
        ctx.fail(ErrorCode::bad_input_file, o.path("elements"), "is required");
      }
      break;
    case ScriptActionKind::cut_collider:
      o.read("collider", out.index, true);
      if (const Json* c = o.find("cutter")) read_cutter(*c, o.path("cutter"), ctx, out.cutter);
      for (auto [key, pose] : {std::pair{"from", &out.from}, std::pair{"to", &out.to}}) {
        if (const Json* p = o.find(key)) {
          Object po(*p, o.path(key), ctx);
          read_pose(po, *pose);
          po.finish();
        } else if (!ctx.failed()) {
          ctx.fail(ErrorCode::bad_input_file, o.path(key), "is required");
        }
      }
      break;
    case ScriptActionKind::set_emitter:
      o.read("emitter", out.index, true);
      read_emitter(o, out.emitter);
      break;
    case ScriptActionKind::set_sink:
      o.read("sink", out.index, true);
      read_sink(o, out.sink);
      break;
  }
  o.finish();
}

const char* subject_key(ScriptSubject s) {
  switch (s) {
    case ScriptSubject::collider: return "collider";
    case ScriptSubject::target: return "target";
    case ScriptSubject::grasper: return "grasper";
    case ScriptSubject::needle: return "needle";
    case ScriptSubject::tool: return "tool";
  }
  return "?";
}

std::size_t count_of(const SceneDesc& scene, ScriptSubject s) {
  switch (s) {
    case ScriptSubject::collider: return scene.colliders.size();
    case ScriptSubject::target: return scene.targets.size();
    case ScriptSubject::grasper: return scene.graspers.size();
    case ScriptSubject::needle: return scene.needles.size();
    case ScriptSubject::tool: return scene.tools.size();
  }
  return 0;
}

void check_index(Context& ctx, const std::string& path, const char* what, std::size_t index, std::size_t count) {
  if (!ctx.failed() && index >= count)
    ctx.fail(ErrorCode::bad_parameter, path,
             std::string(what) + " " + std::to_string(index) + " does not exist (the scene has " +
                 std::to_string(count) + ")");
}

// The landmark's body exists and every vertex is one of its mesh's.
void check_landmark(Context& ctx, const std::string& path, const ScriptLandmark& l, const SceneDesc& scene) {
  const std::size_t bodies = l.body_kind == BodyKind::tet   ? scene.tet_bodies.size()
                             : l.body_kind == BodyKind::tri ? scene.tri_bodies.size()
                                                            : scene.line_bodies.size();
  check_index(ctx, path, "body", l.body, bodies);
  if (ctx.failed()) return;
  const std::size_t vertices = l.body_kind == BodyKind::tet   ? scene.tet_bodies[l.body].mesh.vertices.size()
                               : l.body_kind == BodyKind::tri ? scene.tri_bodies[l.body].mesh.vertices.size()
                                                              : scene.line_bodies[l.body].vertices.size();
  for (std::uint32_t v : l.vertices)
    if (v >= vertices)
      return ctx.fail(ErrorCode::bad_parameter, path,
                      "vertex " + std::to_string(v) + " is out of range (the body has " + std::to_string(vertices) + ")");
}

}  // namespace

void read_script(const Json& v, const std::string& path, Context& ctx, SceneScript& out) {
  Object o(v, path, ctx);
  if (const Json* p = o.find("poses"))
    read_array(*p, o.path("poses"), ctx, [&](const Json& t, const std::string& tp) {
      read_track(t, tp, ctx, false,
                 {{"collider", ScriptSubject::collider}, {"target", ScriptSubject::target},
                  {"grasper", ScriptSubject::grasper}, {"needle", ScriptSubject::needle}},
                 out.poses.emplace_back());
    });
  if (const Json* f = o.find("forces"))
    read_array(*f, o.path("forces"), ctx, [&](const Json& t, const std::string& tp) {
      read_track(t, tp, ctx, true, {{"tool", ScriptSubject::tool}, {"needle", ScriptSubject::needle}},
                 out.forces.emplace_back());
    });
  if (const Json* a = o.find("actions"))
    read_array(*a, o.path("actions"), ctx, [&](const Json& x, const std::string& xp) {
      read_action(x, xp, ctx, out.actions.emplace_back());
    });
  o.finish();
  std::stable_sort(out.actions.begin(), out.actions.end(),
                   [](const ScriptAction& a, const ScriptAction& b) { return a.frame < b.frame; });
}

void check_script(const SceneScript& script, const SceneDesc& scene, Context& ctx) {
  const auto tracks = [&](const std::vector<ScriptTrack>& list, const char* key) {
    for (std::size_t i = 0; i < list.size(); ++i)
      check_index(ctx, "/script/" + std::string(key) + "/" + std::to_string(i) + "/" + subject_key(list[i].subject),
                  subject_key(list[i].subject), list[i].index, count_of(scene, list[i].subject));
  };
  tracks(script.poses, "poses");
  tracks(script.forces, "forces");
  // Actions were sorted by frame: name them by frame and kind.
  const std::size_t emitters = scene.fluid ? scene.fluid->fluid.emitters.size() : 0;
  const std::size_t sinks = scene.fluid ? scene.fluid->fluid.sinks.size() : 0;
  for (const ScriptAction& a : script.actions) {
    const std::string at = "/script/actions (frame " + std::to_string(a.frame) + ")";
    switch (a.kind) {
      case ScriptActionKind::close_grasper:
      case ScriptActionKind::open_grasper: check_index(ctx, at, "grasper", a.index, scene.graspers.size()); break;
      case ScriptActionKind::cut:
      case ScriptActionKind::cauterize:
      case ScriptActionKind::remove: {
        const std::size_t n = a.body_kind == BodyKind::tet   ? scene.tet_bodies.size()
                              : a.body_kind == BodyKind::tri ? scene.tri_bodies.size()
                                                             : scene.line_bodies.size();
        check_index(ctx, at, "body", a.index, n);
        if (!ctx.failed() && a.kind != ScriptActionKind::remove && a.body_kind == BodyKind::line)
          ctx.fail(ErrorCode::bad_parameter, at, "cuts and cautery act on tet and tri bodies");
        if (!ctx.failed() && !scene.topology_changes)
          ctx.fail(ErrorCode::bad_parameter, at, "needs \"topology_changes\": true in the scene");
        break;
      }
      case ScriptActionKind::cut_collider: check_index(ctx, at, "collider", a.index, scene.colliders.size()); break;
      case ScriptActionKind::set_emitter: check_index(ctx, at, "emitter", a.index, emitters); break;
      case ScriptActionKind::set_sink: check_index(ctx, at, "sink", a.index, sinks); break;
    }
    if (a.at) check_landmark(ctx, at + "/at", *a.at, scene);
  }
}

}  // namespace sinew::scene_file
