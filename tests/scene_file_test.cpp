// scene_file_test.cpp — scene files (sinew/scene_file.h): every scene
// under scenes/ reads and checks; a file and the SceneDesc written in C++
// run to bitwise the same positions; bad files get errors naming the JSON
// path and the rule; the script's keys interpolate and drive the scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/scene_file.h"
#include "sinew/simulation.h"

namespace sinew {
namespace {

const std::filesystem::path kScenes = std::filesystem::path(SINEW_SOURCE_DIR) / "scenes";

// A small scene as text: a 4 x 1 x 2 block pinned at x = 0, with `extra`
// keys added to its tet body.
std::string block_scene(const std::string& extra = "") {
  return R"({"solver": {"time_step": 0.01, "substeps": 4, "iterations": 2},
    "tet_bodies": [{"name": "block", "mesh": {"grid": {"cells": [4, 1, 2], "size": [0.04, 0.01, 0.02]}},
      "density": 1000.0, "elastic": {"youngs_modulus": 20000.0, "poisson_ratio": 0.4},
      "pinned": [{"min": [-1, -1, -1], "max": [0, 1, 1]}])" + extra + "}]}";
}

std::string error_of(const std::string& json) {
  auto file = parse_scene_json(json, kScenes);
  return file ? std::string("(no error)") : file.error().message();
}

TEST(SceneFile, EverySceneUnderScenesReadsAndChecks) {
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kScenes)) {
    if (entry.path().extension() != ".json") continue;
    ++scenes;
    auto file = load_scene_file(entry.path());
    ASSERT_TRUE(file.ok()) << file.error().message();
    EXPECT_TRUE(check_scene(file->scene).ok()) << entry.path();
    // A body or a tool (bone_burr's only moving part is its burr).
    EXPECT_FALSE(file->bodies.empty() && file->scene.tools.empty()) << entry.path();
  }
  EXPECT_GE(scenes, 1);
}

TEST(SceneFile, RunsBitwiseAsTheSceneWrittenInCpp) {
  auto file = parse_scene_json(block_scene(R"(, "velocity_damping": 2.0)"), kScenes);
  ASSERT_TRUE(file.ok()) << file.error().message();

  SceneDesc scene;
  scene.solver = {.time_step = 0.01, .substeps = 4, .iterations = 2};
  TetBodyDesc body;
  body.mesh = *make_tet_grid({.nx = 4, .ny = 1, .nz = 2, .cell_size = {0.04 / 4, 0.01 / 1, 0.02 / 2}});
  ASSERT_TRUE(body.set_elastic(2e4, 0.4).ok());
  body.velocity_damping = 2.0;
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] == 0.0) body.pinned.push_back(v);
  scene.tet_bodies.push_back(body);
  EXPECT_EQ(file->scene.tet_bodies[0].pinned, scene.tet_bodies[0].pinned);
  EXPECT_EQ(file->bodies.at(0).name, "block");

  auto from_file = Simulation::create(file->scene, {.backend = "cpu", .threads = 1});
  auto from_cpp = Simulation::create(scene, {.backend = "cpu", .threads = 1});
  ASSERT_TRUE(from_file.ok() && from_cpp.ok());
  for (int f = 0; f < 10; ++f) ASSERT_TRUE(from_file->step().ok() && from_cpp->step().ok());
  std::vector<float> a, b;
  ASSERT_TRUE(from_file->read_positions(a).ok() && from_cpp->read_positions(b).ok());
  ASSERT_EQ(a, b);
  // It moved: the comparison is not of two scenes at rest.
  EXPECT_GT(from_file->last_frame().kinetic_energy, 0.0);
}

