// edge_network.cpp — springs and volume terms fitted to constant-strain
// linear elasticity (see edge_network.h, docs/materials.md).
#include "compiler/edge_network.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace sinew {
namespace {

using Mat6 = std::array<double, 36>;
using P4 = std::array<std::array<double, 3>, 4>;
constexpr int kUnknowns = 7;  // six springs, one volume term
const double kSqrt2 = std::sqrt(2.0);

double tet_volume(const P4& p) {
  const double a[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
  const double b[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
  const double c[3] = {p[3][0] - p[0][0], p[3][1] - p[0][1], p[3][2] - p[0][2]};
  return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6.0;
}

// The Mandel vector m of an edge (d^T eps d = m . eps) and its length^2.
std::array<double, 6> edge_vector(const P4& p, int e, double& length2) {
  const auto& a = p[kTetEdgePairs[e][0]];
  const auto& b = p[kTetEdgePairs[e][1]];
  const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  length2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  return {d[0] * d[0], d[1] * d[1], d[2] * d[2], kSqrt2 * d[1] * d[2], kSqrt2 * d[0] * d[2], kSqrt2 * d[0] * d[1]};
}

// The 6x6 stiffness per unit coefficient of unknown i: m m^T / L^2 for a
// spring (coefficient k_e [N/m]), V^2 t t^T for the volume (k_v [N/m^5]).
Mat6 basis(const P4& p, int i) {
  std::array<double, 6> v{};
  double scale = 1.0;
  if (i < 6) {
    double l2 = 0.0;
    v = edge_vector(p, i, l2);
    scale = 1.0 / l2;
  } else {
    const double vol = tet_volume(p);
    v = {1, 1, 1, 0, 0, 0};
    scale = vol * vol;
  }
  Mat6 m{};
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) m[r * 6 + c] = scale * v[r] * v[c];
  return m;
}

Mat6 mul(const Mat6& a, const Mat6& b) {
  Mat6 out{};
  for (int r = 0; r < 6; ++r)
    for (int k = 0; k < 6; ++k)
      for (int c = 0; c < 6; ++c) out[r * 6 + c] += a[r * 6 + k] * b[k * 6 + c];
  return out;
}

// x P_h + y P_d: P_h = t t^T / 3 projects on the hydrostatic strain, P_d
// on the deviatoric ones. D = 3K P_h + 2 mu P_d; its powers likewise.
Mat6 isotropic(double x, double y) {
  Mat6 m{};
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) {
      const double h = (r < 3 && c < 3) ? 1.0 / 3.0 : 0.0;
      m[r * 6 + c] = x * h + y * ((r == c ? 1.0 : 0.0) - h);
    }
  return m;
}

double dot(const Mat6& a, const Mat6& b) {
  double s = 0.0;
  for (int i = 0; i < 36; ++i) s += a[i] * b[i];
  return s;
}

// The inverse of a symmetric positive definite matrix by Cholesky; false
// when it is not positive definite.
bool spd_inverse(const Mat6& a, Mat6& inv) {
  double l[6][6] = {};
  for (int j = 0; j < 6; ++j) {
    double d = a[j * 6 + j];
    for (int k = 0; k < j; ++k) d -= l[j][k] * l[j][k];
    if (!(d > 1e-300)) return false;
    l[j][j] = std::sqrt(d);
    for (int i = j + 1; i < 6; ++i) {
      double s = a[i * 6 + j];
      for (int k = 0; k < j; ++k) s -= l[i][k] * l[j][k];
      l[i][j] = s / l[j][j];
    }
  }
  for (int c = 0; c < 6; ++c) {  // solve L L^T x = e_c
    double y[6], x[6];
    for (int i = 0; i < 6; ++i) {
      double s = i == c ? 1.0 : 0.0;
      for (int k = 0; k < i; ++k) s -= l[i][k] * y[k];
      y[i] = s / l[i][i];
    }
    for (int i = 5; i >= 0; --i) {
      double s = y[i];
      for (int k = i + 1; k < 6; ++k) s -= l[k][i] * x[k];
      x[i] = s / l[i][i];
    }
    for (int i = 0; i < 6; ++i) inv[i * 6 + c] = x[i];
  }
  return true;
}

// Solves the n x n system a x = b (row-major, n <= 21) by Gaussian
// elimination with partial pivoting; false when singular.
bool solve(std::vector<double> a, std::vector<double> b, int n, std::vector<double>& x) {
  double largest = 0.0;
  for (double v : a) largest = std::max(largest, std::abs(v));
  for (int c = 0; c < n; ++c) {
    int piv = c;
    for (int i = c + 1; i < n; ++i)
      if (std::abs(a[i * n + c]) > std::abs(a[piv * n + c])) piv = i;
    if (!(std::abs(a[piv * n + c]) > 1e-13 * largest)) return false;
    for (int j = 0; j < n; ++j) std::swap(a[c * n + j], a[piv * n + j]);
    std::swap(b[c], b[piv]);
    for (int i = c + 1; i < n; ++i) {
      const double f = a[i * n + c] / a[c * n + c];
      for (int j = c; j < n; ++j) a[i * n + j] -= f * a[c * n + j];
      b[i] -= f * b[c];
    }
  }
  x.assign(n, 0.0);
  for (int c = n - 1; c >= 0; --c) {
    double s = b[c];
    for (int j = c + 1; j < n; ++j) s -= a[c * n + j] * x[j];
    x[c] = s / a[c * n + c];
  }
  return true;
}

// One tet's least-squares fit in the energy norm: the weighted, normalised
// basis a_i = W B_i W / (V |W B_i W|) (W = D^-1/2 of the asked material),
// its Gram matrix, and the map from a target T to the stiffnesses
// k_i = V / |W B_i W| (G^-1 <a_i, W T W / V>).
struct TetFit {
  Mat6 a[kUnknowns];
  double to_k[kUnknowns];
  std::vector<double> gram;  // 7 x 7
};

TetFit prepare_tet(const P4& p, const Mat6& w) {
  TetFit f;
  const double vol = tet_volume(p);
  for (int i = 0; i < kUnknowns; ++i) {
    f.a[i] = mul(mul(w, basis(p, i)), w);
    const double norm = std::sqrt(dot(f.a[i], f.a[i]));
    for (double& x : f.a[i]) x /= norm;
    f.to_k[i] = vol / norm;
  }
  f.gram.assign(kUnknowns * kUnknowns, 0.0);
  for (int i = 0; i < kUnknowns; ++i)
    for (int j = 0; j < kUnknowns; ++j) f.gram[i * kUnknowns + j] = dot(f.a[i], f.a[j]);
  // A tiny ridge: a sliver's springs can be nearly dependent.
  for (int i = 0; i < kUnknowns; ++i) f.gram[i * kUnknowns + i] += 1e-10;
  return f;
}

// Non-negative least squares over the 127 subsets of free unknowns: the
// best feasible one (the unconstrained solution when it is >= 0).
std::array<double, kUnknowns> fit_nonnegative(const TetFit& f, const Mat6& wtw) {
  std::array<double, kUnknowns> r{};
  for (int i = 0; i < kUnknowns; ++i) r[std::size_t(i)] = dot(f.a[i], wtw);
  const std::vector<double>& gram = f.gram;
  std::array<double, kUnknowns> best{};
  double best_error = INFINITY;
  for (unsigned set = (1u << kUnknowns) - 1; set >= 1; --set) {
    int idx[kUnknowns], n = 0;
    for (int i = 0; i < kUnknowns; ++i)
      if (set >> i & 1u) idx[n++] = i;
    std::vector<double> g(std::size_t(n) * std::size_t(n)), rr(static_cast<std::size_t>(n)), q;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) g[std::size_t(i * n + j)] = gram[std::size_t(idx[i] * kUnknowns + idx[j])];
      rr[std::size_t(i)] = r[std::size_t(idx[i])];
    }
    if (!solve(g, rr, n, q)) continue;
    bool feasible = true;
    for (double x : q) feasible = feasible && x >= 0.0;
    if (!feasible) continue;
    std::array<double, kUnknowns> full{};
    for (int i = 0; i < n; ++i) full[std::size_t(idx[i])] = q[std::size_t(i)];
    double error = 0.0;  // |sum q_i a_i - T|^2 - |T|^2 = q^T G q - 2 q.r
    for (int i = 0; i < kUnknowns; ++i) {
      error -= 2.0 * full[std::size_t(i)] * r[std::size_t(i)];
      for (int j = 0; j < kUnknowns; ++j)
        error += full[std::size_t(i)] * gram[std::size_t(i * kUnknowns + j)] * full[std::size_t(j)];
    }
    if (error < best_error) {
      best_error = error;
      best = full;
    }
    if (set == (1u << kUnknowns) - 1) break;  // the unconstrained optimum is feasible
  }
  for (int i = 0; i < kUnknowns; ++i) best[std::size_t(i)] *= f.to_k[i];
  return best;
}

}  // namespace

