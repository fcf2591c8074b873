// edge_network.h — the springs (distance constraints) and volume terms of a
// tet body fitted to linear elasticity of Young's modulus E and Poisson's
// ratio nu, for TetBodyDesc::set_elastic; and the moduli a network amounts
// to (effective_moduli). Measured accuracy: docs/materials.md.
//
// Under a uniform small strain eps (6-vector in Mandel notation: eps11,
// eps22, eps33, sqrt2 eps23, sqrt2 eps13, sqrt2 eps12), an edge d = x_b - x_a
// of length L stretches by d^T eps d / L = (m . eps) / L with
// m = (d1^2, d2^2, d3^2, sqrt2 d2 d3, sqrt2 d1 d3, sqrt2 d1 d2), and the
// volume changes by V (t . eps) with t = (1, 1, 1, 0, 0, 0). A spring k_e
// [N/m] and a volume stiffness k_v [N/m^5] (energy k_v dV^2 / 2) store
//     eps^T (sum_e k_e / L_e^2 m_e m_e^T + k_v V^2 t t^T) eps / 2,
// and constant-strain linear elasticity stores eps^T (V D) eps / 2 with
// D = lambda t t^T + 2 mu I. A linear tet has exactly these six strains as
// its deformations, so matching the 6x6 matrices would match the tet's
// whole stiffness, and both energies are sums over tets. Six springs and a
// volume term cannot match V D (21 numbers), so each tet is fitted in the
// relative energy norm
//     min_{k >= 0} || D^-1/2 (K_fit / V - T) D^-1/2 ||_F
// (least-squares identification of spring constants from an element's
// stiffness: Lloyd, Székely and Harders, "Identification of Spring
// Parameters for Deformable Object Simulation", IEEE TVCG 13(5), 2007; here
// with a volume term, the relative norm and non-negative stiffnesses).
// Fitting T = D itself leaves a six-tet grid 1.4x too soft in bending and
// 3x in shear: springs cannot cancel the coupling of normal and shear
// strain that the grid's diagonals (all one way) give, and the tets'
// errors add up in the soft directions. So the target T is a cubic matrix
// (the normal diagonal, the normal off-diagonal and the shear diagonal, in
// Mandel form), chosen by Gauss-Newton from T = D so that the body's mean
// network stiffness has, along the axes, the asked compliance: Young's
// modulus, Poisson's ratio (weighted 0.3) and shear modulus (axis_moduli).
#pragma once

#include <array>
#include <vector>

#include "sinew/scene.h"

namespace sinew {

/// The edges of a tet in the order of its springs: corners (0,1) (0,2)
/// (0,3) (1,2) (1,3) (2,3).
inline constexpr int kTetEdgePairs[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

/// The lowest Poisson's ratio set_elastic accepts. Springs are central
/// forces: an isotropic network of them has nu = 1/4 (the Cauchy
/// relation). An anisotropic one can have a lower nu along the axes, but
/// below 0.2 the fit leaves soft modes that its mean stiffness does not
/// show (measured: a jittered grid at nu = 0.1 stretched 14x too far).
inline constexpr double kNetworkMinPoisson = 0.2;

/// One tet's part of the network: what it adds to each of its edges'
/// springs and its volume stiffness. An edge's spring is the sum of its
/// tets' parts.
struct TetNetworkFit {
  std::array<double, 6> edge{};  ///< spring stiffness parts (kTetEdgePairs order) [N/m], > 0
  double volume = 0.0;           ///< k_v [N/m^5] (alpha = 1 / k_v), > 0
};

/// A body's fit and the moduli it got (axis_moduli of the result).
struct BodyNetworkFit {
  std::vector<TetNetworkFit> tets;
  ElasticModuli effective;
};

/// Fits the springs and volume terms of a body of Young's modulus E [Pa]
/// and Poisson's ratio nu on `mesh` (every tet positively oriented), as
/// described at the top. The target is chosen on at most 2000 tets (every
/// n-th). Deterministic. Each spring part is at least 0.3 E V / (6 L^2)
/// and each volume term at least 1e-6 K / V, so every compliance is finite.
BodyNetworkFit fit_body_network(const TetMesh& mesh, double young, double poisson);

/// The parts a body's distance and volume constraints get: the fit for
/// set_elastic (calibrated_network), else from the hand-set compliances.
std::vector<TetNetworkFit> network_springs(const TetBodyDesc& body);

/// The network's stiffness under uniform strain, summed over tets (Mandel
/// 6x6, row-major) [N m]: add_tet_network adds one tet's part.
/// axis_moduli: from the mean compliance S (the inverse of sum / volume
/// [m^3]), E = 1 / mean(S_xxxx, S_yyyy, S_zzzz), nu = -E mean(S_xxyy,
/// S_yyzz, S_xxzz), G = 1 / (2 mean(Mandel shear diagonal)), K the bulk
/// modulus from those; all zero when sum is not positive definite.
void add_tet_network(const std::array<std::array<double, 3>, 4>& p, const TetNetworkFit& k,
                     std::array<double, 36>& sum);
ElasticModuli axis_moduli(const std::array<double, 36>& sum, double volume);

/// Tet t's corners as the compiler sees them (rounded to float) [m].
std::array<std::array<double, 3>, 4> tet_corners(const TetMesh& mesh, std::size_t t);

}  // namespace sinew