TEST(SceneFile, ErrorsNameTheJsonPathAndTheRule) {
  EXPECT_EQ(error_of(block_scene(R"(, "density": -1)")), "/tet_bodies/0/density: must be finite and > 0 (got -1)");
  EXPECT_EQ(error_of(R"({"tet_bodies": [{"mesh": {"grid": {"cells": [1, 1, 1], "size": [1, 1, 1]}},
                          "elastic": {"youngs_modulus": -5, "poisson_ratio": 0.3}}]})"),
            "/tet_bodies/0/elastic/youngs_modulus: must be finite and > 0 (got -5)");
  EXPECT_EQ(error_of(block_scene(R"(, "densty": 5)")),
            "/tet_bodies/0/densty: unknown key (docs/scene_files.md lists the keys)");
  EXPECT_EQ(error_of(block_scene(R"(, "density": "heavy")")), "/tet_bodies/0/density: must be a number (got a string)");
  EXPECT_EQ(error_of(block_scene(R"(, "pinned": [1000])")),
            "/tet_bodies/0/pinned/0: vertex 1000 is out of range (the mesh has 30)");
  EXPECT_EQ(error_of(block_scene(R"(, "material": "jelly")")),
            "/tet_bodies/0/material: must be one of \"none\", \"neo_hookean\", \"stvk\", \"corotational\" (got \"jelly\")");
  EXPECT_EQ(error_of(R"({"solver": {"substeps": 2.5}})"), "/solver/substeps: must be a whole number (got 2.5)");
  EXPECT_EQ(error_of(R"({"tet_bodies": [{"mesh": {"file": "no_such_mesh.node"}}]})"),
            "/tet_bodies/0/mesh/file: " + (kScenes / "no_such_mesh.node").string() + " is not a readable file");
  // A folder (or a device, a pipe) is not read: nothing waits on it.
  EXPECT_EQ(error_of(R"({"tri_bodies": [{"mesh": {"file": "schema"}}]})"),
            "/tri_bodies/0/mesh/file: " + (kScenes / "schema").string() + " is not a readable file");
  EXPECT_EQ(error_of(R"({"tet_bodies": [{"mesh": {"vertices": [[0,0,0]], "tets": [[0, 1, 2, 3]]}}]})"),
            "/tet_bodies/0/mesh/tets/0/1: vertex 1 is out of range (there are 1)");
  EXPECT_EQ(error_of(R"({"line_bodies": [{"vertices": [[0,0,0],[1,0,0]], "mass": 1}],
                         "script": {"actions": [{"frame": 3, "do": "open_grasper", "grasper": 0}]}})"),
            "/script/actions (frame 3): grasper 0 does not exist (the scene has 0)");
  EXPECT_EQ(error_of(R"({"run": {"frames": 0}})"), "/run/frames: must be >= 1");
  EXPECT_EQ(error_of("[1, 2]"), "/: must be an object (got an array of 2)");
  EXPECT_EQ(error_of("{\"tet_bodies\": [").rfind("not valid JSON: ", 0), 0u);
  // The fluid's keys are in "fluid" itself (SceneFluidDesc::fluid's).
  EXPECT_EQ(error_of(block_scene().substr(0, block_scene().size() - 1) +
                     R"(, "fluid": {"settings": {"time_step": 0.003}, "capacity": 10}})"),
            "/fluid/settings/time_step: the scene's frame (solver.time_step 0.01 s) is not a whole number of fluid "
            "steps of 0.003 s");
  // An empty scene is check_scene's error, at the root.
  EXPECT_EQ(error_of("{}").rfind("/: ", 0), 0u);
}