std::array<std::array<double, 3>, 4> tet_corners(const TetMesh& mesh, std::size_t t) {
  std::array<std::array<double, 3>, 4> p{};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) p[i][k] = static_cast<float>(mesh.vertices[mesh.tets[t][i]][k]);
  return p;
}

void add_tet_network(const P4& p, const TetNetworkFit& k, std::array<double, 36>& sum) {
  for (int i = 0; i < kUnknowns; ++i) {
    const Mat6 b = basis(p, i);
    const double c = i < 6 ? k.edge[std::size_t(i)] : k.volume;
    for (int j = 0; j < 36; ++j) sum[std::size_t(j)] += c * b[std::size_t(j)];
  }
}

ElasticModuli axis_moduli(const std::array<double, 36>& sum, double volume) {
  // The mean compliance S = (sum / volume)^-1 along the axes: 1/E the mean
  // of S_xxxx, S_yyyy, S_zzzz; -nu/E the mean of S_xxyy, S_yyzz, S_xxzz;
  // 1/(2G) the mean of the Mandel shear diagonal.
  Mat6 c{}, s{};
  for (int i = 0; i < 36; ++i) c[std::size_t(i)] = sum[std::size_t(i)] / volume;
  ElasticModuli m;
  if (!spd_inverse(c, s)) return m;  // no finite compliance: zeros
  const double sa = (s[0] + s[7] + s[14]) / 3.0, sb = (s[1] + s[2] + s[8]) / 3.0,
               sc = (s[21] + s[28] + s[35]) / 3.0;
  m.young = 1.0 / sa;
  m.poisson = -sb / sa;
  m.shear = 1.0 / (2.0 * sc);
  m.bulk = 1.0 / (3.0 * sa + 6.0 * sb);
  return m;
}

