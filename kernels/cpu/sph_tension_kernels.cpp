// sph_tension_kernels.cpp — CPU reference of the fluid's surface tension
// (kernels/shared/sph_tension_params.h; Akinci, Akinci and Teschner 2013):
// the surface normals, then cohesion and curvature as an acceleration over
// the step, on the neighbour grid in the order of nbr_query, each float
// operation in the order of the GPU twins (kernels/gpu/sph_normals.gpu,
// sph_tension.gpu).
#include <cmath>
#include <cstdint>

#include "cpu/cpu_kernels.h"
#include "cpu/neighbour_cells.h"
#include "cpu/sph_spline.h"
#include "sph_tension_params.h"

namespace sinew::kernels {
namespace {

using u32 = std::uint32_t;
using cells::visit_cells;

float cohesion_spline(const TensionParams& p, float r) {
  const float t = p.h - r;
  const float t3 = (t * t) * t;
  const float r3 = (r * r) * r;
  if (r + r > p.h) return p.cohesion * (t3 * r3);
  return p.cohesion * ((2.0f * t3) * r3 - p.h6_64);
}

}  // namespace

void sph_normals(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const TensionParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  const auto* density = reinterpret_cast<const float*>(bindings[4]);
  auto* normals = reinterpret_cast<float*>(bindings[5]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    float* out = normals + 4 * std::size_t{s};
    float nx = 0.0f, ny = 0.0f, nz = 0.0f;
    if (x[3] > 0.0f)
      visit_cells(cells, ranges, p.table_mask, cells + 4 * std::size_t{s}, [&](u32 t) {
        const float* y = points + 4 * std::size_t{t};
        if (!(y[3] > 0.0f)) return;
        const float ex = x[0] - y[0], ey = x[1] - y[1], ez = x[2] - y[2];
        const float d2 = ex * ex + ey * ey + ez * ez;
        if (!(d2 < p.h2) || !(d2 > 0.0f)) return;
        const float r = std::sqrt(d2);
        const float k = ((y[3] / density[t]) * p.grad_sigma) * spline::slope(r * p.inv_l) / r;
        nx = nx + k * ex;
        ny = ny + k * ey;
        nz = nz + k * ez;
      });
    out[0] = p.h * nx;
    out[1] = p.h * ny;
    out[2] = p.h * nz;
    out[3] = 0.0f;
  }
}

void sph_tension(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const TensionParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  const auto* density = reinterpret_cast<const float*>(bindings[4]);
  const auto* normals = reinterpret_cast<const float*>(bindings[5]);
  auto* next_points = reinterpret_cast<float*>(bindings[6]);
  auto* next_velocity = reinterpret_cast<float*>(bindings[7]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    if (!(x[3] > 0.0f)) continue;
    const float* ni = normals + 4 * std::size_t{s};
    const float rho = density[s];
    float ax = 0.0f, ay = 0.0f, az = 0.0f;
    visit_cells(cells, ranges, p.table_mask, cells + 4 * std::size_t{s}, [&](u32 t) {
      const float* y = points + 4 * std::size_t{t};
      if (!(y[3] > 0.0f)) return;
      const float ex = x[0] - y[0], ey = x[1] - y[1], ez = x[2] - y[2];
      const float d2 = ex * ex + ey * ey + ez * ez;
      if (!(d2 < p.h2) || !(d2 > 0.0f)) return;
      const float r = std::sqrt(d2);
      const float k = (2.0f * p.rho0) / (rho + density[t]);
      const float c = (y[3] * cohesion_spline(p, r)) / r;
      const float* nj = normals + 4 * std::size_t{t};
      const float gk = p.gamma * k;
      ax = ax - gk * (c * ex + (ni[0] - nj[0]));
      ay = ay - gk * (c * ey + (ni[1] - nj[1]));
      az = az - gk * (c * ez + (ni[2] - nj[2]));
    });
    float* v = next_velocity + 4 * std::size_t{s};
    float* xn = next_points + 4 * std::size_t{s};
    v[0] = v[0] + p.dt * ax;
    v[1] = v[1] + p.dt * ay;
    v[2] = v[2] + p.dt * az;
    xn[0] = xn[0] + p.dt2 * ax;
    xn[1] = xn[1] + p.dt2 * ay;
    xn[2] = xn[2] + p.dt2 * az;
  }
}

}  // namespace sinew::kernels