// "body_attachments": BodyAttachmentDesc's fields, the break force
// infinite when left out; errors at their JSON path.
TEST(SceneFile, BodyAttachmentsReadWithTheirFieldsAndErrors) {
  const auto with = [](const std::string& link) {
    std::string s = block_scene();
    return s.substr(0, s.size() - 1) + R"(, "body_attachments": [)" + link + "]}";
  };
  auto file = parse_scene_json(with(R"({"a": {"body_kind": "tet", "body": 0, "vertices": [5], "weights": [1]},
      "b": {"body": 0, "vertices": [6, 7], "weights": [0.25, 0.75]}, "compliance": 1e-4, "rest_length": 0.002})"), kScenes);
  ASSERT_TRUE(file.ok()) << file.error().message();
  ASSERT_EQ(file->scene.body_attachments.size(), 1u);
  const BodyAttachmentDesc& a = file->scene.body_attachments[0];
  EXPECT_EQ(a.a.vertices, std::vector<std::uint32_t>{5});
  EXPECT_EQ(a.b.vertices, (std::vector<std::uint32_t>{6, 7}));
  EXPECT_EQ(a.b.weights, (std::vector<double>{0.25, 0.75}));
  EXPECT_EQ(a.compliance, 1e-4);
  EXPECT_TRUE(std::isinf(a.break_force));
  EXPECT_EQ(a.rest_length, 0.002);
  EXPECT_TRUE(Simulation::create(file->scene, {.backend = "cpu", .quiet = true}).ok());
  EXPECT_EQ(error_of(with(R"({"a": {"vertices": [5], "weights": [0.5]}, "b": {"vertices": [6], "weights": [1]}})"))
                .rfind("/body_attachments/0/a/weights", 0),
            0u);
  EXPECT_EQ(error_of(with(R"({"a": {"vertices": [5], "weights": [1]}, "b": {"vertices": [6], "weights": [1]},
                              "break_force": -1})"))
                .rfind("/body_attachments/0/break_force", 0),
            0u);
  EXPECT_EQ(error_of(with(R"({"a": {"vertices": [5], "weights": [1]}, "b": {"vertices": [6], "weights": [1]},
                              "rest_length": -0.001})"))
                .rfind("/body_attachments/0/rest_length", 0),
            0u);
  EXPECT_EQ(error_of(with(R"({"a": {"vertices": [5], "weights": [1]}})")), "/body_attachments/0/b: is required");
}

// A "data:" file name is found in SINEW_DATA_DIR when the environment sets
// it, else in the build's data folder; a missing one names the variable.
TEST(SceneFile, DataNamesResolveInTheDataFolder) {
  const std::string scene = R"({"tet_bodies": [{"mesh": {"file": "data:meshes/tet/armadillo_4k.node",
    "scale": 0.5, "translate": [1.0, -2.0, 0.25]}, "elastic": {"youngs_modulus": 20000.0, "poisson_ratio": 0.4}}]})";
  auto mesh = read_tet_mesh(std::filesystem::path(SINEW_DATA_DIR) / "meshes/tet/armadillo_4k.node");
  ASSERT_TRUE(mesh.ok()) << mesh.error().message();
  const std::array<double, 3> shift{1.0, -2.0, 0.25};
  const char* saved = std::getenv("SINEW_DATA_DIR");
  const std::string restore = saved ? saved : "";
  for (const bool from_environment : {false, true}) {
    if (from_environment) ::setenv("SINEW_DATA_DIR", SINEW_DATA_DIR, 1);
    else ::unsetenv("SINEW_DATA_DIR");
    auto file = parse_scene_json(scene, kScenes);
    ASSERT_TRUE(file.ok()) << file.error().message();
    const auto& read = file->scene.tet_bodies[0].mesh;
    ASSERT_EQ(read.vertices.size(), mesh->vertices.size());
    EXPECT_EQ(read.tets, mesh->tets);
    for (std::size_t v = 0; v < read.vertices.size(); ++v)
      for (int k = 0; k < 3; ++k) ASSERT_EQ(read.vertices[v][k], mesh->vertices[v][k] * 0.5 + shift[k]);
  }
  ::setenv("SINEW_DATA_DIR", "/no/such/data", 1);
  const std::string e = error_of(scene);
  EXPECT_NE(e.find("/tet_bodies/0/mesh/file: /no/such/data/meshes/tet/armadillo_4k.node is not a readable file"),
            std::string::npos) << e;
  EXPECT_NE(e.find("SINEW_DATA_DIR"), std::string::npos) << e;
  if (saved) ::setenv("SINEW_DATA_DIR", restore.c_str(), 1);
  else ::unsetenv("SINEW_DATA_DIR");
}

TEST(SceneFile, LoadingNamesTheFile) {
  auto file = load_scene_file(kScenes / "no_such_scene.json");
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.error().code(), ErrorCode::bad_input_file);
  EXPECT_NE(file.error().message().find("no_such_scene.json: cannot be read"), std::string::npos);
}

