// material_benchmark — how close set_elastic's edge network comes to linear
// elasticity on the same mesh (docs/materials.md): a bar in tension, a beam
// in bending, a block in shear, on a regular six-tet grid and on a graded,
// jittered one, for several Poisson's ratios; the network before
// calibration (c_d = 1/E, c_v = 3 (1 - 2 nu) / E) for comparison.
//
//   bench_material [--csv FILE] [--xpbd 0|1]
//
// Per row: the effective moduli the body reports (effective_moduli, along
// the axes), and the stiffness ratio (oracle displacement / network
// displacement of the loaded face: 1 exact, < 1 softer) of the network
// linearised at rest and, with --xpbd 1, of the xPBD body on the CPU
// backend run to its statics (residual mode, warm start, 40 frames); and
// the bar's thinning in tension (its Poisson effect) against the oracle's
// (lateral_ratio: 1 the same, > 1 thins more).
// Loads and meshes are tests/material_test.cpp's.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "material_cases.h"

namespace {
constexpr double kE = sinew::test::kMaterialE;
using sinew::Vec3d;

// The bar's thinning under tension: the mean y displacement of its y = 0
// face minus its top face's, over the free half of its length [m].
double thinning(const sinew::test::MaterialProblem& p, const std::vector<Vec3d>& u) {
  double top = 0.0, bottom = 0.0;
  int nt = 0, nb = 0;
  for (std::size_t v = 0; v < u.size(); ++v) {
    const Vec3d& x = p.mesh.vertices[v];
    if (x[0] < 4 * sinew::test::kMaterialCell - 1e-9) continue;
    if (x[1] < 1e-9) bottom += u[v][1], ++nb;
    if (x[1] > 2 * sinew::test::kMaterialCell - 1e-9) top += u[v][1], ++nt;
  }
  return bottom / nb - top / nt;
}
}  // namespace

int main(int argc, char** argv) {
  std::string csv;
  bool with_xpbd = true;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--csv") csv = v;
    else if (k == "--xpbd") with_xpbd = v == "1";
    else {
      std::fprintf(stderr, "unknown option %s\n", k.c_str());
      return 2;
    }
  }
  std::ofstream out;
  if (!csv.empty()) {
    out.open(csv);
    out << "mesh,network,nu_asked,E_eff_over_E,nu_eff,G_eff_over_G,stretch_ratio,bend_ratio,shear_ratio,"
           "xpbd_stretch_ratio,xpbd_bend_ratio,xpbd_shear_ratio,lateral_ratio,xpbd_lateral_ratio,note\n";
  }
  const char* cases[3] = {"stretch", "bend", "shear"};
  for (bool graded : {false, true})
    for (const char* network : {"calibrated", "hand_set"})
      for (double nu : {0.0, 0.1, 0.2, 0.3, 0.45}) {
        const std::string mesh_name = graded ? "graded_jittered_8x2x2" : "regular_8x2x2";
        const bool calibrated = std::string(network) == "calibrated";
        std::string note;
        double ratio[3] = {NAN, NAN, NAN}, xr[3] = {NAN, NAN, NAN}, lateral = NAN, xlateral = NAN;
        sinew::ElasticModuli eff{};
        for (int c = 0; c < 3; ++c) {
          const auto p = sinew::test::material_problem(sinew::test::MaterialCase(c), graded);
          sinew::TetBodyDesc body;
          body.mesh = p.mesh;
          if (calibrated) {
            const sinew::Status s = body.set_elastic(kE, nu);
            if (!s) {
              note = s.error().message();
              break;
            }
          } else {
            body.distance_compliance = 1.0 / kE;
            body.volume_compliance = 3.0 * (1.0 - 2.0 * nu) / kE;
          }
          if (c == 0) {
            auto m = sinew::effective_moduli(body);
            if (m) eff = *m;
          }
          std::string error;
          const auto oracle = sinew::test::solve_linear_elastic(p.mesh, kE, nu, p.loads, &error);
          const auto lin = sinew::test::solve_network(p.mesh, sinew::test::body_springs(body), p.loads, &error);
          if (oracle.empty() || lin.empty()) {
            note = error;
            break;
          }
          ratio[c] = sinew::test::measured(p, oracle) / sinew::test::measured(p, lin);
          std::vector<Vec3d> u;
          if (with_xpbd) {
            u = sinew::test::xpbd_statics(p, body, nullptr, &error);
            xr[c] = u.empty() ? NAN : sinew::test::measured(p, oracle) / sinew::test::measured(p, u);
          }
          if (c == 0) {
            lateral = thinning(p, lin) / thinning(p, oracle);
            if (!u.empty()) xlateral = thinning(p, u) / thinning(p, oracle);
          }
        }
        const double g = kE / (2.0 * (1.0 + nu));
        std::printf("%-22s %-10s nu %.2f: E_eff %.3f E, nu_eff %.3f, G_eff %.3f G | linearised: %s %.3f %s %.3f %s %.3f"
                    " | xPBD: %.3f %.3f %.3f | thinning %.3f %.3f %s\n",
                    mesh_name.c_str(), network, nu, eff.young / kE, eff.poisson, eff.shear / g, cases[0], ratio[0],
                    cases[1], ratio[1], cases[2], ratio[2], xr[0], xr[1], xr[2], lateral, xlateral, note.c_str());
        if (out) {
          for (char& ch : note)
            if (ch == ',') ch = ';';
          out << mesh_name << ',' << network << ',' << nu << ',' << eff.young / kE << ',' << eff.poisson << ','
              << eff.shear / g << ',' << ratio[0] << ',' << ratio[1] << ',' << ratio[2] << ',' << xr[0] << ','
              << xr[1] << ',' << xr[2] << ',' << lateral << ',' << xlateral << ",\"" << note << "\"\n";
        }
      }
  return 0;
}
