// vbd_kernels.cpp — CPU reference kernels of Vertex Block Descent
// (SolverSettings::method = vbd).
//
// Anka He Chen, Ziheng Liu, Yin Yang, Cem Yuksel, "Vertex Block Descent",
// ACM TOG 43(4), SIGGRAPH 2024. A substep of implicit Euler minimises
//   G(x) = sum_i m_i / (2 h^2) |x_i - y_i|^2 + sum_t E_t(x),
// y = x_prev + h v + h^2 g. VBD does block coordinate descent on G: a
// vertex at a time (all others held), one Newton step on its 3 unknowns,
//   (m / h^2 I + sum_t H_t) dx = -(m / h^2 (x - y) + sum_t grad E_t),
// over the tets t around it, with each H_t a positive semi-definite 3x3
// block (kernels/math/vbd_math.h). Vertices of one colour share no tet, so
// their steps are independent: one dispatch per colour, Gauss-Seidel from
// colour to colour, as xPBD sweeps its constraints.
//
// Why VBD for stiff bodies: unconverged xPBD sweeps leave a body softer
// than its material (docs/tissue.md); a VBD step uses the material's full
// stiffness in every vertex's Newton step, so unconverged sweeps leave the
// inertia term partly unsolved (extra damping of fast motion) rather than
// a softer material.
//
// All in float, like the GPU twins (kernels/gpu/vbd_*.gpu); a pinned
// particle (w == 0) is never written. No allocation.
#include "cpu/cpu_kernels.h"

#include "fem_params.h"
#include "math/vbd_math.h"
#include "vbd_params.h"

namespace sinew::kernels {

void vbd_initial_guess(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const VbdInitParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  auto* y = reinterpret_cast<float4*>(bindings[1]);
  for (std::uint32_t i = begin; i < end; ++i) {
    y[i] = x[i];
    if (x[i].w == 0.0f) continue;
    x[i].x -= p.h2g_x;
    x[i].y -= p.h2g_y;
    x[i].z -= p.h2g_z;
  }
}

void vbd_solve_vertices(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const VbdSolveParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* y = reinterpret_cast<const float4*>(bindings[1]);
  const auto* vertices = reinterpret_cast<const std::uint32_t*>(bindings[2]);
  const auto* offsets = reinterpret_cast<const std::uint32_t*>(bindings[3]);
  const auto* incidences = reinterpret_cast<const std::uint32_t*>(bindings[4]);
  const auto* idx = reinterpret_cast<const uint4*>(bindings[5]);
  const auto* data = reinterpret_cast<const float*>(bindings[6]);
  auto* state = reinterpret_cast<float*>(bindings[7]);
  for (std::uint32_t e = p.first + begin; e < p.first + end; ++e) {
    const std::uint32_t v = vertices[e];
    const float4 xv = x[v];
    if (xv.w == 0.0f) continue;  // pinned
    const float inertia = p.inv_h2 / xv.w;  // m / h^2 [N/m]
    vbd::VertexSystem<float> s;
    const float4 yv = y[v];
    s.f[0] = -inertia * (xv.x - yv.x);
    s.f[1] = -inertia * (xv.y - yv.y);
    s.f[2] = -inertia * (xv.z - yv.z);
    s.h[0] = s.h[1] = s.h[2] = inertia;
    for (std::uint32_t k = offsets[e]; k < offsets[e + 1]; ++k) {
      const std::uint32_t tet = incidences[k] >> 2, corner = incidences[k] & 3u;
      const uint4 t = idx[tet];
      const float* d = data + std::size_t{tet} * SINEW_FEM_DATA_STRIDE;
      fem::mat3<float> dm_inv;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) dm_inv.m[r][c] = d[SINEW_FEM_DM_INV + 3 * r + c];
      const fem::mat3<float> f = fem::deformation_gradient(x[t.x], x[t.y], x[t.z], x[t.w], dm_inv);
      const float inv_ad = 1.0f / d[SINEW_FEM_ALPHA_D], inv_ah = 1.0f / d[SINEW_FEM_ALPHA_H];
      float b[3];
      vbd::corner_weights(dm_inv, int(corner), b);
      if (p.model == SINEW_VBD_COROTATIONAL) {
        // The tet's rotation, kept between solves as xpbd_solve_corotational
        // keeps it (exact on the first, then refined): this item is the only
        // one of its colour that touches this tet.
        float* kept = state + std::size_t{tet} * p.lambda_stride + SINEW_FEM_ROTATION;
        fem::quat<float> q{kept[0], kept[1], kept[2], kept[3]};
        if (q.w == 0.0f && q.x == 0.0f && q.y == 0.0f && q.z == 0.0f) q = fem::rotation_quaternion(f);
        q = fem::refine_rotation(f, q, fem::kRotationIterations);
        kept[0] = q.w, kept[1] = q.x, kept[2] = q.y, kept[3] = q.z;
        const fem::mat3<float> r = fem::quaternion_matrix(q);
        vbd::add_tet(s, r, vbd::corotational_stress(f, r, d[SINEW_FEM_H0], inv_ad, inv_ah), b, inv_ad, inv_ah);
      } else {
        const fem::mat3<float> cof = fem::cofactor(f);
        vbd::add_tet(s, cof, vbd::neo_hookean_stress(f, cof, d[SINEW_FEM_H0], inv_ad, inv_ah), b, inv_ad, inv_ah);
      }
    }
    float dx[3];
    if (!vbd::solve_step(s, dx)) continue;
    x[v] = float4{xv.x + dx[0], xv.y + dx[1], xv.z + dx[2], xv.w};
  }
}

}  // namespace sinew::kernels