TEST(SceneFile, KeysInterpolateLinearlyAndHoldBeyondTheEnds) {
  std::vector<ScriptKey> keys(2);
  keys[0].frame = 10, keys[0].position = {0.0, 1.0, 0.0};
  keys[1].frame = 20, keys[1].position = {1.0, 3.0, 0.0};
  keys[1].rotation = {0.0, 0.0, 1.0, 0.0};  // half a turn about y
  EXPECT_EQ(interpolate_keys(keys, 0).position, keys[0].position);
  EXPECT_EQ(interpolate_keys(keys, 99).position, keys[1].position);
  const ScriptKey mid = interpolate_keys(keys, 15);
  EXPECT_DOUBLE_EQ(mid.position[0], 0.5);
  EXPECT_DOUBLE_EQ(mid.position[1], 2.0);
  EXPECT_NEAR(mid.rotation[0], std::sqrt(0.5), 1e-15);  // a quarter turn, normalised
  EXPECT_NEAR(mid.rotation[2], std::sqrt(0.5), 1e-15);
}

TEST(SceneFile, ScriptMovesACollider) {
  // A sphere collider keyed from far away into the block's middle pushes it.
  auto file = parse_scene_json(R"({"solver": {"time_step": 0.01, "substeps": 4, "iterations": 2}, "gravity": [0, 0, 0],
    "tet_bodies": [{"mesh": {"grid": {"cells": [4, 1, 2], "size": [0.04, 0.01, 0.02]}},
      "elastic": {"youngs_modulus": 20000.0, "poisson_ratio": 0.4}, "pinned": [{"min": [-1, -1, -1], "max": [0, 1, 1]}]}],
    "colliders": [{"shape": "sphere", "radius": 0.004, "position": [0.03, 0.5, 0.01]}],
    "script": {"poses": [{"collider": 0, "keys": [{"frame": 0, "position": [0.03, 0.02, 0.01]},
                                                  {"frame": 5, "position": [0.03, 0.008, 0.01]}]}]}})",
                               kScenes);
  ASSERT_TRUE(file.ok()) << file.error().message();
  auto sim = Simulation::create(file->scene, {.backend = "cpu", .threads = 1});
  ASSERT_TRUE(sim.ok());
  ScriptPlayer player(file->script);
  for (int f = 1; f <= 8; ++f) {
    ASSERT_TRUE(player.before_frame(*sim, f).ok());
    ASSERT_TRUE(sim->step().ok());
  }
  std::vector<float> x;
  ASSERT_TRUE(sim->read_positions(x).ok());
  // The block's top vertex under the sphere (rest (0.03, 0.01, 0.01)) is pushed down.
  const auto& rest = file->scene.tet_bodies[0].mesh.vertices;
  const auto top = std::min_element(rest.begin(), rest.end(), [](const Vec3d& a, const Vec3d& b) {
    const auto d = [](const Vec3d& v) { return std::abs(v[0] - 0.03) + std::abs(v[1] - 0.01) + std::abs(v[2] - 0.01); };
    return d(a) < d(b);
  });
  const float lowest_top = x[4 * static_cast<std::size_t>(top - rest.begin()) + 1];
  EXPECT_LT(lowest_top, 0.0045f);
}

