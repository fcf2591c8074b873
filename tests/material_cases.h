// material_cases.h — the load cases that set_elastic's network is measured
// on against the linear-elastic oracle (tests/material_test.cpp,
// benchmarks/material_benchmark.cpp, docs/materials.md), and the statics of
// an xPBD body on the CPU backend.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "linear_elastic_oracle.h"
#include "sinew/simulation.h"

namespace sinew::test {

inline constexpr double kMaterialE = 1e6;      // [Pa]
inline constexpr double kMaterialCell = 0.01;  // [m]

enum class MaterialCase { stretch, bend, shear };
inline const char* case_name(MaterialCase c) {
  return c == MaterialCase::stretch ? "stretch" : c == MaterialCase::bend ? "bend" : "shear";
}

/// A mesh, its loads and supports, and the face whose mean displacement
/// is measured: component `axis` over the vertices with rest coordinate
/// `along` == `at`.
struct MaterialProblem {
  TetMesh mesh;
  StaticLoads loads;
  int axis = 0, along = 0;
  double at = 0.0;
};

/// stretch: an 8 x 2 x 2 bar of 1 cm cells pinned at x = 0, pulled along +x
/// by a body load of 10 m/s^2; bend: the same bar as a cantilever under
/// -1 m/s^2 in y; shear: a 4 x 2 x 4 block pinned at y = 0 under 40 m/s^2
/// along x (shear across its height). Density 1000 kg/m^3; at E = 1 MPa
/// the strains are ~1e-3. graded: cells growing 1.15x along x, interior
/// vertices jittered by 0.15 of a cell.
inline MaterialProblem material_problem(MaterialCase c, bool graded) {
  MaterialProblem p;
  const bool block = c == MaterialCase::shear;
  p.mesh = graded_box(block ? 4 : 8, 2, block ? 4 : 2, kMaterialCell, graded ? 1.15 : 1.0, graded ? 0.15 : 0.0);
  p.loads.density = 1000.0;
  p.loads.gravity = c == MaterialCase::stretch ? Vec3d{10, 0, 0} : c == MaterialCase::bend ? Vec3d{0, -1, 0} : Vec3d{40, 0, 0};
  p.axis = c == MaterialCase::bend ? 1 : 0;
  p.along = block ? 1 : 0;
  p.at = block ? 2 * kMaterialCell : 8 * kMaterialCell;
  for (std::uint32_t v = 0; v < p.mesh.vertices.size(); ++v)
    if (p.mesh.vertices[v][std::size_t(p.along)] < 1e-9) p.loads.pinned.push_back(v);
  return p;
}

inline double measured(const MaterialProblem& p, const std::vector<Vec3d>& u) {
  return mean_displacement(p.mesh, u, p.axis, p.along, p.at);
}

/// The xPBD body `desc` (its mesh, compliances or material) under the
/// problem's loads on the CPU backend, run to its statics: 40 frames of
/// 1/60 s, 2 substeps, residual mode (tolerance 1e-7, up to 20,000 sweeps)
/// with the warm start. Displacements [m]; empty if it failed (`last`:
/// the last frame's statistics).
inline std::vector<Vec3d> xpbd_statics(const MaterialProblem& p, const TetBodyDesc& desc, FrameStats* last,
                                       std::string* error) {
  SceneDesc scene;
  TetBodyDesc body = desc;
  body.density = p.loads.density;
  body.pinned = p.loads.pinned;
  scene.tet_bodies.push_back(body);
  scene.gravity = p.loads.gravity;
  scene.solver.substeps = 2;
  scene.solver.iterations = 4;
  scene.solver.residual_tolerance = 1e-7;
  scene.solver.max_iterations = 20000;
  scene.solver.check_interval = 16;
  scene.solver.warm_start = true;
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  if (!sim) {
    if (error) *error = sim.error().message();
    return {};
  }
  for (int f = 0; f < 40; ++f)
    if (Status s = sim->step(); !s) {
      if (error) *error = s.error().message();
      return {};
    }
  if (last) *last = sim->last_frame();
  std::vector<float> x;
  if (!sim->read_positions(x)) return {};
  std::vector<Vec3d> u(p.mesh.vertices.size());
  for (std::size_t v = 0; v < u.size(); ++v)
    for (std::size_t k = 0; k < 3; ++k) u[v][k] = double(x[4 * v + k]) - p.mesh.vertices[v][k];
  return u;
}

}  // namespace sinew::test
