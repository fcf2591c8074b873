// sinew/scene_file.h — scenes as JSON files (docs/scene_files.md): a
// SceneDesc with its bodies, materials, pins, colliders, tools, graspers,
// needles, threads, level sets, fluid and solver settings, plus a script of
// what happens while it runs (keyframed poses and forces, actions at given
// frames), read into plain data and played on a Simulation.
//
//   auto file = sinew::load_scene_file("scenes/tissue_sag.json");
//   if (!file) { std::cerr << file.error().message() << '\n'; return 1; }
//   auto sim = sinew::Simulation::create(file->scene, {.backend = "cpu"});
//   sinew::ScriptPlayer player(file->script);
//   for (int f = 1; f <= file->run.frames; ++f) {
//     if (auto s = player.before_frame(*sim, f); !s) ...;   // poses, forces, actions of frame f
//     if (auto s = sim->step(); !s) ...;
//   }
//
// Errors name the JSON path of the value and the rule it broke, e.g.
// "scene.json: /tet_bodies/0/youngs_modulus: must be finite and > 0 (got -1)";
// nothing here throws, aborts or exits on a bad file.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sinew/haptics/scripted_hands.h"
#include "sinew/level_set.h"
#include "sinew/result.h"
#include "sinew/scene.h"
#include "sinew/topology.h"

namespace sinew {

class Simulation;

/// A body's name and kind, in the order of the scene's bodies of that kind
/// (for output file names: "<name>_<frame>.vtu").
struct SceneBodyName {
  BodyKind kind = BodyKind::tet;
  std::uint32_t index = 0;  ///< among the scene's bodies of that kind
  std::string name;         ///< from the file's "name", else "tet0", "tri1", "line0", ...
};

/// What the file asks of a run (the runner's defaults; its command line wins).
struct SceneRunSettings {
  int frames = 60;              ///< frames to run, >= 1
  int every = 10;               ///< output (VTU and a statistics line) every N frames, >= 1
  std::string backend = "auto"; ///< "auto", "cpu", "opencl" or "vulkan"
};

/// What a keyframed track drives (SceneScript::poses and forces).
enum class ScriptSubject { collider, target, grasper, needle, tool };

/// One key of a track: at the end of frame `frame` the subject has this
/// pose (poses), or this force and torque act on it during the frame
/// (forces). Between two keys the value is interpolated linearly in the
/// frame number (positions, forces, torques: a + (b - a) s; rotations:
/// normalised linear interpolation of the quaternions along the shorter
/// arc); before the first key the first holds, after the last the last.
struct ScriptKey {
  int frame = 0;                                        ///< >= 0; keys strictly increasing
  std::array<double, 3> position{0.0, 0.0, 0.0};       ///< poses [m]; forces: the force [N]
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};  ///< poses: unit quaternion (w, x, y, z)
  std::array<double, 3> torque{0.0, 0.0, 0.0};         ///< forces: [N m]
};

/// A keyframed pose or force of one subject. Poses: collider (Tools::set_pose),
/// target (Tools::set_position; the rotation is ignored), grasper
/// (Graspers::move, only while it is closed), needle (Needles::set_pose).
/// Forces: tool (Tools::apply_force), needle (Needles::apply_force).
///
/// A grasper's track may be `relative`: its keys are then offsets from the
/// pose the jaws closed at (ScriptAction::at finds that pose in the running
/// scene): position = closed position + key position [m], rotation = key
/// rotation * closed rotation (the key's rotation applied after the
/// closed pose's, in the world frame). "Lift 15 mm from wherever it took
/// hold" is then two keys, {0, 0, 0} and {0, 0.015, 0}.
struct ScriptTrack {
  ScriptSubject subject = ScriptSubject::collider;
  std::uint32_t index = 0;  ///< among the scene's objects of that kind
  std::vector<ScriptKey> keys;  ///< at least one
  bool relative = false;    ///< grasper tracks only: keys relative to the pose the jaws closed at
};

/// A point of the running scene: the mean of some vertices of one body
/// where they are when the action runs (after the frame's poses are set,
/// before its step), plus an offset. The vertices are summed in the order
/// given, in double, from the float positions Simulation::read_positions
/// returns; then divided by their count. Grasping "where the membrane's
/// middle hangs now" or burning "where this strand is now" is a landmark.
struct ScriptLandmark {
  BodyKind body_kind = BodyKind::tet;   ///< tet, tri or line body
  std::uint32_t body = 0;               ///< among the scene's bodies of that kind
  std::vector<std::uint32_t> vertices;  ///< at least one, each a vertex of that body's mesh
  std::array<double, 3> offset{0.0, 0.0, 0.0};  ///< [m], added to the mean
};

/// What a ScriptAction does at its frame.
enum class ScriptActionKind {
  close_grasper,  ///< Graspers::close(grasper, pose, half_extents)
  open_grasper,   ///< Graspers::open(grasper)
  cut,            ///< Topology::cut(body, from, to) of a tet or tri body
  cauterize,      ///< Topology::cauterize(body, centre, radius, seconds, dwell_time)
  remove,         ///< Topology::remove_tets / remove_triangles / remove_segments(body, elements)
  cut_collider,   ///< Tools::cut(collider, cutter, from, to) of a level-set collider
  set_emitter,    ///< SceneFluid::set_emitter(index, emitter)
  set_sink,       ///< SceneFluid::set_sink(index, sink)
};