// A landmark finds where the tissue is when the action runs, and a relative
// grasper track moves the jaws from where they closed: the script plays
// bitwise as the same done by hand in C++ (read the positions, close on
// their mean, lift from there).
TEST(SceneFile, LandmarksAndRelativeTracksFollowTheRunningScene) {
  const std::string far_end = "[4, 9, 14, 19, 24, 29]";  // x = 0.04 of the 5 x 2 x 3 grid's vertices
  auto file = parse_scene_json(block_scene().substr(0, block_scene().size() - 1) + R"(,
    "graspers": [{"capacity": 64, "compliance": 0.0}],
    "script": {"poses": [{"grasper": 0, "relative": true,
                          "keys": [{"frame": 5, "position": [0, 0, 0]}, {"frame": 15, "position": [0, 0.01, 0]}]}],
               "actions": [{"frame": 5, "do": "close_grasper", "grasper": 0, "half_extents": [0.003, 0.008, 0.012],
                            "at": {"body": 0, "vertices": )" + far_end + R"(}}]}})",
                               kScenes);
  ASSERT_TRUE(file.ok()) << file.error().message();
  ASSERT_TRUE(file->script.actions.at(0).at.has_value());
  const std::vector<std::uint32_t> end = file->script.actions[0].at->vertices;
  for (std::uint32_t v : end) ASSERT_EQ(file->scene.tet_bodies[0].mesh.vertices.at(v)[0], 0.04);

  auto played = Simulation::create(file->scene, {.backend = "cpu", .threads = 1});
  auto by_hand = Simulation::create(file->scene, {.backend = "cpu", .threads = 1});
  ASSERT_TRUE(played.ok() && by_hand.ok());
  ScriptPlayer player(file->script);
  std::vector<ScriptEvent> events;
  std::vector<float> x;
  const auto mean_of_end = [&](Simulation& sim) {
    EXPECT_TRUE(sim.read_positions(x).ok());
    std::array<double, 3> m{0.0, 0.0, 0.0};
    for (std::uint32_t v : end)
      for (int c = 0; c < 3; ++c) m[c] += x[4 * v + c];
    for (double& c : m) c /= static_cast<double>(end.size());
    return m;
  };
  auto grasper = by_hand->graspers().grasper(0);
  ASSERT_TRUE(grasper.ok());
  Pose jaws;
  std::array<double, 3> closed_at{};
  std::size_t held_by_hand = 0;
  for (int f = 1; f <= 20; ++f) {
    ASSERT_TRUE(player.before_frame(*played, f, events).ok());
    if (f == 5) {
      closed_at = jaws.position = mean_of_end(*by_hand);
      auto held = by_hand->graspers().close(*grasper, jaws, {0.003, 0.008, 0.012});
      ASSERT_TRUE(held.ok());
      held_by_hand = held->size();
    } else if (f > 5) {
      jaws.position[1] = closed_at[1] + 0.01 * std::min(double(f - 5) / 10.0, 1.0);
      ASSERT_TRUE(by_hand->graspers().move(*grasper, jaws).ok());
    }
    ASSERT_TRUE(played->step().ok() && by_hand->step().ok());
  }
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].particles.size(), held_by_hand);
  EXPECT_EQ(held_by_hand, end.size());  // the jaws closed on the sagged end, not where it was at rest
  std::vector<float> a, b;
  ASSERT_TRUE(played->read_positions(a).ok() && by_hand->read_positions(b).ok());
  EXPECT_EQ(a, b);
  // The end was lifted 10 mm from where it was grasped (held rigidly: within a tenth of a millimetre).
  EXPECT_NEAR(mean_of_end(*played)[1] - closed_at[1], 0.01, 1e-4);
}

// "axes" turns a mesh by quarter turns, exactly; a reflection is refused.
TEST(SceneFile, MeshAxesTurnExactlyAndRefuseReflections) {
  const std::string tet = R"({"vertices": [[0.001, 0.002, 0.003], [0.011, 0.002, 0.003], [0.001, 0.012, 0.003],
                                           [0.001, 0.002, 0.013]], "tets": [[0, 1, 2, 3]])";
  auto file = parse_scene_json(R"({"tet_bodies": [{"mesh": )" + tet + R"(, "axes": ["x", "z", "-y"]},
                                                  "elastic": {"youngs_modulus": 1e4, "poisson_ratio": 0.3}}]})",
                               kScenes);
  ASSERT_TRUE(file.ok()) << file.error().message();
  const auto& v = file->scene.tet_bodies[0].mesh.vertices;
  EXPECT_EQ(v[0], (Vec3d{0.001, 0.003, -0.002}));
  EXPECT_EQ(v[3], (Vec3d{0.001, 0.013, -0.002}));
  const auto error_with = [&](const std::string& axes) {
    return error_of(R"({"tet_bodies": [{"mesh": )" + tet + R"(, "axes": )" + axes +
                    R"(}, "elastic": {"youngs_modulus": 1e4, "poisson_ratio": 0.3}}]})");
  };
  EXPECT_EQ(error_with(R"(["x", "z", "y"])"),
            "/tet_bodies/0/mesh/axes: is a reflection, which turns every tet inside out (flip one sign)");
  EXPECT_EQ(error_with(R"(["x", "x", "y"])"), "/tet_bodies/0/mesh/axes: must name each of x, y and z once");
  EXPECT_EQ(error_with(R"(["x", "w", "y"])"),
            "/tet_bodies/0/mesh/axes/1: must be one of \"x\", \"y\", \"z\", \"-x\", \"-y\", \"-z\"");
  EXPECT_EQ(error_of(R"({"tet_bodies": [{"mesh": )" + tet + R"(, "axes": ["-x", "-y", "z"]},
                         "elastic": {"youngs_modulus": 1e4, "poisson_ratio": 0.3}}]})"),
            "(no error)");  // a half turn about z
}