BodyNetworkFit fit_body_network(const TetMesh& mesh, double young, double poisson) {
  const double mu = young / (2.0 * (1.0 + poisson)), lambda = 2.0 * mu * poisson / (1.0 - 2.0 * poisson);
  const double bulk = lambda + 2.0 * mu / 3.0;
  const Mat6 w = isotropic(1.0 / std::sqrt(3.0 * bulk), 1.0 / std::sqrt(2.0 * mu));  // D^-1/2
  const std::size_t nt = mesh.tets.size();
  // The target T(x) = x0 A + x1 B + x2 S (A: the normal diagonal, B: the
  // normal off-diagonal, S: the shear diagonal, in Mandel form): the
  // isotropic D is (lambda + 2 mu, lambda, 2 mu).
  const auto target = [](const std::array<double, 3>& x) {
    Mat6 m{};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m[std::size_t(r * 6 + c)] = r == c ? x[0] : x[1];
    for (int r = 3; r < 6; ++r) m[std::size_t(r * 6 + r)] = x[2];
    return m;
  };
  // The fit of T on a sample of at most 2000 tets (every n-th), each tet
  // prepared once.
  const std::size_t stride = std::max<std::size_t>(1, nt / 2000);
  std::vector<TetFit> sample;
  std::vector<P4> corners;
  for (std::size_t t = 0; t < nt; t += stride) {
    corners.push_back(tet_corners(mesh, t));
    sample.push_back(prepare_tet(corners.back(), w));
  }
  const auto fit_one = [&](const TetFit& f, const P4& p, const Mat6& wtw) {
    const auto k = fit_nonnegative(f, wtw);
    // Floors, so that every compliance is finite and no spring is left
    // slack for large deformations to fold: a spring part of at least 0.3
    // of E V / (6 L^2) (the hand-set rule's part for c_d = 1/E; with
    // 1e-3, a slab of flat cells squeezed to a quarter of its thickness
    // folded), a volume term of at least 1e-6 K / V.
    TetNetworkFit out;
    const double vol = tet_volume(p);
    for (int e = 0; e < 6; ++e) {
      double l2 = 0.0;
      (void)edge_vector(p, e, l2);
      out.edge[std::size_t(e)] = std::max(k[std::size_t(e)], 0.3 * young * vol / (6.0 * l2));
    }
    out.volume = std::max(k[6], 1e-6 * bulk / vol);
    return out;
  };
  // Residuals: E and G along the axes relative to the asked ones, and nu
  // (weighted 0.3: below 1/4 it cannot be reached, and E and G matter more).
  const auto residual = [&](const std::array<double, 3>& x, std::array<double, 3>& r) {
    const Mat6 wtw = mul(mul(w, target(x)), w);
    std::array<double, 36> sum{};
    double volume = 0.0;
    for (std::size_t i = 0; i < sample.size(); ++i) {
      add_tet_network(corners[i], fit_one(sample[i], corners[i], wtw), sum);
      volume += tet_volume(corners[i]);
    }
    const ElasticModuli m = axis_moduli(sum, volume);
    if (!(m.young > 0.0) || !(m.shear > 0.0)) return false;
    r = {m.young / young - 1.0, 0.3 * (m.poisson - poisson), m.shear / mu - 1.0};
    return true;
  };
  // Gauss-Newton with step halving from T = D.
  std::array<double, 3> x{lambda + 2.0 * mu, lambda, 2.0 * mu}, r{};
  if (residual(x, r)) {
    double err = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    for (int iter = 0; iter < 40 && err > 1e-10; ++iter) {
      std::vector<double> jac(9), jtj(9, 0.0), jtr(3, 0.0), step;
      for (int j = 0; j < 3; ++j) {
        auto up = x;
        const double h = 1e-4 * (std::abs(x[std::size_t(j)]) + 1e-2 * mu);
        up[std::size_t(j)] += h;
        std::array<double, 3> ru{};
        if (!residual(up, ru)) ru = r;
        for (int i = 0; i < 3; ++i) jac[std::size_t(i * 3 + j)] = (ru[std::size_t(i)] - r[std::size_t(i)]) / h;
      }
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b)
          for (int i = 0; i < 3; ++i) jtj[std::size_t(a * 3 + b)] += jac[std::size_t(i * 3 + a)] * jac[std::size_t(i * 3 + b)];
        for (int i = 0; i < 3; ++i) jtr[std::size_t(a)] -= jac[std::size_t(i * 3 + a)] * r[std::size_t(i)];
      }
      for (int a = 0; a < 3; ++a) jtj[std::size_t(a * 3 + a)] *= 1.0 + 1e-9;
      if (!solve(jtj, jtr, 3, step)) break;
      bool improved = false;
      for (double t = 1.0; t > 1e-3 && !improved; t *= 0.5) {
        auto next = x;
        for (int j = 0; j < 3; ++j) next[std::size_t(j)] += t * step[std::size_t(j)];
        std::array<double, 3> rn{};
        if (residual(next, rn) && rn[0] * rn[0] + rn[1] * rn[1] + rn[2] * rn[2] < err) {
          x = next;
          r = rn;
          err = rn[0] * rn[0] + rn[1] * rn[1] + rn[2] * rn[2];
          improved = true;
        }
      }
      if (!improved) break;
    }
  }
  // Every tet fitted to that target.
  const Mat6 wtw = mul(mul(w, target(x)), w);
  BodyNetworkFit out;
  out.tets.reserve(nt);
  std::array<double, 36> sum{};
  double volume = 0.0;
  for (std::size_t t = 0; t < nt; ++t) {
    const P4 p = tet_corners(mesh, t);
    out.tets.push_back(fit_one(prepare_tet(p, w), p, wtw));
    add_tet_network(p, out.tets.back(), sum);
    volume += tet_volume(p);
  }
  out.effective = axis_moduli(sum, volume);
  return out;
}

