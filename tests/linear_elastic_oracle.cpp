// linear_elastic_oracle.cpp — see linear_elastic_oracle.h.
#include "linear_elastic_oracle.h"

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <cmath>

#include "compiler/edge_network.h"
#include "sinew/scene.h"

namespace sinew::test {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

Eigen::Vector3d at(const TetMesh& mesh, std::uint32_t v) {
  return {mesh.vertices[v][0], mesh.vertices[v][1], mesh.vertices[v][2]};
}

// Adds a 12x12 element matrix on the tet's corners.
void scatter(Triplets& k, const std::array<std::uint32_t, 4>& tet, const Eigen::Matrix<double, 12, 12>& ke) {
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          k.emplace_back(3 * int(tet[a]) + i, 3 * int(tet[b]) + j, ke(3 * a + i, 3 * b + j));
}

// Assembles the load vector, removes the held components (by keeping only
// the free ones) and solves K u = f with sparse LDL^T.
std::vector<Vec3d> solve(const TetMesh& mesh, const Triplets& triplets, const StaticLoads& loads,
                         std::string* error) {
  const int n = int(mesh.vertices.size()) * 3;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  for (const auto& tet : mesh.tets) {
    const Eigen::Vector3d x0 = at(mesh, tet[0]);
    const double vol = (at(mesh, tet[1]) - x0).dot((at(mesh, tet[2]) - x0).cross(at(mesh, tet[3]) - x0)) / 6.0;
    for (std::uint32_t v : tet)
      for (int i = 0; i < 3; ++i) f[3 * v + i] += loads.density * vol / 4.0 * loads.gravity[i];
  }
  for (std::size_t v = 0; v < loads.point_forces.size(); ++v)
    for (int i = 0; i < 3; ++i) f[3 * v + i] += loads.point_forces[v][i];
  std::vector<char> held(n, 0);
  for (std::uint32_t v : loads.pinned) held[3 * v] = held[3 * v + 1] = held[3 * v + 2] = 1;
  for (const auto& [v, axis] : loads.fixed_components) held[3 * v + axis] = 1;
  std::vector<int> free_index(n, -1);
  int m = 0;
  for (int d = 0; d < n; ++d)
    if (!held[d]) free_index[d] = m++;
  Triplets reduced;
  reduced.reserve(triplets.size());
  for (const auto& t : triplets)
    if (free_index[t.row()] >= 0 && free_index[t.col()] >= 0)
      reduced.emplace_back(free_index[t.row()], free_index[t.col()], t.value());
  Eigen::SparseMatrix<double> k(m, m);
  k.setFromTriplets(reduced.begin(), reduced.end());
  Eigen::VectorXd rhs(m);
  for (int d = 0; d < n; ++d)
    if (free_index[d] >= 0) rhs[free_index[d]] = f[d];
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k);
  if (ldlt.info() != Eigen::Success) {
    if (error) *error = "the stiffness matrix could not be factored (too few supports?)";
    return {};
  }
  const Eigen::VectorXd u = ldlt.solve(rhs);
  // A singular K (a free rigid motion) factors with a zero pivot: check.
  if (ldlt.info() != Eigen::Success || !u.allFinite() || (k * u - rhs).norm() > 1e-8 * (rhs.norm() + 1e-300)) {
    if (error) *error = "the static solve failed (a rigid motion is free?)";
    return {};
  }
  std::vector<Vec3d> out(mesh.vertices.size(), Vec3d{0, 0, 0});
  for (int d = 0; d < n; ++d)
    if (free_index[d] >= 0) out[std::size_t(d / 3)][std::size_t(d % 3)] = u[free_index[d]];
  return out;
}

}  // namespace

std::vector<Vec3d> solve_linear_elastic(const TetMesh& mesh, double young, double poisson, const StaticLoads& loads,
                                        std::string* error) {
  const double mu = young / (2.0 * (1.0 + poisson));
  const double lambda = young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
  // D in Voigt order (xx, yy, zz, yz, xz, xy) with engineering shear strains.
  Eigen::Matrix<double, 6, 6> d = Eigen::Matrix<double, 6, 6>::Zero();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) d(i, j) = lambda;
    d(i, i) += 2.0 * mu;
    d(i + 3, i + 3) = mu;
  }
  Triplets triplets;
  triplets.reserve(mesh.tets.size() * 144);
  for (const auto& tet : mesh.tets) {
    // Shape-function gradients: columns of (X^-T) for X = [x1-x0, x2-x0, x3-x0].
    const Eigen::Vector3d x0 = at(mesh, tet[0]);
    Eigen::Matrix3d x;
    for (int c = 0; c < 3; ++c) x.col(c) = at(mesh, tet[c + 1]) - x0;
    const double vol = x.determinant() / 6.0;
    const Eigen::Matrix3d inv = x.inverse();  // row c: gradient of corner c+1's shape function
    Eigen::Vector3d grad[4];
    grad[0] = -(inv.row(0) + inv.row(1) + inv.row(2)).transpose();
    for (int c = 0; c < 3; ++c) grad[c + 1] = inv.row(c).transpose();
    Eigen::Matrix<double, 6, 12> b = Eigen::Matrix<double, 6, 12>::Zero();
    for (int a = 0; a < 4; ++a) {
      const Eigen::Vector3d& g = grad[a];
      b(0, 3 * a + 0) = g[0];
      b(1, 3 * a + 1) = g[1];
      b(2, 3 * a + 2) = g[2];
      b(3, 3 * a + 1) = g[2];
      b(3, 3 * a + 2) = g[1];
      b(4, 3 * a + 0) = g[2];
      b(4, 3 * a + 2) = g[0];
      b(5, 3 * a + 0) = g[1];
      b(5, 3 * a + 1) = g[0];
    }
    const Eigen::Matrix<double, 12, 12> ke = vol * b.transpose() * d * b;
    scatter(triplets, tet, ke);
  }
  return solve(mesh, triplets, loads, error);
}