TEST(SceneFile, LandmarkAndRelativeTrackErrors) {
  const std::string scene = block_scene().substr(0, block_scene().size() - 1) +
                            R"(, "graspers": [{"capacity": 8}], "colliders": [{"shape": "sphere", "radius": 0.01}],
                            "script": )";
  EXPECT_EQ(error_of(scene + R"({"actions": [{"frame": 1, "do": "close_grasper", "grasper": 0, "half_extents": [1, 1, 1],
                                  "at": {"body": 0, "vertices": [30]}}]}})"),
            "/script/actions (frame 1)/at: vertex 30 is out of range (the body has 30)");
  EXPECT_EQ(error_of(scene + R"({"actions": [{"frame": 1, "do": "close_grasper", "grasper": 0, "half_extents": [1, 1, 1],
                                  "at": {"body_kind": "tri", "body": 0, "vertices": [0]}}]}})"),
            "/script/actions (frame 1)/at: body 0 does not exist (the scene has 0)");
  EXPECT_EQ(error_of(scene + R"({"actions": [{"frame": 1, "do": "close_grasper", "grasper": 0, "half_extents": [1, 1, 1],
                                  "position": [0, 0, 0], "at": {"body": 0, "vertices": [0]}}]}})"),
            "/script/actions/0/position: give \"position\" or \"at\" (a landmark), not both");
  EXPECT_EQ(error_of(scene + R"({"actions": [{"frame": 1, "do": "close_grasper", "grasper": 0, "half_extents": [1, 1, 1],
                                  "at": {"body": 0, "vertices": []}}]}})"),
            "/script/actions/0/at/vertices: must not be empty");
  // A landmark after a key that already failed: that error stands (the fuzzer's find: a null dereference).
  EXPECT_EQ(error_of(scene + R"({"actions": [{"frame": 1, "do": "close_grasper", "half_extents": [1, 1, 1],
                                  "at": {"body": 0, "vertices": [0]}}]}})"),
            "/script/actions/0/grasper: is required");
  EXPECT_EQ(error_of(scene + R"({"poses": [{"collider": 0, "relative": true, "keys": [{"frame": 0, "position": [0, 0, 0]}]}]}})"),
            "/script/poses/0/relative: only a grasper's track can be relative (to the pose its jaws closed at)");
}

