// sinew/scene.h — describing a scene: bodies, materials, gravity and solver
// settings. A SceneDesc is plain data; Simulation::create checks it, compiles
// it into device buffers and a frame program, and runs it.
//
// Units are SI throughout: metres, kilograms, seconds, pascals, newtons.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/result.h"

namespace sinew {

/// A volumetric body simulated on a tet mesh with xPBD constraints.
///
/// Distance constraints (one per mesh edge) resist stretch; volume
/// constraints (one per tet) resist volume change. Compliances are given as
/// the inverse of a modulus [1/Pa] and scaled per element so the body's
/// response does not depend on how finely it is meshed:
///  - edge e of rest length L with a share V_e of the volumes of its tets
///    (each tet gives V/6 to each of its 6 edges): alpha_e = c_d * L^2 / V_e
///    [m/N], the spring k = E V_e / L^2 whose energy is (E/2) strain^2 V_e;
///  - tet of rest volume V: alpha = c_v * V [m^3/Pa], i.e. the energy
///    (K/2) (dV/V)^2 V with bulk modulus K = 1 / c_v.
/// Compliance 0 makes a constraint rigid (solved as a hard constraint).
struct TetBodyDesc {
  TetMesh mesh;                         ///< rest shape [m]; must pass check_tet_mesh
  double density = 1000.0;              ///< [kg/m^3], > 0; mass is lumped to vertices (V/4 each)
  bool distance_constraints = true;     ///< one distance constraint per edge
  double distance_compliance = 1e-5;    ///< c_d [1/Pa], >= 0 (1/E of the edge network)
  bool volume_constraints = true;       ///< one volume constraint per tet
  double volume_compliance = 1e-6;      ///< c_v [1/Pa], >= 0 (1/K, the bulk compliance)
  std::vector<std::uint32_t> pinned;    ///< vertices held fixed (inverse mass 0)

  /// Sets both compliances from Young's modulus E [Pa] (> 0) and Poisson's
  /// ratio nu (in (-1, 0.5)): c_d = 1/E, c_v = 3 (1 - 2 nu) / E. This is
  /// the usual approximation of a linear material by an edge network plus
  /// volume constraints, not an FEM material. Errors name the parameter.
  Status set_elastic(double youngs_modulus, double poisson_ratio);
};

/// Particles joined by distance constraints (a chain, a simple thread).
struct LineBodyDesc {
  std::vector<Vec3d> vertices;                          ///< rest positions [m]
  std::vector<double> masses;                           ///< per vertex [kg], > 0
  std::vector<std::array<std::uint32_t, 2>> segments;   ///< vertex pairs, rest length > 0
  double compliance = 0.0;                              ///< per segment [m/N], >= 0
  std::vector<std::uint32_t> pinned;                    ///< vertices held fixed
};

/// How each frame is solved: a frame of length time_step is split into
/// `substeps` substeps of h = time_step / substeps; each substep predicts,
/// runs `iterations` Gauss-Seidel sweeps over all constraints (colour by
/// colour) and updates velocities (Macklin et al., "Small Steps", 2019).
struct SolverSettings {
  double time_step = 1.0 / 60.0;  ///< frame length [s], > 0
  int substeps = 1;               ///< >= 1
  int iterations = 5;             ///< >= 1
  /// Measure the frame's errors (FrameStats): costs one store per
  /// constraint in the last sweep and a read-back of the residuals,
  /// velocities and positions after each frame.
  bool measure_errors = true;
};

struct SceneDesc {
  std::array<double, 3> gravity{0.0, -9.81, 0.0};  ///< [m/s^2]
  SolverSettings solver;
  std::vector<TetBodyDesc> tet_bodies;
  std::vector<LineBodyDesc> line_bodies;
};

/// Checks every parameter of a scene; the first problem found is returned,
/// naming the body and parameter (e.g. "tet_bodies[0].density must be > 0 (got -1)").
Status check_scene(const SceneDesc& scene);

}  // namespace sinew
