// suture_scene.h — the reference scene "S3 suture" (issue: surgery at
// interactive rates), shared by examples/suture_scene.cpp,
// benchmarks/suture_scene.cpp and its ctest: a tissue pad of tet cells with a
// slit cut across its middle (the slit's cells removed above the bottom
// layer: two lips joined at the bottom), a curved needle with a thread of
// many segments tied to its tail, turned about the cut twice (a running
// suture through both lips at two depths along the cut), then pulled up and
// away until the thread's knot (its last vertex) holds at the first
// puncture, a little more, and held: the stitches close the slit. Mesh
// collision and continuous collision are on: the thread meets itself and
// the tissue (away from its punctures: docs/needles.md) and never passes
// through either. 60 Hz frames.
//
// The needle is kinematic, moved by pose every frame from a script (as
// examples/suturing.cpp), not through the haptic tool bridge: the bridge
// drives a rigid tool (ToolDesc) by force, and a needle is a NeedleDesc that
// has no ToolDesc to ride on.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sinew/result.h"
#include "sinew/scene.h"
#include "sinew/simulation.h"

namespace sinew::examples {

/// How the suture scene is built and run.
struct SutureSettings {
  std::string backend = "cpu";  ///< cpu, opencl, vulkan or auto
  int threads = 0;              ///< cpu backend worker threads (0: all)
  /// The pad's grid: cells along x (across the cut), y (depth) and z (along
  /// the cut), each `cell` [m] wide. The default is 27 x 8 x 16 cells of
  /// 2 mm: 20,064 tets after the slit. Why 2 mm: on 1 mm cells the tip's
  /// push dimples the finer surface and the needle never punctured it in
  /// the stitch's 110 frames (measured: 0 punctures, the thread dragged
  /// against the tissue, ~30,000 CCD touches in 150 frames). The pad must reach 9 mm either side
  /// of the cut (the needle's entry points), 7 mm deep and 4 mm past the
  /// stitches along z; the slit is 2 mm wide (a whole number of cells,
  /// nx minus them even: the slit in the middle).
  int nx = 27, ny = 8, nz = 16;
  double cell = 2e-3;
  int thread_segments = 200;  ///< the thread's segments, 100 mm in all
  /// Per 1/60 s frame, and iterations per substep: 16 x 2 (32 sweeps)
  /// lands as close to a converged run (64 x 4) as 8 x 10 (80 sweeps) does
  /// at 40% of the sweeps: the pad within 2.3 um RMS (8 x 10: 2.6 um), the
  /// thread within 1.2 mm RMS (1.1 mm) after the first stitch (benchmarks.md,
  /// bench_suture_scene --positions; small steps: Macklin et al., SCA 2019).
  int substeps = 16;
  int iterations = 2;         ///< per substep
  double young = 3e4;         ///< the pad's Young's modulus [Pa] (edge network, set_elastic)
  bool continuous = true;     ///< MeshCollisionDesc::continuous (the thread's CCD)
};

/// The scene in a few lines, for the programs' --help.
inline constexpr const char* kSutureAbout =
    "The reference scene S3: a tissue pad (default 54 x 16 x 32 mm, 2 mm cells, 20,064 tets, 30 kPa) with a\n"
    "2 mm slit, a curved needle (radius 8 mm) with a 100 mm thread of 200 segments turned through both lips\n"
    "twice, then pulled until the thread's knot holds and the stitches close the slit; mesh collision and\n"
    "continuous collision of the thread on; 60 Hz frames.\n";

/// The running suture's script, shared with examples/suturing.cpp: a
/// curved needle (a half circle of kSutureNeedleRadius, its centre
/// kSutureNeedleAbove over the cut at y = 0) turned about the z axis through
/// both lips at kSutureStitchZ[0] (kSutureTurnFrames frames), moved along
/// the cut to kSutureStitchZ[1] (kSutureShiftFrames), turned again, then
/// pulled up and away.
inline constexpr double kSutureNeedleRadius = 0.008, kSutureNeedleAbove = 0.002;  // [m]
inline constexpr double kSutureStitchZ[2] = {-0.003, 0.003};                    // [m]
inline constexpr int kSutureTurnFrames = 110, kSutureShiftFrames = 40;
inline constexpr int kSutureStitchFrames = 2 * kSutureTurnFrames + kSutureShiftFrames;
/// The needle's pose: its centre [m] and its turn about z [rad].
struct SutureNeedlePose {
  std::array<double, 3> position;
  double angle;
};
/// [in] frame: from 0; [in] pulled: how far [m] the pull has gone (used
/// from frame kSutureStitchFrames on: pulled up, and half as far away from
/// the cut along +x).
SutureNeedlePose suture_script(int frame, double pulled);

/// What the scene's checks measure (SutureScene::check).
struct SutureCheck {
  std::size_t punctures = 0;        ///< the needle's punctures (entering and leaving)
  std::size_t left_lip = 0;         ///< of them, in the lip at x < 0
  std::size_t right_lip = 0;        ///< of them, in the lip at x > 0
  std::size_t on_thread = 0;        ///< of them, passed on to the thread
  bool knot_holds = false;          ///< the thread's last segment sits in the first puncture
  double gap = 0.0;                 ///< the slit's width at the stitches [m] (SutureScene::gap)
  double thread_min_distance = 0.0;  ///< the least distance between two non-adjacent thread segments [m]
  std::array<int, 2> thread_closest{-1, -1};  ///< those two segments
  bool finite = true;               ///< every particle's position is finite
};

/// The scene. Build with create(), then call frame() until done().
class SutureScene {
 public:
  /// Builds the pad, the needle and its thread. Errors: bad settings
  /// (named), the scene's.
  static Result<SutureScene> create(const SutureSettings& settings);

  /// One 1/60 s frame: the needle to its scripted pose, step(), the knot's
  /// watch (the pull stops kTighten frames after the knot holds).
  /// Errors: the simulation's; the knot not reached within the pull's
  /// longest length.
  Status frame();
  /// Whether the script is over: the knot held, tightened and held still.
  [[nodiscard]] bool done() const { return last_ >= 0 && frames_ > last_; }
  /// Frames run so far.
  [[nodiscard]] int frames() const { return frames_; }
  /// The frame whose step first held the knot at the first puncture (-1: not yet).
  [[nodiscard]] int knot_frame() const { return knot_frame_; }
  /// [out] the slit's width [m] at the stitches' depth and positions along
  /// the cut: the mean x distance between its two faces' vertices there.
  Result<double> gap();
  /// The scene's checks on the positions after the last frame.
  Result<SutureCheck> check();

  [[nodiscard]] Simulation& sim() { return *sim_; }
  [[nodiscard]] const SceneDesc& scene() const { return scene_; }
  [[nodiscard]] const SutureSettings& settings() const { return settings_; }

 private:
  SutureScene() = default;
  Status read();  // x_ from the simulation

  SutureSettings settings_;
  SceneDesc scene_;
  std::optional<Simulation> sim_;
  std::vector<float> x_;
  std::vector<std::uint32_t> left_face_, right_face_;  // the slit's faces' vertices at the stitches
  std::vector<std::array<double, 3>> surface_points_;  // each boundary triangle's centre at rest [m]
  double pulled_ = 0.0;                                 // [m]
  int frames_ = 0, knot_frame_ = -1, last_ = -1;
};

}  // namespace sinew::examples