// "haptics": scripted hands read with their paths, loops and damping; every
// bad value named by its JSON path.
TEST(SceneFile, HapticsHandsReadWithTheirFieldsAndErrors) {
  const auto with = [](const std::string& hands) {
    std::string s = block_scene();
    s.pop_back();  // the closing brace: add a tool and the hands
    return s + R"(, "tools": [{"shape": "capsule", "radius": 0.004, "half_height": 0.01, "mass": 0.2,
      "inertia": [1e-4, 1e-4, 1e-4], "position": [0.02, 0.02, 0.01], "gravity": false}],
      "haptics": {"hands": [)" + hands + "]}}";
  };
  const std::string good = R"({"tool": 0, "rate_hz": 500, "path": {"interpolation": "linear",
      "keys": [{"time": 0, "position": [0.02, 0.02, 0.01]},
               {"time": 1, "position": [0.02, 0.015, 0.01], "rotation": [0, 0, 0, 2]}]},
      "coupling": {"stiffness": 300, "damping": 2, "max_force": 5}, "tool_damping": 4, "tool_angular_damping": 0.001})";
  auto file = parse_scene_json(with(good), kScenes);
  ASSERT_TRUE(file.ok()) << file.error().message();
  ASSERT_EQ(file->hands.size(), 1u);
  const haptics::ScriptedHandDesc& h = file->hands[0];
  EXPECT_EQ(h.tool, 0u);
  EXPECT_EQ(h.loop.rate_hz, 500.0);
  EXPECT_EQ(h.loop.coupling.stiffness, 300.0);
  EXPECT_EQ(h.loop.coupling.damping, 2.0);
  EXPECT_EQ(h.loop.coupling.max_force, 5.0);
  EXPECT_EQ(h.loop.coupling.rotational_stiffness, haptics::CouplingParams{}.rotational_stiffness);
  EXPECT_EQ(h.tool_damping, 4.0);
  EXPECT_EQ(h.tool_angular_damping, 0.001);
  EXPECT_EQ(h.path.interpolation(), haptics::PathInterpolation::linear);
  ASSERT_EQ(h.path.keys().size(), 2u);
  EXPECT_EQ(h.path.keys()[1].rotation, (haptics::Quat{0.0, 0.0, 0.0, 1.0}));  // normalised
  EXPECT_NEAR(h.path.at(0.5).position[1], 0.0175, 1e-15);

  EXPECT_EQ(error_of(with(R"({"tool": 1, "path": {"keys": [{"time": 0, "position": [0, 0, 0]}]}})")),
            "/haptics/hands/0/tool: tool 1 does not exist (the scene has 1)");
  EXPECT_EQ(error_of(with(R"({"tool": 0, "path": {"keys": [{"time": 0, "position": [0, 0, 0]}]}},
                              {"tool": 0, "path": {"keys": [{"time": 0, "position": [0, 0, 0]}]}})")),
            "/haptics/hands/1/tool: tool 0 is driven by /haptics/hands/0 already");
  EXPECT_EQ(error_of(with(R"({"tool": 0})")), "/haptics/hands/0/path: is required");
  EXPECT_EQ(error_of(with(R"({"tool": 0, "path": {"keys": []}})")),
            "/haptics/hands/0/path/keys: a path needs at least one key");
  EXPECT_EQ(error_of(with(R"({"tool": 0, "path": {"keys": [{"time": 1, "position": [0, 0, 0]},
                                                           {"time": 0.5, "position": [0, 0, 0]}]}})")),
            "/haptics/hands/0/path/keys/1/time: must be greater than the previous key's (got 0.5 after 1)");
  EXPECT_EQ(error_of(with(R"({"tool": 0, "path": {"keys": [{"time": 0}]}})")),
            "/haptics/hands/0/path/keys/0/position: is required");
  EXPECT_EQ(error_of(with(R"({"tool": 0, "path": {"interpolation": "cubic", "keys": [{"time": 0, "position": [0, 0, 0]}]}})"))
                .rfind("/haptics/hands/0/path/interpolation: must be one of", 0),
            0u);
  EXPECT_EQ(error_of(with(R"({"tool": 0, "rate_hz": 0, "path": {"keys": [{"time": 0, "position": [0, 0, 0]}]}})")),
            "/haptics/hands/0/rate_hz: must be in [1, 1e6] [Hz]");
  EXPECT_EQ(error_of(with(R"({"tool": 0, "coupling": {"damping": -1}, "path": {"keys": [{"time": 0, "position": [0, 0, 0]}]}})"))
                .rfind("/haptics/hands/0/coupling/damping: must be finite and >= 0", 0),
            0u);
  EXPECT_EQ(error_of(with(R"({"tool": 0, "tool_damping": -1, "path": {"keys": [{"time": 0, "position": [0, 0, 0]}]}})")),
            "/haptics/hands/0/tool_damping: must be finite and >= 0");
  // Each damping is named by its own key.
  EXPECT_EQ(error_of(with(R"({"tool": 0, "tool_angular_damping": -0.5, "path": {"keys": [{"time": 0, "position": [0, 0, 0]}]}})")),
            "/haptics/hands/0/tool_angular_damping: must be finite and >= 0");
  EXPECT_EQ(error_of(with(R"({"tool": 0, "grip": 1, "path": {"keys": [{"time": 0, "position": [0, 0, 0]}]}})"))
                .rfind("/haptics/hands/0/grip", 0),
            0u);
}

}  // namespace
}  // namespace sinew
