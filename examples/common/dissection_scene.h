// dissection_scene.h — the reference scene "S2 dissection", shared by
// examples/dissection.cpp, benchmarks/dissection.cpp and its ctest: the
// gallbladder (data/meshes/tet/gallbladder_volumetric.vtk, corotational FEM,
// held along its top) above a liver bed (a slab of tets, pinned underneath),
// a membrane of 6,000 triangles (1 mm cells) between them attached two ways
// to BOTH bodies (BodyAttachmentDesc, docs/attachments.md), a grasper
// lifting the membrane's free middle, a cautery tip burning along the liver
// attachment line and a blade cutting along the gallbladder's, every few
// frames (Topology, docs/cutting.md); 60 Hz frames.
//
// The tools as haptic tools. Each tool (grasper, cautery, blade) is a rigid
// capsule (ToolDesc, its handle) moved by a scripted hand
// (sinew/haptics/scripted_hands.h: a KeyframePath, a 1 kHz HapticLoop on a
// virtual clock, the haptic tool bridge), the path a real device takes. The
// working part (the jaws, the cautery's tip, the blade's edge) rides at a
// fixed offset below its handle, which stays clear of the tissue: the
// tissue meets the tools only through what they do (holds, burns, cuts). As
// in S1 (retraction_scene.h), the grasper's holds are compliant and their
// pull goes back to the handle as a force, one frame late.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sinew/haptics/scripted_hands.h"
#include "sinew/result.h"
#include "sinew/scene.h"
#include "sinew/simulation.h"

namespace sinew::examples {

/// How the dissection scene is built and run.
struct DissectionSettings {
  std::string gallbladder;         ///< the gallbladder's tet mesh (millimetres, scaled to metres)
  std::string backend = "cpu";     ///< cpu, opencl, vulkan or auto
  int threads = 0;                 ///< cpu backend worker threads (0: all)
  int substeps = 10;               ///< per 1/60 s frame
  int iterations = 2;              ///< per substep
  double gallbladder_young = 20e3; ///< the gallbladder's Young's modulus [Pa] (corotational, nu 0.45)
  double attachment_compliance = 1e-4;  ///< of each body attachment [m/N]
  int topology_every = 2;          ///< a burn and a cut every this many frames (>= 1)
  bool mesh_collision = true;      ///< contacts between the bodies' meshes (MeshCollisionDesc)
  double script_speed = 1.0;       ///< the hands' script runs this many times faster (> 0; the ctest's short run)
};

/// The scene in a few lines, for the programs' --help.
inline constexpr const char* kDissectionAbout =
    "The reference scene S2: the gallbladder (1,063 tets, corotational 20 kPa, held along its top) over a liver\n"
    "bed (a tet slab, 10 kPa, pinned underneath); a membrane of 6,000 triangles between them attached two ways\n"
    "to both; a grasper lifts the membrane's middle 10 mm, then a cautery tip burns along the liver's\n"
    "attachment line and a blade cuts along the gallbladder's (a topology change every few frames); the\n"
    "three tools driven by scripted hands through the haptic tool bridge; 60 Hz frames.\n";

/// The script [s of script time]: the grasper lifts kLift [m] over
/// [kLiftStart, kLiftEnd]; the cautery and the blade sweep across the
/// membrane over [kDissectStart, kDissectEnd].
inline constexpr double kLift = 0.010, kLiftStart = 0.1, kLiftEnd = 1.0;
inline constexpr double kDissectStart = 1.1, kDissectEnd = 2.1;
/// The script's length [s]: everything still after it.
inline constexpr double kScriptEnd = 2.3;

/// What one frame's checks measure (DissectionScene::check).
struct DissectionCheck {
  /// The gallbladder's attached vertices' mean rise since the lift began [m].
  double gallbladder_lift = 0.0;
  /// The liver's attached vertices' mean rise since the lift began [m].
  double liver_lift = 0.0;
  /// The held membrane vertices' mean rise since the lift began [m].
  double membrane_lift = 0.0;
  std::array<double, 3> grasp_force{};  ///< the tissue's pull on the jaws [N]
  bool finite = true;                   ///< every position finite
  /// The deepest a live membrane vertex lies inside the gallbladder's tets
  /// or below the liver bed's top [m] (0 when none is inside).
  double deepest_inside = 0.0;
  std::size_t membrane_triangles = 0;   ///< live
};

/// The scene, its three scripted hands and the grasp. Not movable.
class DissectionScene {
 public:
  /// Builds the meshes, the scene and the hands; closes the grasper on the
  /// membrane. Errors: bad settings (named), the mesh's, the scene's, the hands'.
  static Result<std::unique_ptr<DissectionScene>> create(const DissectionSettings& settings);

