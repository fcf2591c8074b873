// scene_file.cpp — reading a scene file (sinew/scene_file.h): the JSON
// parsed, its sections read (readers.h), the scene checked by check_scene
// with its messages turned into the file's JSON paths.
#include <fstream>
#include <sstream>

#include "scene_file/readers.h"
#include "sinew/scene_file.h"

namespace sinew {
namespace {

using scene_file::Context;
using scene_file::Json;
using scene_file::Object;

// A scene file larger than this is refused before it is read (a mesh
// belongs in a mesh file).
constexpr std::uintmax_t kMostBytes = 256u << 20;

void read_run(const Json& v, const std::string& path, Context& ctx, SceneRunSettings& out) {
  Object o(v, path, ctx);
  o.read("frames", out.frames);
  o.read("every", out.every);
  o.read("backend", out.backend);
  o.finish();
  if (ctx.failed()) return;
  if (out.frames < 1) ctx.fail(ErrorCode::bad_parameter, o.path("frames"), "must be >= 1");
  else if (out.every < 1) ctx.fail(ErrorCode::bad_parameter, o.path("every"), "must be >= 1");
  else if (out.backend != "auto" && out.backend != "cpu" && out.backend != "opencl" && out.backend != "vulkan")
    ctx.fail(ErrorCode::bad_parameter, o.path("backend"), "must be one of \"auto\", \"cpu\", \"opencl\", \"vulkan\"");
}

template <class Desc, class Reader>
void read_list(Object& root, const char* key, std::vector<Desc>& out, Reader&& read) {
  if (const Json* v = root.find(key))
    scene_file::read_array(*v, root.path(key), root.ctx(),
                           [&](const Json& e, const std::string& p) { read(e, p, out.emplace_back()); });
}

void name_bodies(SceneFile& file, BodyKind kind, std::size_t count, const char* prefix,
                 const std::vector<std::string>& names) {
  for (std::size_t i = 0; i < count; ++i)
    file.bodies.push_back({kind, static_cast<std::uint32_t>(i),
                           i < names.size() && !names[i].empty() ? names[i] : prefix + std::to_string(i)});
}

// check_scene's verdict as the file's error.
void check(const SceneDesc& scene, Context& ctx) {
  if (ctx.failed()) return;
  if (Status s = check_scene(scene); !s) {
    const auto [path, rule] = scene_file::split_scene_message(s.error().message(), scene_file::kSceneRoots);
    ctx.fail(s.error().code(), path, rule);
  }
}

Result<SceneFile> read_document(const Json& doc, const scene_file::Where& where) {
  Context ctx;
  SceneFile file;
  Object root(doc, "", ctx);
  std::string format;
  root.read("format", format);
  if (!ctx.failed() && !format.empty() && format != "sinew-scene")
    ctx.fail(ErrorCode::bad_input_file, "/format", "must be \"sinew-scene\"");
  int version = 1;
  root.read("version", version);
  if (!ctx.failed() && version != 1) ctx.fail(ErrorCode::bad_input_file, "/version", "must be 1 (the only version)");
  std::string description;
  root.read("description", description);
  if (const Json* r = root.find("run")) read_run(*r, "/run", ctx, file.run);
  SceneDesc& scene = file.scene;
  root.read("gravity", scene.gravity);
  if (const Json* s = root.find("solver")) scene_file::read_solver(*s, "/solver", ctx, scene.solver);
  std::vector<std::string> tet_names, tri_names, line_names;
  read_list(root, "tet_bodies", scene.tet_bodies, [&](const Json& e, const std::string& p, TetBodyDesc& b) {
    scene_file::read_tet_body(e, p, where, ctx, b, tet_names.emplace_back());
  });
  read_list(root, "tri_bodies", scene.tri_bodies, [&](const Json& e, const std::string& p, TriBodyDesc& b) {
    scene_file::read_tri_body(e, p, where, ctx, b, tri_names.emplace_back());
  });
  read_list(root, "line_bodies", scene.line_bodies, [&](const Json& e, const std::string& p, LineBodyDesc& b) {
    scene_file::read_line_body(e, p, ctx, b, line_names.emplace_back());
  });
  read_list(root, "colliders", scene.colliders, [&](const Json& e, const std::string& p, ColliderDesc& c) {
    scene_file::read_collider(e, p, where, ctx, c);
  });
  read_list(root, "targets", scene.targets, [&](const Json& e, const std::string& p, std::array<double, 3>& t) {
    scene_file::read_doubles(e, p, ctx, t);
  });
  read_list(root, "attachments", scene.attachments, [&](const Json& e, const std::string& p, AttachmentDesc& a) {
    scene_file::read_attachment(e, p, ctx, a);
  });
  read_list(root, "body_attachments", scene.body_attachments,
            [&](const Json& e, const std::string& p, BodyAttachmentDesc& a) {
              scene_file::read_body_attachment(e, p, ctx, a);
            });
  read_list(root, "tools", scene.tools, [&](const Json& e, const std::string& p, ToolDesc& t) {
    scene_file::read_tool(e, p, where, ctx, t);
  });
  read_list(root, "needles", scene.needles, [&](const Json& e, const std::string& p, NeedleDesc& n) {
    scene_file::read_needle(e, p, ctx, n);
  });
  read_list(root, "graspers", scene.graspers, [&](const Json& e, const std::string& p, GrasperDesc& g) {
    scene_file::read_grasper(e, p, ctx, g);
  });
  if (const Json* m = root.find("mesh_collision"))
    scene_file::read_mesh_collision(*m, "/mesh_collision", ctx, scene.mesh_collision);
  root.read("external_forces", scene.external_forces);
  root.read("topology_changes", scene.topology_changes);
  // The bodies are checked before the fluid selects triangles of them.
  check(scene, ctx);
  if (const Json* f = root.find("fluid")) {
    scene_file::read_fluid(*f, "/fluid", scene, ctx, scene.fluid.emplace());
    check(scene, ctx);
  }
  if (const Json* s = root.find("script")) scene_file::read_script(*s, "/script", ctx, file.script);
  if (const Json* h = root.find("haptics")) scene_file::read_haptics(*h, "/haptics", ctx, file.hands);
  root.finish();
  scene_file::check_script(file.script, scene, ctx);
  scene_file::check_haptics(file.hands, scene, ctx);
  if (ctx.failed()) return *ctx.error();
  name_bodies(file, BodyKind::tet, scene.tet_bodies.size(), "tet", tet_names);
  name_bodies(file, BodyKind::tri, scene.tri_bodies.size(), "tri", tri_names);
  name_bodies(file, BodyKind::line, scene.line_bodies.size(), "line", line_names);
  return file;
}

}  // namespace

Result<SceneFile> parse_scene_json(std::string_view json, const std::filesystem::path& base_dir) {
  // nlohmann::json reports syntax errors by exception: caught here, so
  // nothing escapes the API.
  Json doc;
  try {
    doc = Json::parse(json.begin(), json.end(), nullptr, true, false);
  } catch (const Json::exception& e) {
    // parse_error, and out_of_range for a number beyond a double (1e999).
    return Error(ErrorCode::bad_input_file, std::string("not valid JSON: ") + e.what());
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::out_of_memory, "out of memory parsing the scene");
  }
  try {
    return read_document(doc, {base_dir});
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::out_of_memory, "out of memory reading the scene");
  } catch (const std::exception& e) {
    return Error(ErrorCode::internal, std::string("reading the scene: ") + e.what());
  }
}

Result<SceneFile> load_scene_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return Error(ErrorCode::bad_input_file, path.string() + ": cannot be read (" + ec.message() + ")");
  if (size > kMostBytes)
    return Error(ErrorCode::bad_input_file, path.string() + ": larger than 256 MiB (meshes belong in mesh files)");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) return Error(ErrorCode::bad_input_file, path.string() + ": cannot be read");
  auto file = parse_scene_json(text.str(), path.parent_path());
  if (!file) return Error(file.error().code(), path.string() + ": " + file.error().message());
  return file;
}

}  // namespace sinew
