// fuzz_scene_json.cpp — libFuzzer target for the scene-file reader
// (parse_scene_json). Input: the JSON text; relative mesh file names
// resolve against the repository's scenes/ folder, so the seeds (the
// scene files themselves) read their meshes. Checked: a documented error
// with a message that names a JSON path (or the JSON syntax), or a scene
// that check_scene accepts and whose script names objects that exist.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_support.h"
#include "sinew/scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sinew;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const Result<SceneFile> file = parse_scene_json(text, SINEW_SCENES_DIR);
  if (!file) {
    // backend_unavailable: a level set in a build without OpenVDB (the
    // fuzz build's reader has none: it would spend its time voxelising).
    fuzz::check_error(file.error(),
                      {ErrorCode::bad_input_file, ErrorCode::bad_parameter, ErrorCode::out_of_memory,
                       ErrorCode::backend_unavailable, ErrorCode::capacity_exceeded},
                      "parse_scene_json");
    const std::string& m = file.error().message();
    if (m.empty() || (m[0] != '/' && m.rfind("not valid JSON", 0) != 0))
      fuzz::fail("parse_scene_json's message names no JSON path: " + m);
    return 0;
  }
  if (Status s = check_scene(file->scene); !s) fuzz::fail("parse_scene_json accepted a scene check_scene refuses: " + s.error().message());
  std::size_t bodies = file->scene.tet_bodies.size() + file->scene.tri_bodies.size() + file->scene.line_bodies.size();
  if (file->bodies.size() != bodies) fuzz::fail("parse_scene_json named " + std::to_string(file->bodies.size()) + " bodies of " + std::to_string(bodies));
  for (const ScriptTrack& t : file->script.poses)
    if (t.keys.empty()) fuzz::fail("a pose track without keys");
  return 0;
}