std::vector<Vec3d> solve_network(const TetMesh& mesh, const std::vector<TetSprings>& springs,
                                 const StaticLoads& loads, std::string* error) {
  static constexpr int kPairs[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  Triplets triplets;
  triplets.reserve(mesh.tets.size() * 144);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const auto& tet = mesh.tets[t];
    Eigen::Matrix<double, 12, 12> ke = Eigen::Matrix<double, 12, 12>::Zero();
    // A spring: energy k (n . (u_b - u_a))^2 / 2.
    for (int e = 0; e < 6; ++e) {
      const int a = kPairs[e][0], b = kPairs[e][1];
      const Eigen::Vector3d n = (at(mesh, tet[b]) - at(mesh, tet[a])).normalized();
      Eigen::Matrix<double, 12, 1> g = Eigen::Matrix<double, 12, 1>::Zero();
      g.segment<3>(3 * b) = n;
      g.segment<3>(3 * a) = -n;
      ke += springs[t].edge[e] * g * g.transpose();
    }
    // The volume: energy k_v (grad V . u)^2 / 2, grad_i V = (opposite face's area normal) / 3.
    const Eigen::Vector3d x0 = at(mesh, tet[0]), x1 = at(mesh, tet[1]), x2 = at(mesh, tet[2]), x3 = at(mesh, tet[3]);
    Eigen::Matrix<double, 12, 1> g;
    g.segment<3>(3) = (x2 - x0).cross(x3 - x0) / 6.0;
    g.segment<3>(6) = (x3 - x0).cross(x1 - x0) / 6.0;
    g.segment<3>(9) = (x1 - x0).cross(x2 - x0) / 6.0;
    g.segment<3>(0) = -(g.segment<3>(3) + g.segment<3>(6) + g.segment<3>(9));
    ke += springs[t].volume * g * g.transpose();
    scatter(triplets, tet, ke);
  }
  return solve(mesh, triplets, loads, error);
}

std::vector<TetSprings> body_springs(const TetBodyDesc& body) {
  std::vector<TetSprings> out;
  for (const TetNetworkFit& k : network_springs(body)) out.push_back({k.edge, k.volume});
  return out;
}

double mean_displacement(const TetMesh& mesh, const std::vector<Vec3d>& u, int axis, int along, double at) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    if (std::abs(mesh.vertices[v][along] - at) < 1e-9) {
      sum += u[v][axis];
      ++n;
    }
  return n ? sum / n : 0.0;
}

TetMesh graded_box(int nx, int ny, int nz, double cell, double grading, double jitter) {
  auto grid = make_tet_grid({.nx = nx, .ny = ny, .nz = nz, .origin = {0, 0, 0}, .cell_size = {1.0, 1.0, 1.0}});
  if (!grid.ok()) return {};
  TetMesh mesh = *grid;
  // x of grid line i: cells growing by `grading`, total nx * cell.
  std::vector<double> xs(std::size_t(nx) + 1, 0.0);
  double w = 1.0, total = 0.0;
  for (int i = 0; i < nx; ++i, w *= grading) total += w;
  w = nx * cell / total;
  for (int i = 0; i < nx; ++i, w *= grading) xs[std::size_t(i) + 1] = xs[std::size_t(i)] + w;
  const double smallest = std::min(cell, (nx * cell / total) * std::min(1.0, std::pow(grading, nx - 1)));
  std::uint32_t state = 12345u;  // a fixed LCG: the same mesh on every run
  const auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24) * 2.0 - 1.0;
  };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        Vec3d& v = mesh.vertices[std::size_t(i + (nx + 1) * (j + (ny + 1) * k))];
        v = {xs[std::size_t(i)], j * cell, k * cell};
        const bool interior[3] = {i > 0 && i < nx, j > 0 && j < ny, k > 0 && k < nz};
        for (int a = 0; a < 3; ++a) {
          const double r = next();
          if (interior[a]) v[std::size_t(a)] += jitter * smallest * r;
        }
      }
  return mesh;
}

}  // namespace sinew::test
