// accelerator_kernels.cpp — CPU reference of the Chebyshev semi-iterative
// accelerator (kernels/shared/accelerator_params.h).
//
// Wang, "A Chebyshev Semi-Iterative Approach for Accelerating Projective
// and Position-Based Dynamics", SIGGRAPH Asia 2015, eq. 12. Each float is
// one independent item, so any split across threads gives the same bits;
// the operations are written in the order the GPU twin rounds them
// (kernels/gpu/xpbd_chebyshev.gpu, PRECISE: no fused multiply-add).
#include "cpu/cpu_kernels.h"

#include "accelerator_params.h"
#include "math/xpbd_math.h"

namespace sinew::kernels {

void xpbd_chebyshev(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const ChebyshevParams*>(params);
  auto* values = reinterpret_cast<float*>(bindings[0]);
  auto* newer = reinterpret_cast<float*>(bindings[1]);
  auto* older = reinterpret_cast<float*>(bindings[2]);
  for (std::uint32_t j = begin; j < end && j < p.count; ++j) {
    if (j % p.stride >= p.width) continue;  // not state (inverse mass, kept rotation)
    const float q_hat = values[j];
    const float q_k = newer[j];
    if (p.mix == 0) {
      older[j] = q_k;
      newer[j] = q_hat;
      continue;
    }
    const float q_km1 = older[j];
    // omega (gamma (q^ - q_k) + q_k - q_km1) + q_km1, rounded step by step.
    const float step = p.gamma * (q_hat - q_k);
    const float inner = (step + q_k) - q_km1;
    const float q_next = p.omega * inner + q_km1;
    values[j] = q_next;
    older[j] = q_k;
    newer[j] = q_next;
  }
}

}  // namespace sinew::kernels

namespace sinew::kernels {

// The lambda warm start (accelerator_params.h): each constraint of one
// colour adds the correction its last lambda made, with the gradient at the
// substep's start. A colour's constraints share no movable particle, so the
// writes never race; immovable particles (w == 0) are never written.
void xpbd_warm_start(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const WarmStartParams*>(params);
  auto* x = reinterpret_cast<float4*>(bindings[0]);
  const auto* prev = reinterpret_cast<const float4*>(bindings[1]);
  const auto* idx = reinterpret_cast<const std::uint32_t*>(bindings[2]);
  const auto* lambda = reinterpret_cast<const float*>(bindings[3]);
  for (std::uint32_t i = p.first + begin; i < p.first + end; ++i) {
    const float l = lambda[i];
    if (l == 0.0f) continue;
    if (p.arity == 2) {
      const std::uint32_t a = idx[2 * i], b = idx[2 * i + 1];
      const float4 pa = prev[a], pb = prev[b];
      const float len = edge_length(pa, pb);
      if (len <= 0.0f) continue;
      const float4 n = edge_length_gradient(pa, pb, len);
      if (x[a].w > 0.0f) x[a] = add_scaled3(x[a], x[a].w * l, n);
      if (x[b].w > 0.0f) x[b] = add_scaled3(x[b], -x[b].w * l, n);
    } else {
      const std::uint32_t* t = idx + 4 * std::size_t{i};
      float4 g[4];
      tet_volume_gradients(prev[t[0]], prev[t[1]], prev[t[2]], prev[t[3]], g);
      for (int k = 0; k < 4; ++k)
        if (x[t[k]].w > 0.0f) x[t[k]] = add_scaled3(x[t[k]], x[t[k]].w * l, g[k]);
    }
  }
}

}  // namespace sinew::kernels