  /// One 1/60 s frame: the hands' ticks up to the frame's end and their
  /// forces; the grasp's pull on its handle; the jaws to the handle; the
  /// cautery's burn and the blade's cut (when due); step(); the tools' state
  /// to the hands; the grasp's pull for the next frame.
  Status frame();
  /// The frame's checks (reads the positions back; point-in-tet over the
  /// gallbladder for every live membrane vertex, ~6 M tests).
  Result<DissectionCheck> check();

  [[nodiscard]] Simulation& sim() { return *sim_; }
  [[nodiscard]] const SceneDesc& scene() const { return scene_; }
  [[nodiscard]] const haptics::ScriptedHands& hands() const { return *hands_; }
  [[nodiscard]] std::uint64_t frames() const { return frames_; }
  /// Topology events so far, and the triangles they removed.
  [[nodiscard]] std::size_t topology_events() const { return events_; }
  [[nodiscard]] std::size_t triangles_removed() const { return removed_; }
  /// Wall time of the last frame's burn and cut [ms] (0 when none).
  [[nodiscard]] double last_topology_ms() const { return last_topology_ms_; }
  [[nodiscard]] std::size_t held() const { return held_.size(); }
  /// The tools' working parts now, for drawing: the jaws' centre and half
  /// extents, the cautery's tip and radius, the blade's edge.
  [[nodiscard]] const Pose& jaws() const { return jaws_; }
  [[nodiscard]] const std::array<double, 3>& jaw_half_extents() const { return jaw_half_; }
  [[nodiscard]] const std::array<double, 3>& cautery_tip() const { return tip_; }
  [[nodiscard]] double cautery_radius() const;
  [[nodiscard]] const std::array<std::array<double, 3>, 2>& blade_edge() const { return edge_; }
  /// Whether the cautery and the blade are working this frame (script time
  /// within [kDissectStart, kDissectEnd]).
  [[nodiscard]] bool dissecting() const { return dissecting_; }
  [[nodiscard]] double frame_time() const { return scene_.solver.time_step; }

 private:
  DissectionScene() = default;
  Status grasp();
  Status measure_pull();
  Result<Pose> tool_pose(std::uint32_t tool);
  double mean_y(const std::vector<std::uint32_t>& particles) const;

  DissectionSettings settings_;
  SceneDesc scene_;
  std::optional<Simulation> sim_;
  std::unique_ptr<haptics::ScriptedHands> hands_;
  std::array<double, 3> jaw_offset_{}, tip_offset_{};  // from the handle's centre, world frame [m]
  std::array<double, 3> jaw_half_{};
  Pose jaws_;
  std::array<double, 3> tip_{};
  std::array<std::array<double, 3>, 2> edge_{};
  std::optional<std::array<std::array<double, 3>, 2>> last_edge_;  // the blade's edge at its last cut
  std::vector<std::uint32_t> held_;
  std::vector<std::array<double, 3>> held_offset_;  // each held vertex from the jaws' centre [m]
  double hold_compliance_ = 0.0;                    // [m/N] per held vertex
  std::array<double, 3> pull_{};
  std::vector<std::uint32_t> gallbladder_attached_, liver_attached_;  // particles
  double gallbladder_y0_ = 0.0, liver_y0_ = 0.0, held_y0_ = 0.0;    // at the lift's start
  bool baseline_ = false;
  std::vector<std::array<std::uint32_t, 4>> gallbladder_tets_;  // particles
  double liver_top_ = 0.0;
  std::array<double, 4> liver_xz_{};  // the slab's x and z range [m]
  std::vector<float> x_;
  std::uint64_t frames_ = 0;
  std::size_t events_ = 0, removed_ = 0;
  double last_topology_ms_ = 0.0;
  bool dissecting_ = false;
};

}  // namespace sinew::examples
