// readers.h — the scene file's sections, each read from its JSON object
// into the SceneDesc's structs (docs/scene_files.md is the format). Each
// records the first problem in the Context and leaves the rest undone.
#pragma once

#include <filesystem>
#include <string_view>
#include <vector>

#include "scene_file/json_fields.h"
#include "sinew/scene.h"
#include "sinew/scene_file.h"

namespace sinew::scene_file {

/// Where relative file names in the document are resolved.
struct Where {
  std::filesystem::path base_dir;
};

/// The prefix of a file name found in the data folder: "data:meshes/tet/x.node".
inline constexpr std::string_view kDataPrefix = "data:";

/// The data folder "data:" names are found in (data_folder.cpp).
struct DataFolder {
  std::filesystem::path path;
  bool from_environment = false;  ///< SINEW_DATA_DIR was set (else the build's data folder)
};
/// The environment variable SINEW_DATA_DIR when set and not empty, else
/// the data folder the library was built with (the build's SINEW_DATA_DIR,
/// where the packed meshes are unpacked).
DataFolder data_folder();

/// A file the document names: "data:REST" is REST in data_folder(); others
/// are relative to the scene file's folder (absolute ones stay); and a
/// regular file (not a folder, a device or a pipe a read would wait on),
/// else an error at `path` (for a "data:" name, saying where it looked).
std::filesystem::path resolve_file(const Where& where, const std::string& name, const std::string& path,
                                   Context& ctx);
/// The object's "file" member, read and resolved (resolve_file); empty
/// when it is missing or wrong (the error is in ctx).
std::filesystem::path read_file_member(Object& o, const Where& where, Context& ctx);

// body_readers.cpp
void read_tet_body(const Json& v, const std::string& path, const Where& where, Context& ctx, TetBodyDesc& out,
                   std::string& name);
void read_tri_body(const Json& v, const std::string& path, const Where& where, Context& ctx, TriBodyDesc& out,
                   std::string& name);
void read_line_body(const Json& v, const std::string& path, Context& ctx, LineBodyDesc& out, std::string& name);
/// Which point of a triangle select_triangles tests against the boxes.
enum class TriangleTest { centroid, any_vertex };
/// Triangles whose centroid (or any of whose vertices) lies in one of the
/// boxes at `v` (an array of {"min", "max"} objects, bounds included).
void select_triangles(const Json& v, const std::string& path, Context& ctx, const std::vector<Vec3d>& vertices,
                      const std::vector<std::array<std::uint32_t, 3>>& triangles,
                      std::vector<std::array<std::uint32_t, 3>>& out, TriangleTest test = TriangleTest::centroid);

// feature_readers.cpp
void read_solver(const Json& v, const std::string& path, Context& ctx, SolverSettings& out);
void read_collider(const Json& v, const std::string& path, const Where& where, Context& ctx, ColliderDesc& out);
void read_tool(const Json& v, const std::string& path, const Where& where, Context& ctx, ToolDesc& out);
void read_needle(const Json& v, const std::string& path, Context& ctx, NeedleDesc& out);
void read_grasper(const Json& v, const std::string& path, Context& ctx, GrasperDesc& out);
void read_attachment(const Json& v, const std::string& path, Context& ctx, AttachmentDesc& out);
void read_body_attachment(const Json& v, const std::string& path, Context& ctx, BodyAttachmentDesc& out);
void read_mesh_collision(const Json& v, const std::string& path, Context& ctx, MeshCollisionDesc& out);
void read_body_kind(const Json& v, const std::string& path, Context& ctx, BodyKind& out);
void read_pose(Object& o, Pose& out);
void read_cutter(const Json& v, const std::string& path, Context& ctx, CutterShape& out);

// fluid_reader.cpp: needs the bodies read already (surfaces select their triangles).
void read_fluid(const Json& v, const std::string& path, const SceneDesc& scene, Context& ctx, SceneFluidDesc& out);
void read_emitter(Object& o, FluidEmitter& out);
void read_sink(Object& o, FluidSink& out);

// script_reader.cpp
void read_script(const Json& v, const std::string& path, Context& ctx, SceneScript& out);
/// The script's references against the scene (a grasper, a body, a collider
/// that exists; keyed subjects of the right kind).
void check_script(const SceneScript& script, const SceneDesc& scene, Context& ctx);

// haptics_reader.cpp
void read_haptics(const Json& v, const std::string& path, Context& ctx, std::vector<haptics::ScriptedHandDesc>& out);
/// Each hand's tool exists and is driven by one hand only.
void check_haptics(const std::vector<haptics::ScriptedHandDesc>& hands, const SceneDesc& scene, Context& ctx);

}  // namespace sinew::scene_file
