// bleeding_organ_scene.h — the bleeding reference scene (S4), shared by
// the example examples/bleeding_kidney.cpp, the benchmark
// benchmarks/bleeding_organ.cpp and the test tests/bleeding_organ_test.cpp,
// so the three run the very same scene.
//
// The scene: kidney_57k (the mesher's vertex order, mm scaled to m) laid on
// its back (the file's thinnest axis, z, up: (x, y, z) -> (x, z, -y)),
// corotational FEM at 20 kPa, pinned where it rests (its lowest 15%), 60 Hz
// frames. A cut vessel (an emitter of 2 mm radius, pulsing +-50% at 72
// beats a minute) bleeds onto the top of the kidney; the blood (SPH, 1 mm
// particles, rho0 1060 kg/m^3) pools on it and runs down its sides. A
// suction tip (a sink ball of 4 mm) comes down onto the wound at a
// scripted time and sweeps it. The fluid and the tissue are coupled both
// ways (SceneDesc::fluid).
//
// Only the surface near the fluid is sampled: the kidney's boundary
// triangles above the drain level (less 8 mm) carry boundary particles,
// and a drain (a sink ball of 1 m whose top is the drain level, at 70% of
// the kidney's height) removes the blood that has run that far down, so no
// fluid particle ever meets the kidney's unsampled lower half. The boundary
// is what a fluid step costs most on an organ (docs/fluids.md): the top
// half carries less than half the particles of the whole surface.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "command_line.h"
#include "sinew/mesh.h"
#include "sinew/result.h"
#include "sinew/scene.h"
#include "sinew/scene_fluid.h"

namespace sinew::examples {

struct BleedingOrganOptions {
  std::string mesh_path;        ///< kidney_57k's .node file (millimetres)
  double flow_ml = 3.0;         ///< the vessel's mean flow [ml/s]
  double suction_start = 1.0;   ///< when the suction tip starts down onto the wound [s]
  std::uint32_t capacity = 5000;  ///< the most fluid particles at once
  int substeps = 10;            ///< the tissue's substeps per 60 Hz frame (1 iteration each)
};

/// The scene's options on a command line (--flow, --suction, --capacity,
/// --substeps, --mesh), [in,out] options holding the defaults.
void add_bleeding_organ_options(CommandLine& cli, BleedingOrganOptions& options);

/// The scene and its script.
struct BleedingOrganScene {
  static constexpr double kFrame = 1.0 / 60.0;   ///< the scene's frame [s]
  static constexpr double kSpacing = 1e-3;       ///< the blood's particles [m]
  static constexpr double kRho = 1060.0;         ///< blood [kg/m^3]
  static constexpr int kStepsPerFrame = 136;     ///< fluid steps per frame (1.23e-4 s each, CFL at rest 1.6e-4)
  static constexpr double kSuctionRadius = 4e-3;  ///< the suction tip's ball [m]

  SceneDesc scene;         ///< the kidney and the blood (SceneDesc::fluid)
  TetMesh mesh;            ///< the kidney as placed [m]
  std::uint32_t surface_triangles = 0;  ///< the kidney's boundary triangles
  std::uint32_t coupled_triangles = 0;  ///< ... of them carrying boundary particles
  std::array<double, 3> wound{};        ///< the surface point the vessel bleeds onto [m]
  double drain_level = 0.0;             ///< blood below this height is drained [m]
  std::array<double, 3> drain_centre{};  ///< the drain ball's centre [m] (radius 1 m)
  double flow = 0.0;                    ///< the mean flow [m^3/s]
  double suction_start = 0.0;           ///< [s]

  /// The vessel at time t [s]: its flow pulses +-50% at 1.2 Hz.
  [[nodiscard]] FluidEmitter vessel_at(double t) const;
  /// The suction tip at time t [s]: parked 0.5 m above until suction_start,
  /// then down onto the wound in 0.25 s, then circling it (6 mm, 0.5 Hz).
  [[nodiscard]] FluidSink suction_at(double t) const;
  /// Sets the vessel and the suction tip of `fluid` for the frame that
  /// ends at time t [s] (call before Simulation::step).
  Status script(SceneFluid& fluid, double t) const;
};

/// Builds the scene. Errors: the mesh cannot be read, bad options (named).
Result<BleedingOrganScene> make_bleeding_organ_scene(const BleedingOrganOptions& options);

/// Which points lie inside a tet mesh at positions x (xyzw per vertex,
/// vertex v at 4 v): each tet's bounding box is binned on a uniform grid of
/// `cell` [m]; a point is tested against the tets of its cell with
/// barycentric coordinates (all >= 0).
class TetContainment {
 public:
  TetContainment(const TetMesh& mesh, const std::vector<float>& x, std::uint32_t first, double cell);
  [[nodiscard]] bool inside(const std::array<double, 3>& p) const;

 private:
  [[nodiscard]] std::array<long, 3> key(const std::array<double, 3>& p) const;
  [[nodiscard]] std::array<double, 3> at(std::uint32_t v) const;
  [[nodiscard]] bool in_tet(std::uint32_t t, const std::array<double, 3>& p) const;
  const TetMesh& mesh_;
  const std::vector<float>& x_;
  std::uint32_t first_;
  double cell_;
  std::unordered_map<long long, std::vector<std::uint32_t>> bins_;
};

/// The removal books kept on the host: which sink took each fluid particle
/// that vanished. Fed the particles after every frame (by id), it finds the
/// ids that are gone and names the sink from where each was last seen:
/// within the suction ball grown by `reach`, or below the drain level plus
/// `reach`. The two regions are over 10 mm apart, so a vanished particle
/// fits at most one; one that fits neither is counted `unexplained` (a
/// removal nothing accounts for). Particles made and removed within one
/// frame are never seen: only the suction tip, at the wound, can take one
/// that soon (the drain is over 20 mm below it), so suctioned() counts them.
class RemovalBooks {
 public:
  /// [in] particles: the fluid after a frame; [in] suction: the tip during
  /// that frame; [in] reach: the farthest a particle moved in it [m].
  void update(const std::vector<FluidParticle>& particles, const FluidSink& suction, const BleedingOrganScene& scene,
              double reach);
  /// Taken by the suction tip, of `removed` (FluidStats::removed) in all.
  [[nodiscard]] std::uint64_t suctioned(std::uint64_t removed) const { return removed - drained - unexplained; }
  /// Vanished since seen: at most FluidStats::removed.
  [[nodiscard]] std::uint64_t vanished() const { return near_tip + drained + unexplained; }
  std::uint64_t seen = 0;         ///< particles ever seen
  std::uint64_t near_tip = 0;     ///< vanished near the suction tip
  std::uint64_t drained = 0;      ///< taken by the drain
  std::uint64_t unexplained = 0;  ///< vanished away from both

 private:
  std::unordered_map<std::uint32_t, std::array<float, 3>> alive_;
};

}  // namespace sinew::examples