Result<ElasticModuli> effective_moduli(const TetBodyDesc& body) {
  if (!body.distance_constraints && !body.volume_constraints)
    return Error(ErrorCode::bad_parameter, "effective_moduli: the body has no distance or volume constraints");
  if (body.calibrated_network) {
    if (!(body.youngs_modulus > 0.0) || !(body.poisson_ratio > -1.0 && body.poisson_ratio < 0.5))
      return Error(ErrorCode::bad_parameter,
                   "effective_moduli: youngs_modulus must be > 0 and poisson_ratio in (-1, 0.5) with "
                   "calibrated_network");
    if (body.distance_constraints && body.volume_constraints)
      return fit_body_network(body.mesh, body.youngs_modulus, body.poisson_ratio).effective;
  } else {
    if (body.distance_constraints && !(body.distance_compliance > 0.0))
      return Error(ErrorCode::bad_parameter,
                   "effective_moduli: distance_compliance must be > 0 (a rigid network has no finite modulus)");
    if (body.volume_constraints && !(body.volume_compliance > 0.0))
      return Error(ErrorCode::bad_parameter, "effective_moduli: volume_compliance must be > 0");
  }
  const auto fits = network_springs(body);
  std::array<double, 36> sum{};
  double volume = 0.0;
  for (std::size_t t = 0; t < body.mesh.tets.size(); ++t) {
    const auto p = tet_corners(body.mesh, t);
    add_tet_network(p, fits[t], sum);
    volume += tet_volume(p);
  }
  return axis_moduli(sum, volume);
}

std::vector<TetNetworkFit> network_springs(const TetBodyDesc& body) {
  std::vector<TetNetworkFit> out;
  if (body.calibrated_network) {
    out = fit_body_network(body.mesh, body.youngs_modulus, body.poisson_ratio).tets;
  } else {
    out.resize(body.mesh.tets.size());
    for (std::size_t t = 0; t < out.size(); ++t) {
      // As the compiler sets them: each tet gives V/6 to each edge's share.
      const auto p = tet_corners(body.mesh, t);
      const double v = tet_volume(p);
      for (int e = 0; e < 6; ++e) {
        double l2 = 0.0;
        (void)edge_vector(p, e, l2);
        out[t].edge[std::size_t(e)] = v / (6.0 * body.distance_compliance * l2);
      }
      out[t].volume = 1.0 / (body.volume_compliance * v);
    }
  }
  for (TetNetworkFit& k : out) {
    if (!body.distance_constraints) k.edge = {};
    if (!body.volume_constraints) k.volume = 0.0;
  }
  return out;
}

}  // namespace sinew
