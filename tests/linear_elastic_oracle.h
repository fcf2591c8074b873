// linear_elastic_oracle.h — the static state of small-strain linear
// elasticity on a sinew TetMesh, for tests and benchmarks only: constant-
// strain tets assembled into an Eigen sparse stiffness matrix and solved by
// sparse Cholesky (SimplicialLDLT). Written from the textbook element
// (Zienkiewicz & Taylor, "The Finite Element Method", vol. 1, ch. 6:
// B^T D B V per tet), independently of the solver's kernels. Checked
// against closed forms in tests/material_test.cpp (a bar under end
// traction, a cantilever against Euler-Bernoulli with Timoshenko's shear
// term).
//
// solve_network gives the static state of a distance + volume network
// linearised at rest (springs k_e along edges, volume stiffness k_v on
// each tet's volume): what an xPBD body converges to in small strain.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/scene.h"

namespace sinew::test {

/// Loads and supports of a static problem. Units SI.
struct StaticLoads {
  double density = 1000.0;               ///< [kg/m^3]: body load density * gravity, lumped V/4 per corner
  Vec3d gravity{0.0, 0.0, 0.0};          ///< [m/s^2]
  std::vector<Vec3d> point_forces;       ///< [N] per vertex (empty: none)
  std::vector<std::uint32_t> pinned;     ///< vertices held at rest (all three components)
  /// Single components held at 0: (vertex, axis 0..2). For roller supports.
  std::vector<std::pair<std::uint32_t, int>> fixed_components;
};

/// Static displacements [m] per vertex of constant-strain linear
/// elasticity, Young's modulus E [Pa], Poisson's ratio nu in (-1, 0.5).
/// Empty on failure (singular: too few supports), with `error` set.
std::vector<Vec3d> solve_linear_elastic(const TetMesh& mesh, double young, double poisson, const StaticLoads& loads,
                                        std::string* error = nullptr);

/// Per tet: six spring stiffnesses [N/m] on the edges (0,1) (0,2) (0,3)
/// (1,2) (1,3) (2,3), and the volume stiffness [N/m^5].
struct TetSprings {
  std::array<double, 6> edge{};
  double volume = 0.0;
};

/// Static displacements [m] of the network linearised at rest.
std::vector<Vec3d> solve_network(const TetMesh& mesh, const std::vector<TetSprings>& springs,
                                 const StaticLoads& loads, std::string* error = nullptr);

/// The springs the compiler gives a tet body (TetBodyDesc: set_elastic's
/// fit, or its hand-set compliances).
std::vector<TetSprings> body_springs(const TetBodyDesc& body);

/// Mean of component `axis` of the displacements over the vertices whose
/// rest coordinate `along` is within 1e-9 of `at` [m].
double mean_displacement(const TetMesh& mesh, const std::vector<Vec3d>& u, int axis, int along, double at);

/// A make_tet_grid box of nx x ny x nz cells of edge `cell` [m] from the
/// origin, graded along x (cell i is `grading`^i times the first, the
/// total length kept at nx * cell) and with its interior vertices moved
/// by up to `jitter` x cell in each axis (deterministic): a mesh whose
/// tets differ in shape and size. grading 1, jitter 0: the regular grid.
TetMesh graded_box(int nx, int ny, int nz, double cell, double grading, double jitter);

}  // namespace sinew::test