/// An action run before the step that makes frame `frame`, after that
/// frame's poses and forces, in the order of the file.
struct ScriptAction {
  int frame = 1;  ///< >= 1
  ScriptActionKind kind = ScriptActionKind::close_grasper;
  std::uint32_t index = 0;               ///< the grasper, body, collider, emitter or sink
  BodyKind body_kind = BodyKind::tet;    ///< cut, cauterize, remove
  Pose pose;                             ///< close_grasper: the jaws' pose
  std::array<double, 3> half_extents{};  ///< close_grasper: the jaws' box [m]
  /// close_grasper, cauterize: when set, the jaws' position (pose.rotation
  /// still applies) or the tip's centre is this landmark, found when the
  /// action runs, instead of pose.position or centre. cut: the blade's
  /// points are then offsets from the landmark [m] (a stroke that follows
  /// the tissue).
  std::optional<ScriptLandmark> at;
  std::array<double, 3> a_from{}, b_from{}, a_to{}, b_to{};  ///< cut: the blade's ends, from and to [m]
  std::array<double, 3> centre{};        ///< cauterize [m]
  double radius = 0.0;                   ///< cauterize [m]
  double seconds = 0.0;                  ///< cauterize: the tip's time on the tissue [s]
  double dwell_time = 0.0;               ///< cauterize: the time that burns an element [s]
  std::vector<std::uint32_t> elements;   ///< remove
  CutterShape cutter;                    ///< cut_collider
  Pose from, to;                         ///< cut_collider: the cutter's motion
  FluidEmitter emitter;                  ///< set_emitter
  FluidSink sink;                        ///< set_sink
};

/// What happens while the scene runs ("script" in the file).
struct SceneScript {
  std::vector<ScriptTrack> poses;
  std::vector<ScriptTrack> forces;
  std::vector<ScriptAction> actions;  ///< sorted by frame (stable: file order within a frame)
};

/// A scene file read: the scene, its run settings, its script, and names.
struct SceneFile {
  SceneDesc scene;
  SceneRunSettings run;
  SceneScript script;
  /// "haptics": scripted hands driving tools through the haptic loop on a
  /// virtual clock (haptics::ScriptedHands runs them; sinew run does).
  std::vector<haptics::ScriptedHandDesc> hands;
  std::vector<SceneBodyName> bodies;  ///< every body: tet ones, then tri, then line
};

/// Reads a scene file. Mesh and surface files named in it are relative to
/// the file's folder. The scene is checked (check_scene) and the script's
/// references (grasper, body, collider, emitter indices) are checked against
/// it. Errors: bad_input_file (unreadable file, bad JSON, wrong types,
/// unknown keys, a mesh file that cannot be read) and bad_parameter (a value
/// out of its range), each message "<file>: <JSON path>: <rule>";
/// backend_unavailable for a level set without OpenVDB.
Result<SceneFile> load_scene_file(const std::filesystem::path& path);

/// As load_scene_file, from JSON text; `base_dir` resolves relative file
/// names in it. Messages start with the JSON path.
Result<SceneFile> parse_scene_json(std::string_view json, const std::filesystem::path& base_dir);

/// What one of the script's actions did (ScriptPlayer::before_frame), for
/// callers that react to it (a renderer updating its meshes, bindings
/// handing it on) rather than print it.
struct ScriptEvent {
  int frame = 1;  ///< the frame whose step() follows the action
  ScriptActionKind kind = ScriptActionKind::close_grasper;
  std::uint32_t index = 0;  ///< the grasper, body, collider, emitter or sink (ScriptAction::index)
  /// close_grasper: the particles now held; open_grasper: those released
  /// (read_positions order).
  std::vector<std::uint32_t> particles;
  TopologyEvent topology;  ///< cut, cauterize, remove: what the change did
  CutReport collider_cut;  ///< cut_collider: what the cut removed
  std::string text;        ///< one line saying what happened, as `sinew run` prints it
};

/// Plays a SceneScript on a Simulation made from its scene, frame by frame.
class ScriptPlayer {
 public:
  explicit ScriptPlayer(SceneScript script);
  /// Sets the poses and forces of frame `frame` (>= 1) and runs its
  /// actions; call it before the step() that makes that frame, for frames
  /// 1, 2, 3, ... in order. [out] events, when given, gets a line per
  /// grasp, topology change and collider cut the actions made (emitters and
  /// sinks say nothing). Errors: the first failing call's.
  Status before_frame(Simulation& sim, int frame, std::vector<std::string>* events = nullptr);
  /// As before_frame above; [out] events gets (appended) what each of the
  /// frame's actions did, set_emitter and set_sink included.
  Status before_frame(Simulation& sim, int frame, std::vector<ScriptEvent>& events);

 private:
  SceneScript script_;
  std::size_t next_action_ = 0;
  std::vector<bool> grasper_closed_;
  std::vector<Pose> grasper_closed_at_;  ///< the pose each grasper last closed at (relative tracks)
};

/// A key's interpolated value at `frame` (ScriptKey's rule): position,
/// normalised rotation and torque. [pre] !keys.empty()
ScriptKey interpolate_keys(const std::vector<ScriptKey>& keys, int frame);

}  // namespace sinew
