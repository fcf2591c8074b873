// bind_scene.cpp — scenes for Python: read from a scene file, or built
// from a dict laid out like one (written to JSON text by Python's json
// module and read by the same reader, so both check alike and errors name
// the JSON path).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include "bindings.h"
#include "errors.h"
#include "sinew/scene_file.h"

namespace py = pybind11;

namespace sinew::python {
namespace {

SceneFile from_json_text(const std::string& text, const std::filesystem::path& base_dir) {
  return take(without_gil([&] { return parse_scene_json(text, base_dir); }));
}

SceneFile from_dict(const py::dict& scene, const std::filesystem::path& base_dir) {
  std::string text;
  try {
    // allow_nan=False: NaN and infinity are not JSON; refused here by name
    // rather than written as tokens the reader would call malformed.
    text = py::module_::import("json").attr("dumps")(scene, py::arg("allow_nan") = false).cast<std::string>();
  } catch (py::error_already_set& e) {
    raise(Error{ErrorCode::bad_input_file, std::string("scene dict cannot be written as JSON: ") + e.what()});
  }
  return from_json_text(text, base_dir);
}

}  // namespace

void bind_scene(py::module_& m) {
  py::class_<SceneFile>(m, "Scene",
                        "A scene read from a scene file or a dict: the SceneDesc, its run settings and script.")
      .def_property_readonly("frames", [](const SceneFile& f) { return f.run.frames; }, "run.frames: frames to run")
      .def_property_readonly("every", [](const SceneFile& f) { return f.run.every; }, "run.every: output interval")
      .def_property_readonly("backend", [](const SceneFile& f) { return f.run.backend; }, "run.backend")
      .def_property_readonly("time_step", [](const SceneFile& f) { return f.scene.solver.time_step; }, "[s]")
      .def_property_readonly(
          "bodies",
          [](const SceneFile& f) {
            std::vector<std::tuple<std::string, std::uint32_t, std::string>> out;
            for (const SceneBodyName& b : f.bodies) out.emplace_back(body_kind_name(b.kind), b.index, b.name);
            return out;
          },
          "every body as (kind, index, name): tet bodies, then tri, then line")
      .def_property_readonly("script_actions", [](const SceneFile& f) { return f.script.actions.size(); },
                             "the script's actions")
      .def("__repr__", [](const SceneFile& f) {
        return "<Scene " + std::to_string(f.bodies.size()) + " bodies, " + std::to_string(f.run.frames) + " frames>";
      });

  m.def(
      "load_scene_file", [](const std::filesystem::path& path) { return take(without_gil([&] { return load_scene_file(path); })); },
      py::arg("path"),
      "Reads a scene file (docs/scene_files.md). Raises sinew.Error naming the file, JSON path and rule.");
  m.def("scene_from_dict", &from_dict, py::arg("scene"), py::arg("base_dir") = std::filesystem::path("."),
        "A scene from a dict laid out like a scene file's JSON; mesh files it names are relative to "
        "`base_dir` (default: the current folder). Raises sinew.Error naming the JSON path and rule.");
  m.def("scene_from_json", &from_json_text, py::arg("text"), py::arg("base_dir") = std::filesystem::path("."),
        "A scene from scene-file JSON text; file names relative to `base_dir`.");
}

}  // namespace sinew::python
